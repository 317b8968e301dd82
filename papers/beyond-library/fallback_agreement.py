#!/usr/bin/env python3
"""Where a whole command's fit fell back to NUTS in one run (A) and was kept by importance
sampling in another (B: the defensive second proposal), the two posteriors side by side: each
parameter's mean and 95% interval, and σ per channel, with the difference of the means in
units of A's interval width. Only the fits after (`fit_after`) have their parameters in the
report; a BM2 fit's agreement shows in σ only where it is the fit after.

    fallback_agreement.py RUN_A RUN_B

RUN_A and RUN_B hold NAME.json (`motorcal diagnose --json`) for the same cases."""
import glob, json, os, sys

a_dir, b_dir = sys.argv[1], sys.argv[2]
for path in sorted(glob.glob(f"{a_dir}/*.json")):
    name = os.path.basename(path)[:-5]
    other = os.path.join(b_dir, name + ".json")
    if not os.path.exists(other):
        continue
    a, b = json.load(open(path)), json.load(open(other))
    for stage, conv in (a.get("convergence") or {}).items():
        kept = (b.get("convergence") or {}).get(stage)
        if not (conv and conv["fell_back"] and kept and not kept["fell_back"]):
            continue
        print(f"{name}, fit {stage}: A {conv['sampler']} (first k̂ {conv['khat']:.2f}, {conv['wall_s']:.1f} s), "
              f"B {kept['sampler']} (k̂ {kept['khat']:.2f}, {kept['wall_s']:.1f} s)")
        if stage != "after":
            print("  (parameters of this fit are not in the report)")
            continue
        fa, fb = a["fit_after"], b["fit_after"]
        print("  | parameter | A mean | A 95% | B mean | B 95% | Δmean / A width |")
        print("  |---|---|---|---|---|---|")
        for key, (lo, hi) in fa["params_95"].items():
            if key not in fb["params_95"]:
                print(f"  | {key} | {fa['params_mean'][key]:.4g} | [{lo:.4g}, {hi:.4g}] | (not in B) | | |")
                continue
            blo, bhi = fb["params_95"][key]
            d = (fb["params_mean"][key] - fa["params_mean"][key]) / (hi - lo)
            print(f"  | {key} | {fa['params_mean'][key]:.4g} | [{lo:.4g}, {hi:.4g}] | "
                  f"{fb['params_mean'][key]:.4g} | [{blo:.4g}, {bhi:.4g}] | {d:+.3f} |")
        for ch, s in fa["sigma"].items():
            print(f"  σ {ch}: A {s:.4g}, B {fb['sigma'][ch]:.4g}")

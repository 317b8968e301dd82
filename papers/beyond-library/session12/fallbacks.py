#!/usr/bin/env python3
"""The sampled fits that fell back to NUTS in two runs of whole-command reports (`motorcal
diagnose --json NAME.json`): per case and fit, the sampler, k̂, R-hat, the smallest bulk ESS,
the divergences and the fit's wall time in each run, and each case's whole runtime.

    fallbacks.py RUN_A RUN_B"""
import json, os, sys

a, b = sys.argv[1], sys.argv[2]
print("| case | fit | k̂ | A: R-hat, bulk ESS, div, fit s | B: R-hat, bulk ESS, div, fit s | whole command A → B |")
print("|---|---|---|---|---|---|")
n = 0
for name in sorted(os.listdir(a)):
    if not name.endswith(".json") or not os.path.exists(os.path.join(b, name)):
        continue
    ra, rb = (json.load(open(os.path.join(x, name))) for x in (a, b))
    for fit, ca in sorted(ra.get("convergence", {}).items()):
        cb = rb.get("convergence", {}).get(fit)
        if not cb or not (ca["fell_back"] or cb["fell_back"]):
            continue
        n += 1
        row = lambda c: f"{c['max_rhat']:.4f}, {c['min_ess_bulk']:.0f}, {c['divergences']}, {c['wall_s']:.1f}"
        print(f"| {name[:-5]} | {fit} | {ca['khat']:.2f} | {row(ca)} | {row(cb)} | "
              f"{ra['runtime_s']:.1f} → {rb['runtime_s']:.1f} s |")
print(f"\n{n} fits fell back to NUTS")

#!/usr/bin/env python3
"""Session 32: what is read against its truth — per case of speed_clip, sensor_gain_heat (the
fifteenth set) and current_skew (the sixteenth) in CASES, the truth's top speed (1 − cut)·24/c_m (c_m 0.01, the generator's nominal motor),
gain drift β or skew τ beside the model as given's fingerprint (its kind, place, ω_lim, its
functions, a lag's seconds) and the law discovered (its equation).

    truths.py CASES REPORTS   (REPORTS/CASE.json, `motorcal diagnose --json`)"""
import glob, json, os, re, sys

print("| case | truth | as given | law discovered |")
print("|---|---|---|---|")
for cases in sys.argv[1:-1]:
    reports = sys.argv[-1]
    for d in sorted(glob.glob(f"{cases}/*")):
        name = os.path.basename(d)
        if not re.match(r"(speed_clip|sensor_gain_heat|current_skew)-", name):
            continue
        truth = json.load(open(f"{d}/answer.json"))["truth"]
        value = lambda key: float(re.search(rf"{key}: ([-0-9.e]+)", truth).group(1))
        if name.startswith("speed_clip"):
            told = f"top {(1 - value('cut')) * 24 / 0.01:.1f} rad/s"
        elif name.startswith("sensor_gain_heat"):
            told = f"β {value('beta'):.3g} /J"
        else:
            told = f"τ {value('tau') * 1e3:.3f} ms"
        r = json.load(open(f"{reports}/{name}.json"))
        g = r.get("unexplained_as_given")
        f = g["fingerprint"] if g else {}
        parts = [f.get("kind", "—"), f.get("balance", f.get("channel", ""))]
        parts += [x["name"] for x in f.get("functions", [])]
        if "omega_lim" in f:
            parts.append(f"ω_lim {f['omega_lim']:.1f}")
        if "seconds" in f:
            parts.append(f"{f['seconds'] * 1e3:.3f} ms")
        law = r["discovered"]["equation"] if r.get("discovered") else "—"
        print(f"| {name} | {told} | {' '.join(p for p in parts if p)} | {law} |")

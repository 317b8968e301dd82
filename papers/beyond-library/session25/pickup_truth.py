"""The magnet pickups' truths as the law's two coefficients, a·cos φ on sin(θ) and a·sin φ on
cos(θ) (a·sin(θ + φ) expanded), from each case's answer.json, beside the law each report
discovered and its 95% intervals; and the verdict's sentence of each EMI-burst case.

python3 pickup_truth.py CASES REPORTS   (CASES the cases' folders, REPORTS the diagnose --json
files named CASE.json)"""
import json
import math
import os
import re
import sys

cases, reports = sys.argv[1], sys.argv[2]
print("| case | a | φ | truth on sin(θ) | truth on cos(θ) | discovered (balance: name coefficient [q025, q975]) |")
print("|---|---|---|---|---|---|")
for name in sorted(os.listdir(cases)):
    path = os.path.join(reports, name + ".json")
    if not os.path.exists(path):
        continue
    r = json.load(open(path))
    truth = json.load(open(os.path.join(cases, name, "answer.json")))["truth"]
    if name.startswith("magnet_pickup"):
        a = float(re.search(r"a: ([-\d.e]+)", truth).group(1))
        phase = float(re.search(r"phase: ([-\d.e]+)", truth).group(1))
        d = r["discovered"]
        law = "; ".join(f"{f['name']} {f['coefficient']:.3g} [{f['q025']:.3g}, {f['q975']:.3g}]"
                        for f in d["functions"]) if d else "—"
        balance = d["balance"] if d else "—"
        print(f"| {name} | {a:.3f} | {phase:.3f} | {a * math.cos(phase):.3f} | "
              f"{a * math.sin(phase):.3f} | {balance}: {law} |")
print()
for name in sorted(os.listdir(cases)):
    path = os.path.join(reports, name + ".json")
    if name.startswith("emi_bursts") and os.path.exists(path):
        u = json.load(open(path))["unexplained_as_given"]
        print(f"{name}: " + (f"{u['evidence']:.1f} nats: {u['suggestion']}" if u else "nothing missing found"))

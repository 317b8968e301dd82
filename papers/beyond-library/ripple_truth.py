#!/usr/bin/env python3
"""A torque ripple's law against its truth: for the generator's cases whose truth is a torque
−a·sin(k·θ + φ) (eccentric, cogging, bearing_defect), the truth's sine and cosine coefficients
−a·cos φ and −a·sin φ beside the discovered law's, and whether each 95% interval holds its
truth (a function the law does not hold is held at zero).

    ripple_truth.py CASES REPORTS
"""
import json, math, os, re, sys

cases, reports = sys.argv[1], sys.argv[2]
held_both = laws = 0
print("| case | truth k | law's k | truth sin, cos | law's sin [95%] | law's cos [95%] | both hold |")
print("|---|---|---|---|---|---|---|")
for case in sorted(os.listdir(cases)):
    p = os.path.join(reports, case, "report.json")
    if not os.path.exists(p):
        continue
    truth = json.load(open(os.path.join(cases, case, "answer.json")))["truth"]
    if not re.match(r"(Eccentric|Cogging|BearingDefect) ", truth):
        continue
    value = lambda key: float(re.search(rf"\b{key}: ([-0-9.e]+)", truth).group(1))
    a, phase = value("a"), value("phase")
    k = value("k") if " k: " in truth else 1.0
    want = {"sin(k*theta)": -a * math.cos(phase), "cos(k*theta)": -a * math.sin(phase)}
    law = json.load(open(p)).get("discovered")
    if not law or law["balance"] != "torque":
        laws += 1
        print(f"| {case} | {k:.3f} | — | {want['sin(k*theta)']:.4g}, {want['cos(k*theta)']:.4g} | — | — | no law in the torque balance |")
        continue
    got = {f["name"]: f for f in law["functions"]}
    cells, held = [], True
    for name, w in want.items():
        f = got.get(name)
        if f:
            cells.append(f"{f['coefficient']:.4g} [{f['q025']:.4g}, {f['q975']:.4g}]")
            held &= f["q025"] <= w <= f["q975"]
        else:
            cells.append("—")
            held = False
    others = [n for n in got if n not in want]
    laws += 1
    held_both += held and not others
    print(f"| {case} | {k:.3f} | {law.get('k', float('nan')):.3f} | {want['sin(k*theta)']:.4g}, {want['cos(k*theta)']:.4g} | "
          f"{cells[0]} | {cells[1]} | {'yes' if held and not others else 'no' + (' (also ' + ', '.join(others) + ')' if others else '')} |")
print(f"\nboth intervals hold the truth: {held_both} of {laws}")

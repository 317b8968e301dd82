#!/usr/bin/env python3
"""The discovered law of each case whose truth is a torque ripple in the angle (the
generator's fingerprint: torque balance, sin and cos of k*theta) against its truth, for one
or more runs.

    angle_laws.py SETDIR[,SETDIR...] RUN[,RUN...]

SETDIR holds the generator's cases (CASE/answer.json); RUN holds `motorcal diagnose --json`
reports as RUN/CASE.json. A law is counted right when it is in the torque balance, holds only
sin(k*theta) and cos(k*theta) (no I·, no other function), and its k is within 1/R of the
truth's, R the revolutions the record spans (the angle's Fourier spacing, the order search's
cell), read from the report's fit as the integral of the recorded speed. Prints one row per
case and run, then the count per run, in all and per effect."""
import csv, json, os, re, sys

sets, runs = sys.argv[1].split(","), sys.argv[2].split(",")

def revolutions(case):
    rows = list(csv.DictReader(open(os.path.join(case, "recording.csv"))))
    theta, lo, hi, prev = 0.0, 0.0, 0.0, None
    for r in rows:
        t, w = float(r["t"]), float(r["omega"])
        if prev is not None:
            theta += 0.5 * (t - prev[0]) * (w + prev[1])
        lo, hi, prev = min(lo, theta), max(hi, theta), (t, w)
    return (hi - lo) / (2 * 3.141592653589793)

right = {run: 0 for run in runs}
by_effect = {}
total = 0
print("| case | true k | 1/R | " + " | ".join(f"law ({os.path.basename(r.rstrip('/'))})" for r in runs) + " |")
print("|---|---|---|" + "---|" * len(runs))
for s in sets:
    for name in sorted(os.listdir(s)):
        case = os.path.join(s, name)
        answer = json.load(open(os.path.join(case, "answer.json")))
        k_true = answer["fingerprint"].get("k")
        if k_true is None or answer["fingerprint"].get("balance") != "torque":
            continue
        cell = 1.0 / revolutions(case)
        total += 1
        effect = answer["effect"]
        counts = by_effect.setdefault(effect, [0, {run: 0 for run in runs}])
        counts[0] += 1
        cells = []
        for run in runs:
            path = os.path.join(run, name + ".json")
            if not os.path.exists(path):
                cells.append("(no report)")
                continue
            d = json.load(open(path)).get("discovered")
            if not d:
                cells.append("none")
                continue
            names = {f["name"] for f in d["functions"]}
            ok = (d["balance"] == "torque" and names <= {"sin(k*theta)", "cos(k*theta)"}
                  and d.get("k") is not None and abs(d["k"] - k_true) <= cell)
            right[run] += ok
            counts[1][run] += ok
            law = d["equation"].split(" [")[0].replace("|", "\\|")
            cells.append(("**right** " if ok else "") + law)
        print(f"| {name} | {k_true:.4g} | {cell:.3g} | " + " | ".join(cells) + " |")
print()
for run in runs:
    print(f"{run}: right {right[run]}/{total}")
    for effect, (n, r) in sorted(by_effect.items()):
        print(f"  {effect}: {r[run]}/{n}")

#!/usr/bin/env python3
"""Session 33: per case of current_deadband, bearing_heat_drag, tacho_heat_offset (the sixteenth
set) and the seventeenth set's four effects in CASES, the truth (its debug text, and for a
resonance the truth's frequency) beside the model as given's fingerprint (kind, place,
functions and coefficients, frequency), the selection and the law discovered.

    truths.py CASES [CASES …] REPORTS   (REPORTS/CASE.json, `motorcal diagnose --json`)"""
import glob, json, os, re, sys

EFFECTS = r"(current_deadband|bearing_heat_drag|tacho_heat_offset|bus_sag|hall_compression|grease_thinning|load_side_encoder)-"
print("| case | truth | as given | selected | law discovered |")
print("|---|---|---|---|---|")
reports = sys.argv[-1]
for cases in sys.argv[1:-1]:
    for d in sorted(glob.glob(f"{cases}/*")):
        name = os.path.basename(d)
        if not re.match(EFFECTS, name):
            continue
        answer = json.load(open(f"{d}/answer.json"))
        told = answer["truth"]
        if "frequency_hz" in answer["fingerprint"]:
            told += f", {answer['fingerprint']['frequency_hz']:.1f} Hz"
        r = json.load(open(f"{reports}/{name}.json"))
        g = r.get("unexplained_as_given")
        f = g["fingerprint"] if g else {}
        parts = [f.get("kind", "—"), f.get("balance", f.get("channel", ""))]
        parts += [f"{x['name']} {x['coefficient']:.3g}" for x in f.get("functions", [])]
        if "frequency_hz" in f:
            parts.append(f"{f['frequency_hz']:.1f} Hz")
        law = (r.get("discovered") or {}).get("equation", "—")
        print(f"| {name} | {told} | {' '.join(p for p in parts if p)} | {r['selected']} | {law} |")

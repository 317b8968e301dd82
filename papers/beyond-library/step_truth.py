#!/usr/bin/env python3
"""The step of a reading in steps found by the verdict against the generator's truth, on the
`speed_quantization` cases of `beyond_library_cases` sets.

    step_truth.py CASES:REPORTS ...

CASES holds the cases (answer.json with `SpeedQuantization { q: … }`), REPORTS the reports
REPORTS/CASE/report.json (`motorcal diagnose --rank-only --json`). For each case: the verdict
(unexplained, then on the model as given), the step q reported by a fingerprint with one, and
its error against the truth."""
import json, os, re, sys

print("| case | truth q | verdict | q found | error |")
print("|---|---|---|---|---|")
found = total = 0
for pair in sys.argv[1:]:
    cases, reports = pair.split(":")
    for case in sorted(os.listdir(cases)):
        if not case.startswith("speed_quantization"):
            continue
        answer = json.load(open(os.path.join(cases, case, "answer.json")))
        q = float(re.search(r"q: ([0-9.eE+-]+)", answer["truth"]).group(1))
        report = json.load(open(os.path.join(reports, case, "report.json")))
        total += 1
        verdicts = [("unexplained", report.get("unexplained")),
                    ("as given", report.get("unexplained_as_given"))]
        shown = None
        for name, v in verdicts:
            if not v:
                continue
            for f in [v["fingerprint"]] + v.get("alternatives", []):
                if f.get("q") is not None:
                    shown = (name, f["q"])
                    break
            if shown:
                break
        verdict = "unexplained" if report.get("unexplained") else "nothing missing found" \
            if not report["selected_set"] else "null after " + " + ".join(report["selected_set"])
        if shown:
            found += 1
            print(f"| {case} | {q:.4f} | {verdict} | {shown[1]:.4f} ({shown[0]}) | {100 * (shown[1] / q - 1):+.3f}% |")
        else:
            print(f"| {case} | {q:.4f} | {verdict} | — | — |")
print(f"\na step reported on {found} of {total}")

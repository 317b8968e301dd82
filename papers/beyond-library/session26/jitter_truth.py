"""The jitter cases' truths beside what the verdict reports: for each sample_jitter case in
CASES (answer.json) and its report in REPORTS (<case>.json), the truth's sd s, the verdict's
kind and evidence, and the sd its sentence states where it is a noise that follows the slope.
Usage: python3 jitter_truth.py CASES REPORTS"""
import json
import os
import re
import sys

cases, reports = sys.argv[1], sys.argv[2]
print("| case | truth's s (µs) | selected | verdict | its s (µs) | its s / truth's |")
print("|---|---|---|---|---|---|")
for name in sorted(os.listdir(cases)):
    if not name.startswith("sample_jitter"):
        continue
    answer = json.load(open(os.path.join(cases, name, "answer.json")))
    truth = float(re.search(r"s: ([0-9.e-]+)", answer["truth"]).group(1)) * 1e6
    report = json.load(open(os.path.join(reports, name + ".json")))
    u = report.get("unexplained")
    verdict, found = "null", None
    if u:
        verdict = f"{u['fingerprint']['kind']} ({u['evidence']:.1f} nats)"
        m = re.search(r"off by about ([0-9.]+) µs", u["suggestion"])
        if m:
            found = float(m.group(1))
            verdict += ", the slope's noise"
    ratio = f"{found / truth:.2f}" if found else "—"
    print(f"| {name} | {truth:.1f} | {report.get('selected')} | {verdict} | "
          f"{found if found else '—'} | {ratio} |")

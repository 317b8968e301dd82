#!/usr/bin/env python3
"""What `diagnose` reports on encoder_glitch cases: the verdict's kind and evidence, the samples
its `where` names, how many of them the encoder miscounted (recomputed from the case's salt as
examples/beyond_library_cases.rs draws them) and how many miscounts it names.

    outlier_table.py CASES REPORTS    (REPORTS/CASE.json, `diagnose --json`)
"""
import csv, glob, json, os, sys

from miscounts import case_truth, miscounted



cases, reports = sys.argv[1], sys.argv[2]
print("| case | size (σ) | miss (nats) | verdict | named | of them miscounts | miscounts named / all |")
print("|---|---|---|---|---|---|---|")
named_total = right_total = found_total = all_total = 0
kinds = {}
for case in sorted(glob.glob(f"{cases}/encoder_glitch-*/")):
    name = os.path.basename(case.rstrip("/"))
    answer, salt, a = case_truth(case)
    times = [float(r["t"]) for r in csv.DictReader(open(f"{case}/recording.csv"))]
    truth = {round(times[k], 9) for k in range(len(times)) if miscounted(salt, k)}
    report = json.load(open(f"{reports}/{name}.json"))
    u = report.get("unexplained")
    kind = u["fingerprint"]["kind"] if u else None
    kinds[kind] = kinds.get(kind, 0) + 1
    named = {round(s["t_start"], 9) for s in u["where"] if s["t_start"] == s["t_end"]} if u else set()
    right = len(named & truth)
    named_total += len(named); right_total += right; found_total += right; all_total += len(truth)
    verdict = f"{kind} (+{u['evidence']:.1f})" if u else "nothing missing"
    print(f"| {name} | {a / 10:.2f} | {answer['miss_nats']:.1f} | {verdict} | {len(named)} | {right} | {right} / {len(truth)} |")
print(f"\nverdicts: {kinds}; samples named {named_total}, of them miscounts {right_total}; "
      f"miscounts named {found_total} of {all_total}")

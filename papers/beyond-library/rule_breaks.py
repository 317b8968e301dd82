#!/usr/bin/env python3
"""Two of issue 19's rules, case by case, over sets of independent-integrator cases: never
"nothing missing found" (nothing selected, the verdict null) where the noise-free truth misses
the nominal model by 30 nats or more (answer.json's `miss_nats`); and the library terms
selected with the verdict null where the library's best single term leaves 10 nats or more of
that miss (the library-residual table: a selection of a dynamic term, or of two library terms
together, is listed for reading, since that table scores single terms of the thirteen).

    rule_breaks.py CASES:REPORTS:LIBRARY_RESIDUAL ...

REPORTS holds REPORTS/CASE/report.json (`motorcal diagnose --rank-only --json`)."""
import sys

from case_sets import cases_with_reports

nothing, standing = [], []
total = 0
for case, answer, r, lib in cases_with_reports(sys.argv[1:]):
    total += 1
    miss = answer["miss_nats"]
    if r["unexplained"]:
        continue
    if not r["selected_set"] and miss >= 30:
        nothing.append(f"{case} ({miss:.1f} nats)")
    if r["selected_set"] and "law" not in r["selected_set"] and lib >= 10:
        standing.append(f"{case}: {' + '.join(r['selected_set'])} ({lib:.1f} nats left by the best single term)")
print(f"{total} cases")
print(f"\"nothing missing found\" on a miss of 30 nats or more: {len(nothing)}")
for x in nothing:
    print(f"  {x}")
print(f"library terms selected, verdict null, the best single term leaving 10 nats or more: {len(standing)}")
for x in standing:
    print(f"  {x}")

#!/usr/bin/env python3
"""Per case, the median runtime of each build in ab_runtimes.sh's output, and each build's
ratio to the first build's median on that case.

    ab_summary.py AB_RUNTIMES_TXT"""
import collections, statistics, sys

runs = collections.defaultdict(list)
builds, cases = [], []
for line in open(sys.argv[1]):
    build, _, case, t = line.split()
    runs[(build, case)].append(float(t))
    if build not in builds:
        builds.append(build)
    if case not in cases:
        cases.append(case)
print("| case | " + " | ".join(builds) + " |")
print("|---" * (len(builds) + 1) + "|")
for case in cases:
    base = statistics.median(runs[(builds[0], case)])
    cells = []
    for b in builds:
        m = statistics.median(runs[(b, case)])
        cells.append(f"{m:.1f} s ({m / base:.2f})")
    print(f"| {case} | " + " | ".join(cells) + " |")

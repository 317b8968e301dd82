#!/usr/bin/env python3
"""Whole-command times of two builds run per case one after the other (`runtime_s` of each
NAME.json), side by side: per case the two times and their ratio, then the medians, the
totals, the median ratio and the count over 30 s for each build.

    paired_times.py RUN_A RUN_B"""
import json, os, statistics, sys

a_dir, b_dir = sys.argv[1:3]
rows = []
for f in sorted(os.listdir(a_dir)):
    if not f.endswith(".json") or not os.path.exists(os.path.join(b_dir, f)):
        continue
    a = json.load(open(os.path.join(a_dir, f)))["runtime_s"]
    b = json.load(open(os.path.join(b_dir, f)))["runtime_s"]
    rows.append((f[:-5], a, b))
print(f"{len(rows)} cases, {a_dir} then {b_dir}, per case")
print("| case | A (s) | B (s) | B/A |\n|---|---|---|---|")
for n, a, b in sorted(rows, key=lambda r: -r[1]):
    print(f"| {n} | {a:.1f} | {b:.1f} | {b / a:.2f} |")
for label, k in (("A", 1), ("B", 2)):
    t = [r[k] for r in rows]
    print(f"{label}: median {statistics.median(t):.1f} s, total {sum(t):.0f} s, "
          f"max {max(t):.1f} s, over 30 s: {sum(x > 30 for x in t)}")
print(f"median B/A {statistics.median(r[2] / r[1] for r in rows):.2f}, "
      f"total B/A {sum(r[2] for r in rows) / sum(r[1] for r in rows):.2f}")

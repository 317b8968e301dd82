#!/usr/bin/env python3
"""Two `diagnose_study` runs' study.csv compared case by case: how many cases have the same
selection, selected set, ties, right/wrong and verdict, which differ and how, and the second
run's right counts per set.

    compare_studies.py BASELINE/study.csv NEW/study.csv"""
import csv, sys
from collections import Counter

KEYS = ["selected", "selected_set", "ties", "right", "unexplained"]


def load(path):
    return {r["case"]: r for r in csv.DictReader(open(path))}


base, new = load(sys.argv[1]), load(sys.argv[2])
same, differ = 0, []
for case, row in new.items():
    if case not in base:
        differ.append((case, "not in the baseline"))
    elif all(base[case][k] == row[k] for k in KEYS):
        same += 1
    else:
        differ.append((case, {k: (base[case][k], row[k]) for k in KEYS if base[case][k] != row[k]}))
print(f"the same: {same} of {len(new)} (baseline {len(base)})")
for d in differ:
    print(d)
count, right = Counter(), Counter()
for row in new.values():
    count[row["set"]] += 1
    right[row["set"]] += row["right"] == "true"
print({s: f"{right[s]}/{count[s]}" for s in count})

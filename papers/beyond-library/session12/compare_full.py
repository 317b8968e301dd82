#!/usr/bin/env python3
"""Two runs of whole-command reports (`motorcal diagnose --json NAME.json`) compared field by
field, the times left out (runtime_s, ranking_s, selection_s, each fit's wall_s) and the paths
written (outputs). Prints, per case, the fields that differ (a path into the JSON), then the
counts.

    compare_full.py RUN_A RUN_B"""
import json, os, sys

TIMES = {"runtime_s", "ranking_s", "selection_s", "wall_s", "outputs"}


def diff(x, y, path, out):
    if type(x) != type(y):
        out.append(path)
    elif isinstance(x, dict):
        for k in sorted(set(x) | set(y)):
            if k in TIMES:
                continue
            if k not in x or k not in y:
                out.append(f"{path}/{k}")
            else:
                diff(x[k], y[k], f"{path}/{k}", out)
    elif isinstance(x, list):
        if len(x) != len(y):
            out.append(f"{path} (length)")
        else:
            for i, (u, v) in enumerate(zip(x, y)):
                diff(u, v, f"{path}[{i}]", out)
    elif x != y:
        out.append(path)


a, b = sys.argv[1], sys.argv[2]
same = differ = 0
for name in sorted(os.listdir(a)):
    if not name.endswith(".json") or not os.path.exists(os.path.join(b, name)):
        continue
    out = []
    diff(json.load(open(os.path.join(a, name))), json.load(open(os.path.join(b, name))), "", out)
    if out:
        differ += 1
        print(f"{name[:-5]}: {', '.join(out[:8])}{' …' if len(out) > 8 else ''}")
    else:
        same += 1
print(f"{same} reports the same (times and paths aside), {differ} differ")

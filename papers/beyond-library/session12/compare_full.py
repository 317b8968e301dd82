#!/usr/bin/env python3
"""Two runs of whole-command reports (`motorcal diagnose --json NAME.json`) compared field by
field, the times left out (runtime_s, ranking_s, selection_s, each fit's wall_s) and the paths
written (outputs). Prints, per case, the fields that differ (a path into the JSON), then the
counts.

    compare_full.py [--ignore-units-of FUNCTION] RUN_A RUN_B

With --ignore-units-of, the `units` entries naming FUNCTION are left out too (a function new
to the law's dictionary, which every report's `units` lists once it is there)."""
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


args = sys.argv[1:]
ignored = None
if args[0] == "--ignore-units-of":
    ignored, args = args[1], args[2:]
a, b = args[0], args[1]


def load(path):
    report = json.load(open(path))
    if ignored and isinstance(report.get("units"), dict):
        report["units"] = {k: v for k, v in report["units"].items() if ignored not in k}
    return report


same = differ = 0
for name in sorted(os.listdir(a)):
    if not name.endswith(".json") or not os.path.exists(os.path.join(b, name)):
        continue
    out = []
    diff(load(os.path.join(a, name)), load(os.path.join(b, name)), "", out)
    if out:
        differ += 1
        print(f"{name[:-5]}: {', '.join(out[:8])}{' …' if len(out) > 8 else ''}")
    else:
        same += 1
aside = f"times, paths and the units of {ignored}" if ignored else "times and paths"
print(f"{same} reports the same ({aside} aside), {differ} differ")

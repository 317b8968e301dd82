#!/usr/bin/env python3
"""session12/compare_full.py with the units of the law's new function (the spot of the angle,
which every report's `units` lists once it is in the dictionary) left out: two runs of
whole-command reports compared field by field, times and paths aside.

    compare_full.py RUN_A RUN_B"""
import json, os, sys

NEW = "omega*exp(-2*(1-cos(theta-theta_0))/w^2)"


def strip(report):
    units = report.get("units")
    if isinstance(units, dict):
        report["units"] = {k: v for k, v in units.items() if NEW not in k}
    return report


# session12's `diff`, its own code (the part before its command line).
ns = {}
exec(open(os.path.join(os.path.dirname(__file__), "..", "session12", "compare_full.py")).read()
     .split("\na, b = sys.argv")[0], ns)
a, b = sys.argv[1], sys.argv[2]
same = differ = 0
for name in sorted(os.listdir(a)):
    if not name.endswith(".json") or not os.path.exists(os.path.join(b, name)):
        continue
    out = []
    ns["diff"](strip(json.load(open(os.path.join(a, name)))), strip(json.load(open(os.path.join(b, name)))), "", out)
    if out:
        differ += 1
        print(f"{name[:-5]}: {', '.join(out[:8])}{' …' if len(out) > 8 else ''}")
    else:
        same += 1
print(f"{same} reports the same (times, paths and the new function's units aside), {differ} differ")

#!/usr/bin/env python3
"""Two runs of rank-only reports compared case by case: the selection, the verdict (null or
unexplained), the model as given's fingerprint (kind and balance or channel) and the
discovered law's equation without its intervals. Prints each case that differs and the
counts.

    compare_reports.py RUN_A RUN_B

RUN_A and RUN_B hold SET/CASE/report.json (`motorcal diagnose --rank-only --json`)."""
import json, os, sys

a, b = sys.argv[1], sys.argv[2]

def key(r):
    u, g, d = r.get("unexplained"), r.get("unexplained_as_given"), r.get("discovered")
    kind = g and g["fingerprint"]["kind"] + ":" + (g["fingerprint"].get("balance") or g["fingerprint"].get("channel") or "")
    return (" + ".join(r["selected_set"]) or "none", "unexplained" if u else "null", kind,
            d and d["equation"].split(" [")[0])

same = differ = 0
for s in sorted(os.listdir(a)):
    if not os.path.isdir(os.path.join(a, s)):
        continue
    for c in sorted(os.listdir(os.path.join(a, s))):
        pa, pb = (os.path.join(x, s, c, "report.json") for x in (a, b))
        if not (os.path.exists(pa) and os.path.exists(pb)):
            continue
        ka, kb = key(json.load(open(pa))), key(json.load(open(pb)))
        if ka == kb:
            same += 1
        else:
            differ += 1
            print(f"{s}/{c}\n   A: {ka}\n   B: {kb}")
print(f"the same: {same}; different: {differ}")

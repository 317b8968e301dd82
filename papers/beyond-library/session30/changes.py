#!/usr/bin/env python3
"""Per case, where two runs' reports differ in the model as given's kind or in whether the
verdict after is null, or where knocks are named: the fingerprint (kind, evidence; the knocks'
instants) as given and after, in each run.

    changes.py RUN_A RUN_B   (RUN/CASE.json, `motorcal diagnose --json`)"""
import glob, json, os, sys

a, b = sys.argv[1:3]


def fp(r, key):
    u = r.get(key)
    if not u:
        return "—"
    s = u["fingerprint"]["kind"]
    if "jolted" in u["suggestion"]:
        s += " (knocks at " + u["suggestion"].split("t = ")[1].split(" s)")[0] + " s)"
    return s + f" {u['evidence']:.1f}"


n_same = 0
for f in sorted(glob.glob(f"{b}/*.json")):
    n = os.path.basename(f)[:-5]
    if not os.path.exists(f"{a}/{n}.json"):
        continue
    ra, rb = json.load(open(f"{a}/{n}.json")), json.load(open(f))
    x = (fp(ra, "unexplained_as_given"), fp(ra, "unexplained"))
    y = (fp(rb, "unexplained_as_given"), fp(rb, "unexplained"))
    if x[0].split()[0] != y[0].split()[0] or (x[1] == "—") != (y[1] == "—") or "knocks" in "".join(y):
        print(f"| {n} | {x[0]} | {y[0]} | {x[1]} | {y[1]} |")
    else:
        n_same += 1
print(f"\n{n_same} other cases: the same kind as given and the same null or not after, no knocks")

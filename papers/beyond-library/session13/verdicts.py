"""Per case of two report folders: the verdict (selected terms, the unexplained kind, the
residual mismatch), the discovered equation, and the runtimes. Usage: verdicts.py OLD NEW"""
import glob, json, os, statistics, sys

old, new = sys.argv[1:]
rows = []
for p in sorted(glob.glob(f"{old}/*.json")):
    n = os.path.basename(p)[:-5]
    a, b = json.load(open(p)), json.load(open(f"{new}/{n}.json"))
    verdict = lambda r: (r["selected_set"], ((r["unexplained"] or {}).get("fingerprint") or {}).get("kind"), r["residual_mismatch"])
    law = lambda r: (r["discovered"] or {}).get("equation")
    rows.append((n, a["runtime_s"], b["runtime_s"]))
    if verdict(a) != verdict(b):
        print(f"{n}: verdict {verdict(a)} -> {verdict(b)}")
    elif law(a) != law(b):
        print(f"{n}: the same verdict; law\n    {law(a)}\n    {law(b)}")
print(f"{len(rows)} cases; runtime median {statistics.median(r[1] for r in rows):.1f} -> {statistics.median(r[2] for r in rows):.1f} s, "
      f"total {sum(r[1] for r in rows):.0f} -> {sum(r[2] for r in rows):.0f} s")
for n, a, b in rows:
    if abs(a - b) > 2.0:
        print(f"  {n}: {a:.1f} -> {b:.1f} s")

"""Selections and times of run.sh's output: python3 compare.py OUT_DIR A_NAME B_NAME"""
import csv, json, statistics, sys
out, a, b = sys.argv[1:4]
rows = list(csv.DictReader(open(f"{out}/times.csv")))
cases = sorted({r["case"] for r in rows})
same = 0
print("| case | selected (A) | selected (B) | same | user A s | user B s | wall A s | wall B s |")
print("|---|---|---|---|---|---|---|---|")
ua, ub, wa, wb = [], [], [], []
for c in cases:
    ja = json.load(open(f"{out}/{c}-{a}.json")); jb = json.load(open(f"{out}/{c}-{b}.json"))
    sa = "+".join(ja["selected_set"]) or "none"; sb = "+".join(jb["selected_set"]) or "none"
    verdict_same = (ja.get("unexplained") is None) == (jb.get("unexplained") is None)
    ok = sa == sb and verdict_same
    same += ok
    med = lambda n, k: statistics.median(float(r[k]) for r in rows if r["case"] == c and r["binary"] == n)
    ua.append(med(a, "user_s")); ub.append(med(b, "user_s")); wa.append(med(a, "wall_s")); wb.append(med(b, "wall_s"))
    print(f"| {c} | {sa} | {sb} | {'yes' if ok else 'NO'} | {ua[-1]:.2f} | {ub[-1]:.2f} | {wa[-1]:.2f} | {wb[-1]:.2f} |")
print(f"\nsame selection and verdict: {same} of {len(cases)}")
print(f"median user s: A {statistics.median(ua):.2f}, B {statistics.median(ub):.2f}; median wall s: A {statistics.median(wa):.2f}, B {statistics.median(wb):.2f}")
print(f"median of per-case wall ratios B/A: {statistics.median(y / x for x, y in zip(wa, wb)):.2f}")
print(f"max wall s: A {max(wa):.2f}, B {max(wb):.2f}")

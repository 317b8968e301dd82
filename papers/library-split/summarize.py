"""The wall-time summary of times.csv: per case the median of the three repeats, before and
after, their ratio, then the median over cases and the sums.  python3 summarize.py"""
import collections
import csv
import statistics as st

rows = list(csv.DictReader(open("times.csv")))
runs = collections.defaultdict(list)
for r in rows:
    runs[(r["case"], r["build"])].append(float(r["wall_s"]))
cases = sorted({c for c, _ in runs})
old = [st.median(runs[(c, "old")]) for c in cases]
new = [st.median(runs[(c, "new")]) for c in cases]
for c, o, n in zip(cases, old, new):
    print(f"{c} {o:.2f} {n:.2f} {n / o:.2f}")
ratios = [n / o for o, n in zip(old, new)]
print(f"runs {len(rows)}; median of per-case medians: before {st.median(old):.2f} s, after "
      f"{st.median(new):.2f} s; median ratio {st.median(ratios):.3f} "
      f"(range {min(ratios):.2f}-{max(ratios):.2f}); sums {sum(old):.1f} s, {sum(new):.1f} s")

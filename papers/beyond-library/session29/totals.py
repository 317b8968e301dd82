#!/usr/bin/env python3
"""Totals of kind_table.py's tables over sets: `totals.py [--apart SET] kind-tables-X.md`
prints, per set and summed, the cases of the truth's kind outside the library (the cut: the
library's best single term leaves >= 10 nats) and over all cases; and, on the blind sets, the
misses at the cut by the as-given kind. With --apart (session 30: h90), the sets from SET on
(by name) are summed on a line of their own and left out of the blind sets' line."""
import re, sys

args = sys.argv[1:]
apart = None
if args[0] == "--apart":
    apart, args = args[1], args[2:]
blind = lambda s: s >= "h78" and (apart is None or s < apart)
rows, s, misses = [], None, {}
for line in open(args[0]):
    if line.startswith("### "):
        s = line[4:].strip()
    m = re.match(r"\| (\S+) \| (\S+) \| (\S+) \| ([\d.]+) \|", line)
    if m and blind(s) and float(m[4]) >= 10:
        misses.setdefault(m[3], []).append(m[1])
    m = re.match(r"all cases: (\d+) of (\d+)", line)
    if m:
        rows.append([s, int(m[1]), int(m[2]), 0, 0])
    m = re.match(r"outside the library .*\(the cut\): (\d+) of (\d+)", line)
    if m:
        rows[-1][3:] = [int(m[1]), int(m[2])]
for r in rows:
    print(f"{r[0]:6s} all {r[1]:3d}/{r[2]:<3d} outside {r[3]:3d}/{r[4]:<3d}")
groups = [("sessions 19-28's blind sets (h78-h85v)", [r for r in rows if blind(r[0])])]
if apart:
    groups.append((f"the sets from {apart} on", [r for r in rows if r[0] >= apart]))
for name, sel in groups + [("all sets", rows)]:
    a, b, c, d = (sum(r[i] for r in sel) for i in (1, 2, 3, 4))
    print(f"{name}: all {a}/{b}, outside the library {c}/{d} ({100 * c / d:.0f}%)")
print(f"blind misses at the cut by the model as given's kind: "
      + "; ".join(f"{k} {len(v)} ({', '.join(v)})" for k, v in sorted(misses.items())))

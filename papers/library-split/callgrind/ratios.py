"""New/old instruction ratios from counts.csv (run.sh)."""
import csv
import sys

rows = list(csv.DictReader(open(sys.argv[1])))
count = {(r["k"], r["what"], r["side"]): int(r["instructions"]) for r in rows}
print("| K | operation | before (7ef8f36) | after | after/before |")
print("|---|---|---|---|---|")
for (k, what, side), old in count.items():
    if side == "old":
        new = count[(k, what, "new")]
        print(f"| {k} | {what} | {old:,} | {new:,} | {new / old:.3f} |")

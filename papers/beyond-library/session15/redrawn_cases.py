"""Which cases of two runs of the same study seeds the generator made differently.

python3 redrawn_cases.py NAME OLD.csv NEW.csv [NAME OLD.csv NEW.csv ...]

A case is redrawn where its oracle margin or its input differs between the two study.csv files
(the draw was replaced); each is printed with both runs' verdicts, then the cases made in one run
only.
"""
import csv
import sys

args = sys.argv[1:]
print("# Cases the generator made differently between two runs of the same seeds (the oracle's")
print("# expected margin or the input differs: the draw was replaced), with both runs' verdicts.")
for i in range(0, len(args), 3):
    name, a, b = args[i:i + 3]
    old = {r["case"]: r for r in csv.DictReader(open(a))}
    new = {r["case"]: r for r in csv.DictReader(open(b))}
    changed = [c for c in new if c in old and (old[c]["oracle_margin"] != new[c]["oracle_margin"]
                                                or old[c]["input"] != new[c]["input"])]
    gone = [c for c in old if c not in new]
    made = [c for c in new if c not in old]
    print(f"{name}: {len(new)} cases, {len(changed)} redrawn, {len(gone)} no longer made, "
          f"{len(made)} new in their place")
    for c in changed:
        o, n = old[c], new[c]
        print(f"  {c}: margin {o['oracle_margin']} -> {n['oracle_margin']}, input {o['input']} -> "
              f"{n['input']}, right {o['right']} -> {n['right']}, ties '{o['ties']}' -> '{n['ties']}'")
    for c in gone:
        print(f"  no longer made: {c} (right {old[c]['right']})")
    for c in made:
        print(f"  new: {c} (right {new[c]['right']})")

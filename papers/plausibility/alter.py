#!/usr/bin/env python3
"""The mistakes engineers make with real files, made on purpose: each altered copy of a recording
is written to `altered/NAME.csv` beside a line in `altered/cases.csv` naming the mistake, the
model file it is diagnosed with, and the cause the check should name.

python3 alter.py SHARED OUT   (SHARED: ../shared/data; OUT: the folder for altered/)
"""
import csv, math, random, sys
from pathlib import Path

shared, out = Path(sys.argv[1]), Path(sys.argv[2]) / "altered"
out.mkdir(parents=True, exist_ok=True)

def read(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]

def write(name, header, rows):
    with open(out / f"{name}.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows([[repr(x) for x in r] for r in rows])

def scaled(rows, col, factor):
    return [[x * factor if j == col else x for j, x in enumerate(r)] for r in rows]

case = shared / "concealed-dev/case04"
header, rows = read(case / "recording.csv")
t, i, w = header.index("t"), header.index("I"), header.index("omega")
rng = random.Random(23)
cases = [
    # name, rows, model, expected cause (a word the finding or likely cause must hold)
    ("all_zero", [[r[t]] + [0.0] * (len(r) - 1) for r in rows], "drive running"),
    ("swapped_I_omega", [[r[t], r[w], r[i]] for r in rows], "swapped"),
    ("current_1e12", scaled(rows, i, 1e12), "unit"),
    ("current_in_mA", scaled(rows, i, 1e3), "mA"),
    ("speed_in_rpm", scaled(rows, w, 60 / (2 * math.pi)), "rpm"),
    ("current_sign_flipped", scaled(rows, i, -1.0), "sign"),
    ("time_in_ms", scaled(rows, t, 1e3), "ms"),
    ("speed_constant", [[r[t], r[i], 1234.5] for r in rows], "drive running"),
    ("pure_noise", [[r[t], rng.gauss(0, 2.0), rng.gauss(0, 10.0)] for r in rows], "follow"),
]
model = case / "motor.toml"
lines = []
for name, altered, cause in cases:
    write(name, header, altered)
    lines.append((name, str(model), cause))

# The long real record, for the check's time on ~25 000 samples: EMPS with its force in kN.
emps = shared / "real/emps/emps_estimation.csv"
header, rows = read(emps)
write("emps_force_in_kN", header, scaled(rows, header.index("force_N"), 1e-3))
lines.append(("emps_force_in_kN", "EMPS_MODEL", "kN"))

with open(out / "cases.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["case", "model", "expected_cause"])
    w.writerows(lines)

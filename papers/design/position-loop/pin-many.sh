#!/bin/sh
# Session 21: the pinned sds of the position loop over many records, not one. The same design
# as pin-fit-fixed.sh (`design --pin J,d`, force ±300 N, σ_q = 2 µm, σ_force = 5 N); for each
# input (the designed one and the three fixed), RECORDS records (seeds 9001…) are simulated and
# fitted by `motorcal fit --map-only` (BM1). Printed per input: the sd over the records of the
# MAP J and d (the sampling spread the expected sd predicts), and the mean Laplace sd (the
# posterior width each record shows), each over design.json's expected sd. FIX the model
# (default the fixture; a copy with `q0_offset = {}` under [calibrate] calibrates the initial
# position's offset). BIN a build of the commit named in papers/design.md.
set -e
BIN=${BIN:-motorcal}
RECORDS=${RECORDS:-50}
HERE=$(cd "$(dirname "$0")" && pwd); ROOT=$HERE/../../..
FIX=${FIX:-$ROOT/tests/fixtures/design/position_loop.toml}
W=${W:-/tmp/design-position-many}
rm -rf $W; mkdir -p $W
$BIN design --model $FIX --pin J,d --duration 1 --rate 1000 --limits q=±0.1,omega=±0.5,force=±300 \
    --noise-sd 2e-6 5 --out $W/pin > $W/design.txt
for INPUT in input fixed-constant fixed-reversal fixed-step; do
  for K in $(seq 1 $RECORDS); do SEED=$((9000 + K))
    $BIN simulate --truth $FIX --input $W/pin/$INPUT.csv --noise-sd 2e-6 5 --seed $SEED --out $W/$INPUT-$SEED-rec > /dev/null
    $BIN fit --data $W/$INPUT-$SEED-rec/recording.csv --model $FIX --bm 1 --map-only --quiet \
        --out $W/$INPUT-$SEED-fit > /dev/null
  done
done
python3 - "$W" "$RECORDS" <<'PY'
import json, math, sys, statistics
w, records = sys.argv[1], int(sys.argv[2])
report = json.load(open(f"{w}/pin/design.json"))
expected = {"input": report["expected_sd"]}
for e in report["fixed_experiments"]:
    expected[e["file"][:-4]] = e["expected_sd"]
print(f"{records} records per input, MAP fits (BM1)\n")
print("| input | J: sd of MAPs / expected | ratio | mean Laplace sd / expected | ratio "
      "| d: sd of MAPs / expected | ratio | mean Laplace sd / expected | ratio |")
print("|---|---|---|---|---|---|---|---|---|")
for name, sd in expected.items():
    maps, widths = {"J": [], "d": []}, {"J": [], "d": []}
    for k in range(1, records + 1):
        fit = json.load(open(f"{w}/{name}-{9000 + k}-fit/fit.json"))
        for p in fit["map"]:
            key = p["name"][len("log_"):]
            if key in maps:
                value = math.exp(p["value"])
                maps[key].append(value)
                widths[key].append(value * p["laplace_sd"])
    cells = []
    for key in ("J", "d"):
        spread, width = statistics.stdev(maps[key]), statistics.mean(widths[key])
        cells += [f"{spread:.4g} / {sd[key]:.4g}", f"{spread / sd[key]:.3f}",
                  f"{width:.4g} / {sd[key]:.4g}", f"{width / sd[key]:.3f}"]
    label = "designed" if name == "input" else name[len("fixed-"):]
    print(f"| {label} | " + " | ".join(cells) + " |")
# What the Fisher matrix leaves out: the initial position is the first measured q, noise and
# all, so the records' J moves with that sample's noise.
print("\n| input | corr(first measured q, MAP J) | corr(first measured q, MAP d) |")
print("|---|---|---|")
import csv
for name in expected:
    first, found = [], {"J": [], "d": []}
    for k in range(1, records + 1):
        row = next(csv.DictReader(open(f"{w}/{name}-{9000 + k}-rec/recording.csv")))
        first.append(float(row["q"]))
        for p in json.load(open(f"{w}/{name}-{9000 + k}-fit/fit.json"))["map"]:
            key = p["name"][len("log_"):]
            if key in found:
                found[key].append(math.exp(p["value"]))
    def corr(a, b):
        ma, mb = statistics.mean(a), statistics.mean(b)
        num = sum((x - ma) * (y - mb) for x, y in zip(a, b))
        return num / math.sqrt(sum((x - ma) ** 2 for x in a) * sum((y - mb) ** 2 for y in b))
    label = "designed" if name == "input" else name[len("fixed-"):]
    print(f"| {label} | {corr(first, found['J']):.3f} | {corr(first, found['d']):.3f} |")
# Where the model puts the axis at its first sample: the first measured q, plus the offset
# where the model calibrates q0_offset (the truth starts at rest at the reference's 0).
print("\n| input | start: mean | sd over the records | mean Laplace sd of q0_offset | sd of the first measured q |")
print("|---|---|---|---|---|")
for name in expected:
    start, width, first = [], [], []
    for k in range(1, records + 1):
        row = next(csv.DictReader(open(f"{w}/{name}-{9000 + k}-rec/recording.csv")))
        offset = [p for p in json.load(open(f"{w}/{name}-{9000 + k}-fit/fit.json"))["map"]
                  if p["name"] == "q0_offset"]
        first.append(float(row["q"]))
        start.append(first[-1] + (offset[0]["value"] if offset else 0.0))
        width.append(offset[0]["laplace_sd"] if offset else 0.0)
    label = "designed" if name == "input" else name[len("fixed-"):]
    print(f"| {label} | {statistics.mean(start):.3g} | {statistics.stdev(start):.3g} | "
          f"{statistics.mean(width):.3g} | {statistics.stdev(first):.3g} |")
# The sd of a sample sd of n normal draws is about sd/√(2(n−1)): the spread's ratio is known to
# within that share.
print(f"\nthe sd of the MAPs' sd over {records} records is known to ±{1 / math.sqrt(2 * (records - 1)):.1%} (one sd)")
PY

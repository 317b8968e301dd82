#!/bin/sh
# Session 18: the pinned sds of the fixed inputs (constant, reversal, step) confirmed by fits,
# as pin-fit.sh confirms the designed input's. `design --pin J,d` as run.sh runs it, which now
# writes each fixed experiment beside input.csv (fixed-<input>.csv, at the level it was scored
# at); one record of each input (seed 9000, σ_q = 2 µm, σ_force = 5 N) is fitted by `motorcal
# fit` (BM1, NUTS with the dense metric, 4 chains), and its posterior sds are set beside the
# expected ones of design.json. BIN a build of the commit named in papers/design.md.
set -e
BIN=${BIN:-motorcal}
HERE=$(cd "$(dirname "$0")" && pwd); ROOT=$HERE/../../..
FIX=$ROOT/tests/fixtures/design/position_loop.toml
W=${W:-/tmp/design-position-fixed}
rm -rf $W; mkdir -p $W
$BIN design --model $FIX --pin J,d --duration 1 --rate 1000 --limits q=±0.1,omega=±0.5,force=±300 \
    --noise-sd 2e-6 5 --out $W/pin > $W/design.txt
for INPUT in input fixed-constant fixed-reversal fixed-step; do
  $BIN simulate --truth $FIX --input $W/pin/$INPUT.csv --noise-sd 2e-6 5 --seed 9000 --out $W/$INPUT-rec > /dev/null
  $BIN fit --data $W/$INPUT-rec/recording.csv --model $FIX --bm 1 --sampler nuts-dense --chains 4 \
      --seed 1 --quiet --out $W/$INPUT-fit > $W/$INPUT-fit.txt
done
python3 - "$W" <<'PY'
import json, sys, csv, glob, statistics
w = sys.argv[1]
report = json.load(open(f"{w}/pin/design.json"))
expected = {"input": report["expected_sd"]}
for e in report["fixed_experiments"]:
    expected[e["file"][:-4]] = e["expected_sd"]
print("| input | J: fit sd / expected | ratio | d: fit sd / expected | ratio |")
print("|---|---|---|---|---|")
for name, sd in expected.items():
    draws = {"J": [], "d": []}
    for path in sorted(glob.glob(f"{w}/{name}-fit/fit-nuts-dense-chain*.csv")):
        for row in csv.DictReader(line for line in open(path) if not line.startswith("#")):
            for k in draws:
                draws[k].append(float(row[k]))
    cells = []
    for k in ("J", "d"):
        s = statistics.stdev(draws[k])
        cells += [f"{s:.4g} / {sd[k]:.4g}", f"{s / sd[k]:.3f}"]
    label = "designed" if name == "input" else name[len("fixed-"):]
    print(f"| {label} ({len(draws['J'])} draws) | " + " | ".join(cells) + " |")
PY

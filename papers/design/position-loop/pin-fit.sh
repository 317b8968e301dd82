#!/bin/sh
# Session 16: the pinned sds of run.sh's `design --pin J,d` confirmed by a Bayesian fit: one
# record of the fixture's model (seed 9000, σ_q = 2 µm, σ_force = 5 N) on the designed
# reference, fitted by `motorcal fit` (BM1, NUTS with the dense metric, 4 chains). Run run.sh
# first (same W); BIN a build of fb3be97.
set -e
BIN=${BIN:-motorcal}
HERE=$(cd "$(dirname "$0")" && pwd); ROOT=$HERE/../../..
FIX=$ROOT/tests/fixtures/design/position_loop.toml
W=${W:-/tmp/design-position}
$BIN simulate --truth $FIX --input $W/pin/input.csv --noise-sd 2e-6 5 --seed 9000 --out $W/pinrec
$BIN fit --data $W/pinrec/recording.csv --model $FIX --bm 1 --sampler nuts-dense --chains 4 \
    --seed 1 --out $W/pinfit
python3 - "$W" <<'PY'
import json, sys, csv, glob, statistics
w = sys.argv[1]
predicted = json.load(open(f"{w}/pin/design.json"))["expected_sd"]
draws = {"J": [], "d": []}
for path in sorted(glob.glob(f"{w}/pinfit/fit-nuts-dense-chain*.csv")):
    for row in csv.DictReader(line for line in open(path) if not line.startswith("#")):
        for k in draws:
            draws[k].append(float(row[k]))
for k, v in draws.items():
    sd = statistics.stdev(v)
    print(f"{k}: posterior sd {sd:.4g} over {len(v)} draws, predicted {predicted[k]:.4g}, ratio {sd / predicted[k]:.3f}")
PY

#!/bin/sh
# Session 18: `design --pin R,load_torque.T_0 --diagnosis`: the design sits at the diagnosis's
# selected model at its MAP, so the found term's own parameter can be pinned. A concealed load
# torque (seed 4, constant input) is diagnosed; the pin is designed on the report; then one
# record of the amended model (diagnose --out's model.toml, at the selected MAP) on each input
# (designed, and the fixed constant, reversal and step written beside it) is fitted by `motorcal
# fit` (BM1, NUTS dense, 4 chains) and its posterior sds set beside the expected ones. BIN a
# build of the commit named in papers/design.md.
set -e
BIN=${BIN:-motorcal}
W=${W:-/tmp/design-pin-diagnosis}
rm -rf $W; mkdir -p $W
$BIN simulate --effect load_torque --conceal --input constant --seed 4 --out $W/case > /dev/null
$BIN diagnose --quiet --data $W/case/recording.csv --model $W/case/motor.toml --json $W/case/diag.json \
    --out $W/case/diag > $W/diagnose.txt
python3 -c "import json; r = json.load(open('$W/case/diag.json')); print('selected', r['selected_set'], r['selected_params'])"
$BIN design --model $W/case/motor.toml --diagnosis $W/case/diag.json --pin R,load_torque.T_0 \
    --duration 0.5 --rate 1000 --limits U=±24,I=±300,omega=±3000 --out $W/pin > $W/design.txt
for INPUT in input fixed-constant fixed-reversal fixed-step; do
  $BIN simulate --truth $W/case/diag/model.toml --input $W/pin/$INPUT.csv --seed 9000 --out $W/$INPUT-rec > /dev/null
  $BIN fit --data $W/$INPUT-rec/recording.csv --model $W/case/diag/model.toml --bm 1 --sampler nuts-dense \
      --chains 4 --seed 1 --quiet --out $W/$INPUT-fit > $W/$INPUT-fit.txt
done
python3 - "$W" <<'PY'
import json, sys, csv, glob, statistics
w = sys.argv[1]
report = json.load(open(f"{w}/pin/design.json"))
print("pinned at", report["pinned_at"]["source"], report["pinned_at"]["values"])
expected = {"input": report["expected_sd"]}
for e in report["fixed_experiments"]:
    expected[e["file"][:-4]] = e["expected_sd"]
keys = ["R", "load_torque.T_0"]
print("| input | " + " | ".join(f"{k}: fit sd / expected | ratio" for k in keys) + " |")
print("|---" * (1 + 2 * len(keys)) + "|")
for name, sd in expected.items():
    draws = {k: [] for k in keys}
    for path in sorted(glob.glob(f"{w}/{name}-fit/fit-nuts-dense-chain*.csv")):
        for row in csv.DictReader(line for line in open(path) if not line.startswith("#")):
            for k in keys:
                draws[k].append(float(row[k.replace(".", "__")]))
    cells = []
    for k in keys:
        s = statistics.stdev(draws[k])
        cells += [f"{s:.4g} / {sd[k]:.4g}", f"{s / sd[k]:.3f}"]
    label = "designed" if name == "input" else name[len("fixed-"):]
    print(f"| {label} ({len(draws[keys[0]])} draws) | " + " | ".join(cells) + " |")
for k in keys:
    gains = ", ".join(f"{n[len('fixed-'):]} {sd[k] / expected['input'][k]:.3f}"
                      for n, sd in expected.items() if n != "input")
    print(f"{k}: each fixed input's expected sd over the designed one's: {gains}")
PY

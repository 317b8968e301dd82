#!/bin/sh
# Session 18: `design --pin R,c_g/J` at the model file's values against `--data`, where the
# model as given is fitted to a recording first (its MAP, the targets calibrated; σ from that
# fit). The record is `simulate`'s default: the paper's motor (c_g = 0.01) behind the nominal
# model (c_g = 0.009), seed 5. BIN a build of the commit named in papers/design.md.
set -e
BIN=${BIN:-motorcal}
W=${W:-/tmp/design-pin-data}
rm -rf $W; mkdir -p $W
$BIN simulate --seed 5 --out $W/rec > /dev/null
for MODE in file data; do
  EXTRA=""; [ $MODE = data ] && EXTRA="--data $W/rec/recording.csv"
  $BIN design --model $W/rec/motor.toml $EXTRA --pin R,c_g/J --duration 0.5 --rate 1000 \
      --limits U=±24,I=±300,omega=±3000 --out $W/$MODE > $W/$MODE.txt
done
python3 - "$W" <<'PY'
import json, sys
w = sys.argv[1]
sds, ratios = {}, {}
for mode in ("file", "data"):
    r = json.load(open(f"{w}/{mode}/design.json"))
    at = r["pinned_at"]["values"]
    ratio = at["c_g"] / at["J"]
    print(f"{mode}: at {r['pinned_at']['source']}: R {at['R']:.5g}, c_g/J {ratio:.5g}; "
          f"σ {r['noise_sd']}; runtime {r['runtime_s']:.2f} s")
    rows = [("designed", r["expected_sd"])] + [(e["input"], e["expected_sd"]) for e in r["fixed_experiments"]]
    for name, sd in rows:
        print(f"  {name:9s} expected sd R {sd['R']:.4g} Ω, c_g/J {sd['c_g/J']:.4g} "
              f"({sd['c_g/J'] / ratio:.3g} of the ratio)")
    sds[mode], ratios[mode] = r["expected_sd"], ratio
print(f"designed c_g/J sd at the recording's MAP over at the file's values: "
      f"{sds['data']['c_g/J'] / sds['file']['c_g/J']:.3f}; "
      f"the MAP's c_g/J over the truth's 0.01/5e-5: {ratios['data'] / 200:.4f}")
PY

#!/usr/bin/env bash
# Input delays above the concealed range: the generator's input_delay at a peak effect of MAG σ
# on the current (default 8; not --conceal, so the oracle's margin is reported, not enforced),
# seeds 1400000–1400009, reversal input; each diagnosed rank-only.
#   papers/beyond-library/delays-1400000/run.sh MOTORCAL_BINARY [OUT_DIR] > delays8.csv
set -uo pipefail
bin=$1; out=${2:-/tmp/delay}
mkdir -p "$out"
echo "seed,tau,peak_I,peak_omega,oracle_margin,oracle_runner_up,selected_set,ties"
for s in $(seq 1400000 1400009); do
  d=$out/c$s
  "$bin" simulate --effect input_delay --magnitude "${MAG:-8}" --seed "$s" --input reversal \
    --out "$d" >/dev/null 2>&1 || { echo "$s,not made"; continue; }
  "$bin" diagnose --quiet --rank-only --data "$d/recording.csv" --model "$d/motor.toml" \
    --json "$d/r.json" >/dev/null 2>&1
  python3 -c "
import json
a=json.load(open('$d/answer.json')); r=json.load(open('$d/r.json'))
p=a['max_abs_effect_over_sigma']
print('$s,%.3g,%.2f,%.2f,%s,%s,%s,%s' % (a['params']['tau'], p['I'], p['omega'], a.get('oracle_margin'), a.get('oracle_runner_up'), '+'.join(r['selected_set']), '+'.join(r['ties'])))"
done

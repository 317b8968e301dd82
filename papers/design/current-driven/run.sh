#!/bin/sh
# Session 12: `motorcal design` on a current_driven model, the loop design → simulate → diagnose
# closed on the fixture tests/fixtures/design/current_driven.toml (J calibrated, σ_ω = 1 rad/s).
# For each tie: a truth with the term, a record of it under a constant 1 A (which never
# reverses), design fitted to that record, the designed current played into the truth, and the
# ranking on the new record. BIN is a build of the commit named in README.md here.
set -e
BIN=${BIN:-motorcal}
HERE=$(cd "$(dirname "$0")" && pwd); ROOT=$HERE/../../..
FIX=$ROOT/tests/fixtures/design/current_driven.toml
W=${W:-/tmp/design-current}; rm -rf $W; mkdir -p $W
python3 -c "
print('t,I')
for i in range(1, 501): print(f'{i/1000:.3f},1.0')" > $W/constant-1A.csv
for CASE in "coulomb_friction:T_c = 0.02:load_torque" "viscous_friction:Dd = 1.0e-4:quadratic_drag"; do
  TERM=${CASE%%:*}; REST=${CASE#*:}; VALUE=${REST%%:*}; RIVAL=${REST#*:}
  D=$W/$TERM; mkdir -p $D
  sed "s/^\[drive\]/[terms.$TERM]\n$VALUE\n\n[drive]/" $FIX > $D/truth.toml
  $BIN simulate --truth $D/truth.toml --nominal $FIX --input $W/constant-1A.csv --noise-sd 0 1 --seed 7 --out $D/recorded > /dev/null
  /usr/bin/time -f "design wall %e s" $BIN design --model $FIX --data $D/recorded/recording.csv --separate $TERM,$RIVAL \
      --duration 0.5 --rate 1000 --limits "I=±3,omega=±300" --noise-sd 1 --no-rival-check --out $D/design > $D/design.log 2>&1
  $BIN simulate --truth $D/truth.toml --nominal $FIX --input $D/design/input.csv --noise-sd 0 1 --seed 8 --out $D/designed > /dev/null
  $BIN diagnose --quiet --rank-only --data $D/designed/recording.csv --model $FIX --candidates $TERM,$RIVAL --json $D/designed.json --out $D/diagnosed > /dev/null
  python3 - "$D" "$TERM" "$RIVAL" <<'PY'
import json, sys
d, term, rival = sys.argv[1:]
j = json.load(open(f"{d}/design/design.json"))
fixed = ", ".join(f"{f['input']} {f['expected_gap_nats']:.1f}" for f in j["fixed_experiments"])
r = json.load(open(f"{d}/designed.json"))
score = lambda n: next((e["score"] for e in r["ranking"] if e["effect"] == n), float("nan"))
print(f"{term} (truth) vs {rival}: designed {j['expected_gap_nats']:.1f} ± {j['expected_gap_sd_nats']:.1f} nats; fixed: {fixed}; "
      f"on the designed record diagnose selects {r['selected']} ({term} {score(term):+.1f}, {rival} {score(rival):+.1f} nats over none: "
      f"a lead of {score(term) - score(rival):.1f} nats)")
PY
  grep "design wall" $D/design.log
done

#!/usr/bin/env bash
# Session 30: whole commands, quiet, one at a time, per case session 29's build (HEAD) then this
# session's (NEW), on the slowest five of session 29's build in run.sh's runs and five the
# changes touch; prints each case's runtime_s from its report. From the root.
set -e
T=${T:-/tmp/s30/b}; O=$T/timing; mkdir -p $O
# CASES (SET/CASE …) and T may be set by the caller (session 31's timing.sh); these are session 30's.
CASES=${CASES:-"h81/sensor_dropout-810003 h76/gear_ripple-760017 h77/cogging-770012
  h76/bearing_defect-760002 h68/resonant_sensor-680020 h78/clutch_engagement-780007
  h78/clutch_engagement-780012 h90/loose_part-900004 h90/ac_coupled_tacho-900015
  h79/pump_threshold-790010"}
for N in $CASES; do
  C=$T/cases/$N; n=$(basename $N)
  for V in head:$HEAD new:$NEW; do
    ${V#*:} diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $O/$n-${V%%:*}.json --out $O/$n-${V%%:*}.d > /dev/null 2>&1 || true
  done
  python3 -c "import json; a=json.load(open('$O/$n-head.json'))['runtime_s']; b=json.load(open('$O/$n-new.json'))['runtime_s']; print(f'$n: {a:.1f} s -> {b:.1f} s')"
done

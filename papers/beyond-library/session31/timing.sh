#!/usr/bin/env bash
# Session 31: whole commands, quiet, one at a time, per case session 30's build (HEAD) then this
# session's (NEW), on the slowest five of session 30's build in run.sh's runs and five the
# changes touch; prints each case's runtime_s from its report. From the root.
set -e
T=${T:-/tmp/s31/b}; O=$T/timing; mkdir -p $O
for N in h76/bearing_defect-760002 h68/resonant_sensor-680020 h76/gear_ripple-760017 \
         h51/eccentric-510006 h68/eccentric-680008 h91/brake_release-910006 \
         h91/current_offset_step-910007 h68/flux_saturation-680011 h81/shorted_turn-810016 \
         h68/sensor_heat_drift-680024; do
  C=$T/cases/$N; n=$(basename $N)
  for V in head:$HEAD new:$NEW; do
    ${V#*:} diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $O/$n-${V%%:*}.json --out $O/$n-${V%%:*}.d > /dev/null 2>&1 || true
  done
  python3 -c "import json; a=json.load(open('$O/$n-head.json'))['runtime_s']; b=json.load(open('$O/$n-new.json'))['runtime_s']; print(f'$n: {a:.1f} s -> {b:.1f} s')"
done

#!/usr/bin/env bash
# Session 29: the blind sets of sessions 19–28 (each made after the build it was first run on),
# made again and diagnosed by one build, whole commands, one at a time. From the root.
# `blind_sets.sh cases` makes them into $T/cases; `blind_sets.sh diagnose BIN NAME` diagnoses
# every case into $T/NAME/CASE.json and a tree $T/tNAME/SET/CASE/report.json for kind_table.py.
set -e
T=${T:-/tmp/s29/b}; GEN=${GEN:-target/release/examples/beyond_library_cases}
case $1 in
cases)
  mkdir -p $T/cases
  $GEN --out $T/cases/h78 --effects slew_limit,clutch_engagement,pwm_alias,speed_crosstalk,dc_link_resonance --per-effect 4 --seed-base 780000
  $GEN --out $T/cases/h79 --effects pump_threshold,hydraulic_load,encoder_glitch --per-effect 4 --seed-base 790000
  $GEN --out $T/cases/h79v --effects commutator_ripple --per-effect 4 --seed-base 795000 --volts 2
  $GEN --out $T/cases/h81 --effects mount_resonance,speed_window,sensor_dropout,shorted_turn --per-effect 4 --seed-base 810000
  $GEN --out $T/cases/h82 --effects emi_bursts,supply_dips,seal_friction,sensor_hysteresis --per-effect 4 --seed-base 820000
  $GEN --out $T/cases/h82v --effects magnet_pickup --per-effect 4 --seed-base 825000 --volts 2
  $GEN --out $T/cases/h83 --effects sample_jitter,asymmetric_tacho --per-effect 4 --seed-base 830000
  $GEN --out $T/cases/h83v --effects encoder_missing_line --per-effect 4 --seed-base 835000 --volts 2
  $GEN --out $T/cases/h85v --effects encoder_missing_pulse --per-effect 8 --seed-base 850000 --volts 2
  ;;
diagnose)
  BIN=$2; O=$T/$3; shift 3; mkdir -p $O
  SETS=${*:-h78 h79 h79v h81 h82 h82v h83 h83v h85v}
  for S in $SETS; do for C in $T/cases/$S/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $O/$N.json --out $O/$N.d > $O/$N.log 2>&1 || true
    mkdir -p $T/t$(basename $O)/$S/$N; ln -sfn $O/$N.json $T/t$(basename $O)/$S/$N/report.json
  done; done
  touch $O/DONE
  ;;
esac

#!/usr/bin/env bash
# Session 27's re-validation of the as-given noise models weighed against the selected terms
# (src/discover/unexplained/mod.rs). From the root. BASE a build of cec35e0 (the discovery as
# b6149e2's), NEW of this session's source; GEN, STUDY the examples beyond_library_cases and
# diagnose_study of NEW's build. `validate.sh cases` makes the cases; `validate.sh diagnose
# BUILD NAME` diagnoses every set with BUILD into $T/NAME (whole commands, quiet); `validate.sh
# studies` runs NEW's studies (seeds 1100000, 1300000, 2200000 and fresh nulls 2300000).
set -e
T=${T:-/tmp/s27/v}; B=papers/beyond-library
case $1 in
cases)
  mkdir -p $T/cases
  $GEN --out $T/cases/h78 --effects slew_limit,clutch_engagement,pwm_alias,speed_crosstalk,dc_link_resonance --per-effect 4 --seed-base 780000
  $GEN --out $T/cases/h51
  $GEN --out $T/cases/h68 --per-effect 1 --seed-base 680000 --effects amplifier_saturation,backlash,compliant_coupling,crank_inertia,current_clip,current_limit,current_sensor_resonance,eccentric,eddy_brake,encoder_latency,flux_saturation,inductance_saturation,input_delay,leakage_current,load_friction,load_ramp,load_ripple,mains_pickup,periodic_load,resonant_sensor,return_spring,rotor_rub,sagging_supply,sensor_heat_drift,sensor_lag,speed_offset,speed_quantization,stribeck,supply_ripple,tacho_nonlinearity,thermal_magnet
  $GEN --out $T/cases/h76 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 --seed-base 760000
  $GEN --out $T/cases/h77 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 --seed-base 770000 --volts 2
  $GEN --out $T/cases/h82 --effects emi_bursts,supply_dips,seal_friction,sensor_hysteresis --per-effect 4 --seed-base 820000
  $GEN --out $T/cases/h82v --effects magnet_pickup --per-effect 4 --seed-base 825000 --volts 2
  $GEN --out $T/cases/h83 --effects sample_jitter,asymmetric_tacho --per-effect 4 --seed-base 830000
  $GEN --out $T/cases/h83v --effects encoder_missing_line --per-effect 4 --seed-base 835000 --volts 2
  $GEN --out $T/cases/h84 --effects sample_jitter --per-effect 8 --seed-base 840000
  ;;
diagnose)
  BIN=$2; O=$T/$3; mkdir -p $O
  for C in $T/cases/*/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $O/$N.json --out $O/$N.d > $O/$N.log 2>&1 || true
  done
  for f in ../shared/data/real/hsm150/idf_*.csv; do n=$(basename $f .csv)
    $BIN diagnose --quiet --data $f --model examples/hsm150/model.toml --json $O/real-$n.json --out $O/real-$n.d > $O/real-$n.log 2>&1 || true
  done
  $BIN diagnose --quiet --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $O/real-emps.json --out $O/real-emps.d > $O/real-emps.log 2>&1 || true
  touch $O/DONE
  ;;
studies)
  for D in null-2300000:"--per-effect 0 --null 100 --two 0 --no-dev --seed-base 2300000" \
           null-2200000:"--per-effect 0 --null 100 --two 0 --no-dev --seed-base 2200000" \
           study-1100000:"--per-effect 5 --null 40 --two 20 --seed-base 1100000" \
           terms-1300000:"--effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev --seed-base 1300000"; do
    NAME=${D%%:*}; mkdir -p $B/$NAME-session27
    $STUDY ${D#*:} --out $T/$NAME > $B/$NAME-session27/log.txt
    cp $T/$NAME/study.csv $T/$NAME/study.json $B/$NAME-session27/
  done
  touch $T/STUDIES_DONE
  ;;
esac

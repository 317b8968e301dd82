#!/usr/bin/env bash
# Session 20's runs, as they were made, from the root. BIN_base is a build of ab2ef83 (session
# 19's source and a test), BIN_new of 76385db (the dictionary's shared factors computed once
# per point, e^y's underflow taken without libm's slow path); GEN the example
# beyond_library_cases, STUDY diagnose_study, both of 76385db (unchanged by it).
set -e
HERE=papers/beyond-library/session20; B=papers/beyond-library; S=/tmp/s20/hold
# 1. The cases: session 19's seventh set, and the sets of session 18's section 3 and 4 that
#    held its slowest cases (the first set, session 9's 40 angle cases, the 31 of 680000).
$GEN --out $S/h78 --effects slew_limit,clutch_engagement,pwm_alias,speed_crosstalk,dc_link_resonance \
    --per-effect 4 --seed-base 780000
$GEN --out $S/h51
$GEN --out $S/h68 --per-effect 1 --seed-base 680000 --effects amplifier_saturation,backlash,compliant_coupling,crank_inertia,current_clip,current_limit,current_sensor_resonance,eccentric,eddy_brake,encoder_latency,flux_saturation,inductance_saturation,input_delay,leakage_current,load_friction,load_ramp,load_ripple,mains_pickup,periodic_load,resonant_sensor,return_spring,rotor_rub,sagging_supply,sensor_heat_drift,sensor_lag,speed_offset,speed_quantization,stribeck,supply_ripple,tacho_nonlinearity,thermal_magnet
$GEN --out $S/h76 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 --seed-base 760000
$GEN --out $S/h77 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 --seed-base 770000 --volts 2
# 2. Per case the base then the new build, whole command, quiet (118 cases; two test builds of
#    mine overlapped some of them).
mkdir -p /tmp/s20/qb /tmp/s20/qn
for C in $S/h78/*/ $S/h68/*/ $S/h51/*/ $S/h76/*/ $S/h77/*/; do N=$(basename $C)
  $BIN_base diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json /tmp/s20/qb/$N.json --out /tmp/s20/qb/$N.d > /tmp/s20/qb/$N.log 2>&1
  $BIN_new diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json /tmp/s20/qn/$N.json --out /tmp/s20/qn/$N.d > /tmp/s20/qn/$N.log 2>&1
done
python3 $HERE/paired_times.py /tmp/s20/qb /tmp/s20/qn > $HERE/paired-times-118-ab2ef83-76385db.txt
python3 $B/session12/compare_full.py /tmp/s20/qb /tmp/s20/qn > $HERE/compare-full-118-ab2ef83-76385db.txt
# 3. The five slowest, twice each, base then new, nothing else running.
for rep in 1 2; do for c in h68/resonant_sensor-680020 h51/eccentric-510006 h76/gear_ripple-760017 h77/cogging-770012 h77/bearing_defect-770014; do
  N=$(basename $c); for V in base new; do eval BIN=\$BIN_$V
    $BIN diagnose --quiet --data $S/$c/recording.csv --model $S/$c/motor.toml --json /tmp/s20/quiet-$V-$N-$rep.json > /dev/null 2>&1
    python3 -c "import json; print('$N','$V','run $rep', round(json.load(open('/tmp/s20/quiet-$V-$N-$rep.json'))['runtime_s'],1))"
done; done; done > $HERE/quiet-pairs-5.txt
# 4. No change in the library's study or the coupling's and the lag's concealed cases.
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out /tmp/s20/study > $B/study-1100000-session20/log.txt
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out /tmp/s20/t13 > $B/terms-1300000-session20/log.txt
cp /tmp/s20/study/study.csv /tmp/s20/study/study.json $B/study-1100000-session20/
cp /tmp/s20/t13/study.csv /tmp/s20/t13/study.json $B/terms-1300000-session20/
python3 $B/compare_studies.py $B/study-1100000-session19/study.csv $B/study-1100000-session20/study.csv > $HERE/compare-study-1100000.txt
python3 $B/compare_studies.py $B/terms-1300000-session19/study.csv $B/terms-1300000-session20/study.csv > $HERE/compare-terms-1300000.txt

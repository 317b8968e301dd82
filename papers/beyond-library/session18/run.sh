#!/bin/sh
# Session 18's runs, as they were made, from the root. BIN_base is a build of c48e4c8 (session
# 16's last commit), BIN_new of this session's source (the coupling's frequency also searched
# over the band, told apart at the first fit's mode); STUDY the example diagnose_study of the
# new build; GEN the example beyond_library_cases of c48e4c8 (the generator is unchanged).
set -e
HERE=papers/beyond-library/session18; B=papers/beyond-library
# 1. The case that started it: a law in θ named for a damped coupling.
$BIN_base simulate --effect compliant_coupling --conceal --seed 1300038 --input reversal --out /tmp/s17/c38
$BIN_base diagnose --model /tmp/s17/c38/motor.toml --data /tmp/s17/c38/recording.csv --rank-only
$BIN_new diagnose --model /tmp/s17/c38/motor.toml --data /tmp/s17/c38/recording.csv --rank-only
# 2. The dynamic terms' studies and the library's study, the seeds of session 15.
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out /tmp/s17/t13 > $B/terms-1300000-session18/log.txt
$STUDY --effects input_delay,sensor_lag,compliant_coupling --per-effect 10 --null 0 --two 0 --no-dev \
    --seed-base 1200000 --out /tmp/s17/t12 > $B/terms-1200000-session18/log.txt
$STUDY --effects compliant_coupling,sensor_lag,input_delay --per-effect 15 --null 0 --two 0 --no-dev \
    --seed-base 1500000 --out /tmp/s17/t15 > $B/terms-1500000-session18/log.txt
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out /tmp/s17/study > $B/study-1100000-session18/log.txt
for S in 1200000:t12 1300000:t13 1500000:t15; do SEED=${S%%:*}; D=${S##*:}
  cp /tmp/s17/$D/study.csv /tmp/s17/$D/study.json $B/terms-$SEED-session18/
  python3 $B/compare_studies.py $B/terms-$SEED-session15/study.csv $B/terms-$SEED-session18/study.csv > $HERE/compare-terms-$SEED.txt
done
cp /tmp/s17/study/study.csv /tmp/s17/study/study.json $B/study-1100000-session18/
python3 $B/compare_studies.py $B/study-1100000-session15/study.csv $B/study-1100000-session18/study.csv > $HERE/compare-study-1100000.txt
# 3. Out-of-library cases, whole commands, quiet, per case the new build then the base: the
#    first set's 27 (GEN's defaults, seeds 510000) and session 9's 40 angle cases.
$GEN --out /tmp/s17/hold/h51
$GEN --out /tmp/s17/hold/h76 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 \
    --seed-base 760000 > $HERE/cases-760000.log
$GEN --out /tmp/s17/hold/h77 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 \
    --seed-base 770000 --volts 2 > $HERE/cases-770000.log
for C in /tmp/s17/hold/h51/*/ /tmp/s17/hold/h76/*/ /tmp/s17/hold/h77/*/; do N=$(basename $C)
  for BUILD in new base; do eval BIN=\$BIN_$BUILD; R=/tmp/s17/q-$BUILD; mkdir -p $R
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
H51=/tmp/s17/hold/h51; H76=/tmp/s17/hold/h76; H77=/tmp/s17/hold/h77
python3 $B/whole_commands.py /tmp/s17/q-new $H51 $H76 $H77 > $HERE/whole-command-times-67-session18-quiet.txt
python3 $B/whole_commands.py /tmp/s17/q-base $H51 $H76 $H77 > $HERE/whole-command-times-67-c48e4c8-quiet.txt
python3 $B/session13/verdicts.py /tmp/s17/q-base /tmp/s17/q-new > $HERE/verdicts-67-c48e4c8-session18.txt
python3 $B/session12/compare_full.py /tmp/s17/q-base /tmp/s17/q-new > $HERE/compare-full-67-c48e4c8-session18.txt
python3 $HERE/coupling_moves.py /tmp/s17/q-base /tmp/s17/q-new > $HERE/coupling-moves-67.txt
# 4. 75 more out-of-library cases, the same way (r-head: a build of 50ead9e): session 6's 35
#    (all 31 effects at 24 V once, seeds 680000; four at 2 V, 690000) and the sets of 580000,
#    630000 and 640000 (backlash, the tachometer's nonlinearity, a leak; an eddy brake, a late
#    encoder, a crank; a resonant current sensor, a heat-drifting sensor, a load ramp, a rub).
$GEN --out /tmp/s17/hold/h68 --per-effect 1 --seed-base 680000 --effects amplifier_saturation,backlash,compliant_coupling,crank_inertia,current_clip,current_limit,current_sensor_resonance,eccentric,eddy_brake,encoder_latency,flux_saturation,inductance_saturation,input_delay,leakage_current,load_friction,load_ramp,load_ripple,mains_pickup,periodic_load,resonant_sensor,return_spring,rotor_rub,sagging_supply,sensor_heat_drift,sensor_lag,speed_offset,speed_quantization,stribeck,supply_ripple,tacho_nonlinearity,thermal_magnet > $HERE/cases-680000.log
$GEN --out /tmp/s17/hold/h69 --effects cogging,eccentric,bearing_defect,tacho_ripple --per-effect 1 --seed-base 690000 --volts 2 > $HERE/cases-690000.log
$GEN --out /tmp/s17/hold/h58 --effects leakage_current,tacho_nonlinearity,backlash --per-effect 4 --seed-base 580000 > $HERE/cases-580000.log
$GEN --out /tmp/s17/hold/h63 --effects eddy_brake,encoder_latency,crank_inertia --per-effect 4 --seed-base 630000 > $HERE/cases-630000.log
$GEN --out /tmp/s17/hold/h64 --effects current_sensor_resonance,sensor_heat_drift,load_ramp,rotor_rub --per-effect 4 --seed-base 640000 > $HERE/cases-640000.log
S=/tmp/s17/hold
for C in $S/h68/*/ $S/h69/*/ $S/h58/*/ $S/h63/*/ $S/h64/*/; do N=$(basename $C)
  for BUILD in head base; do eval BIN=\$BIN_$BUILD; R=/tmp/s17/r-$BUILD; mkdir -p $R
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
python3 $B/whole_commands.py /tmp/s17/r-head $S/h68 $S/h69 $S/h58 $S/h63 $S/h64 > $HERE/whole-command-times-75-session18-quiet.txt
python3 $B/whole_commands.py /tmp/s17/r-base $S/h68 $S/h69 $S/h58 $S/h63 $S/h64 > $HERE/whole-command-times-75-c48e4c8-quiet.txt
python3 $B/session13/verdicts.py /tmp/s17/r-base /tmp/s17/r-head > $HERE/verdicts-75-c48e4c8-session18.txt
python3 $B/session12/compare_full.py /tmp/s17/r-base /tmp/s17/r-head > $HERE/compare-full-75-c48e4c8-session18.txt
python3 $HERE/coupling_moves.py /tmp/s17/r-base /tmp/s17/r-head > $HERE/coupling-moves-75.txt

#!/usr/bin/env bash
# Session 21's runs, as they were made (scratch in /tmp/s21). GEN the example
# beyond_library_cases of 21070df (the eighth set added); LIBRES the example library_residual;
# BIN_base a build of 23b443b (session 20's last commit), BIN_new of this session's source (the
# outliers' alternative, src/discover/unexplained/outliers.rs); STUDY diagnose_study of BIN_new's
# source; BIN_final a build of cda1b10 or later. oracle_outliers.py needs only the standard library.
set -e
HERE=papers/beyond-library/session21; B=papers/beyond-library; S=/tmp/s21
# 1. The eighth set of effects not built for, made and diagnosed blind by the base (whole
#    commands, one at a time, while a clean-clone CI ran: its times are not quiet), then by
#    the new build.
$GEN --out $S/h79 --effects pump_threshold,hydraulic_load,encoder_glitch --per-effect 4 \
    --seed-base 790000 > $HERE/cases-790000.log
$GEN --out $S/h79 --effects commutator_ripple --per-effect 4 --seed-base 795000 --volts 2 \
    > $HERE/cases-795000.log
for BUILD in base:r79:t79 new:n79:tn79; do B_=${BUILD%%:*}; R=$S/$(echo $BUILD | cut -d: -f2)
  TREE=$S/${BUILD##*:}; eval BIN=\$BIN_$B_; mkdir -p $R
  for C in $S/h79/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
    mkdir -p $TREE/$N; ln -sf $R/$N.json $TREE/$N/report.json
  done
done
$LIBRES $S/h79/*/ > $HERE/library-residual-790000.md
for T in t79:23b443b tn79:session21; do
  (cd $B && python3 kind_table.py $S/h79:$S/${T%%:*}:session21/library-residual-790000.md) > $HERE/kind-table-790000-${T##*:}.md
  (cd $B && python3 rule_breaks.py $S/h79:$S/${T%%:*}:session21/library-residual-790000.md) > $HERE/rule-breaks-790000-${T##*:}.txt
done
python3 $B/session19/case_table.py $S/h79 $S/r79 > $HERE/case-table-790000-23b443b.md
python3 $B/session19/case_table.py $S/h79 $S/n79 > $HERE/case-table-790000-session21.md
python3 $B/session12/compare_full.py $S/r79 $S/n79 > $HERE/compare-full-790000-23b443b-session21.txt
grep -h '"truth"' $S/h79/*/answer.json > $HERE/truths-790000.txt
# 2. What an oracle finds of the miscounts: the contaminated normal on the truth's own residual.
python3 $HERE/oracle_outliers.py $S/h79/encoder_glitch-*/ > $HERE/oracle-outliers-790000.txt
# 3. The 118 out-of-library cases of session 20 (its run.sh, section 1), the new build, quiet
#    but for this session's own builds; against session 20's reports of 76385db (the same
#    source as 23b443b's).
R=$S/n118; mkdir -p $R
for C in /tmp/s20/hold/h78/*/ /tmp/s20/hold/h51/*/ /tmp/s20/hold/h68/*/ /tmp/s20/hold/h76/*/ /tmp/s20/hold/h77/*/; do
  N=$(basename $C)
  $BIN_new diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
done
python3 $B/session12/compare_full.py /tmp/s20/n118 $R > $HERE/compare-full-118-76385db-session21.txt
python3 $B/whole_commands.py $R /tmp/s20/hold/h78 /tmp/s20/hold/h51 /tmp/s20/hold/h68 /tmp/s20/hold/h76 /tmp/s20/hold/h77 > $HERE/whole-command-times-118-session21.txt
# 4. No change where nothing is an outlier: the library's study and the coupling's and lag's.
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out $S/study > $B/study-1100000-session21/log.txt
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out $S/t13 > $B/terms-1300000-session21/log.txt
cp $S/study/study.csv $S/study/study.json $B/study-1100000-session21/
cp $S/t13/study.csv $S/t13/study.json $B/terms-1300000-session21/
python3 $B/compare_studies.py $B/study-1100000-session20/study.csv $B/study-1100000-session21/study.csv > $HERE/compare-study-1100000.txt
python3 $B/compare_studies.py $B/terms-1300000-session20/study.csv $B/terms-1300000-session21/study.csv > $HERE/compare-terms-1300000.txt
# 5. The real records (HSM150's six, EMPS), rank-only, the base then the new build: the same.
for V in base new; do eval BIN=\$BIN_$V; mkdir -p $S/real/$V
  for f in ../shared/data/real/hsm150/idf_*.csv; do n=$(basename $f .csv)
    $BIN diagnose --quiet --rank-only --data $f --model examples/hsm150/model.toml --json $S/real/$V/$n.json > /dev/null 2>&1
  done
  $BIN diagnose --quiet --rank-only --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $S/real/$V/emps.json > /dev/null 2>&1
done
python3 $B/session12/compare_full.py $S/real/base $S/real/new > $HERE/compare-full-real-23b443b-session21.txt
# 6. (issue 20) The position loop's pinned sds over 50 records per input.
#    BIN_q0 a build of a316337 (q0_offset); the first run is the fixture as it is, the second
#    calibrates the offset.
BIN=$BIN_q0 W=$S/pm-a papers/design/position-loop/pin-many.sh > papers/design/position-loop/pin-many.txt
FIX=papers/design/position-loop/position_loop_q0.toml BIN=$BIN_q0 W=$S/pm-b \
    papers/design/position-loop/pin-many.sh > papers/design/position-loop/pin-many-q0.txt
# 7. Fresh miscount cases, made after the alternative was written: twelve at seeds 800000,
#    both builds, whole commands; what each names against the true miscounts.
$GEN --out $S/h80 --effects encoder_glitch --per-effect 12 --seed-base 800000 > $HERE/cases-800000.log
for V in base:r80 new:n80; do eval BIN=\$BIN_${V%%:*}; R=$S/${V##*:}; mkdir -p $R
  for C in $S/h80/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
python3 $HERE/outlier_table.py $S/h80 $S/r80 > $HERE/outlier-table-800000-23b443b.txt
python3 $HERE/outlier_table.py $S/h80 $S/n80 > $HERE/outlier-table-800000-session21.txt
python3 $HERE/oracle_outliers.py $S/h80/*/ > $HERE/oracle-outliers-800000.txt
# 8. A hundred fresh null cases (seeds 1700000) for the verdict's false alarms.
$STUDY --per-effect 0 --null 100 --two 0 --no-dev --seed-base 1700000 --out $S/null17 > $B/null-1700000-session21/log.txt
cp $S/null17/study.csv $S/null17/study.json $B/null-1700000-session21/
# 9. (issue 20) EMPS's record with and without the initial position's offset calibrated.
(echo '$ motorcal fit --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --bm 1 --map-only --quiet --out /tmp/emps-a'
 $BIN_final fit --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --bm 1 --map-only --quiet --out /tmp/emps-a 2>&1; echo
 echo '$ motorcal fit --data ../shared/data/real/emps/emps_estimation.csv --model papers/design/position-loop/emps_q0.toml --bm 1 --map-only --quiet --out /tmp/emps-b'
 $BIN_final fit --data ../shared/data/real/emps/emps_estimation.csv --model papers/design/position-loop/emps_q0.toml --bm 1 --map-only --quiet --out /tmp/emps-b 2>&1) > papers/design/position-loop/emps-q0.txt

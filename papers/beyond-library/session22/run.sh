#!/usr/bin/env bash
# Session 22's runs, as they were made (scratch in /tmp/s22). GEN the example
# beyond_library_cases of 010de56 (the ninth set added); LIBRES the example library_residual;
# BIN_base a build of f91ab8c (session 21's last commit), BIN_new of 33d63e9 (a ringing must
# beat a transient that does not ring, src/discover/unexplained/transient.rs); STUDY
# diagnose_study of BIN_new's source. (BIN_new was built before generic.rs's transient
# sentence lost its last clause, "and a record that holds each level longer than … ms";
# nothing else differs.)
set -e
HERE=papers/beyond-library/session22; B=papers/beyond-library; S=/tmp/s22
# 1. The ninth set, made and diagnosed blind by the base (whole commands, one at a time,
#    quiet), then by the new build.
$GEN --out $S/h81 --effects mount_resonance,speed_window,sensor_dropout,shorted_turn \
    --per-effect 4 --seed-base 810000 > $HERE/cases-810000.log
$LIBRES $S/h81/*/ > $HERE/library-residual-810000.md
for BUILD in base:r81:t81 new:n81:tn81; do B_=${BUILD%%:*}; R=$S/$(echo $BUILD | cut -d: -f2)
  TREE=$S/${BUILD##*:}; eval BIN=\$BIN_$B_; mkdir -p $R
  for C in $S/h81/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
    mkdir -p $TREE/$N; ln -sf $R/$N.json $TREE/$N/report.json
  done
done
for T in t81:f91ab8c tn81:session22; do
  (cd $B && python3 kind_table.py $S/h81:$S/${T%%:*}:session22/library-residual-810000.md) > $HERE/kind-table-810000-${T##*:}.md
  (cd $B && python3 rule_breaks.py $S/h81:$S/${T%%:*}:session22/library-residual-810000.md) > $HERE/rule-breaks-810000-${T##*:}.txt
done
python3 $B/session19/case_table.py $S/h81 $S/r81 > $HERE/case-table-810000-f91ab8c.md
python3 $B/session19/case_table.py $S/h81 $S/n81 > $HERE/case-table-810000-session22.md
python3 $B/whole_commands.py $S/r81 $S/h81 > $HERE/whole-command-times-810000-f91ab8c.txt
python3 $B/whole_commands.py $S/n81 $S/h81 > $HERE/whole-command-times-810000-session22.txt
# 2. The 118 out-of-library cases of session 20 (its run.sh, section 1) with the new build,
#    quiet; against session 20's reports of 76385db (the source session 21 found the same on
#    these 118). verdict_keys.py compares what is selected, both verdicts and the law.
R=$S/n118; mkdir -p $R
for C in /tmp/s20/hold/h78/*/ /tmp/s20/hold/h51/*/ /tmp/s20/hold/h68/*/ /tmp/s20/hold/h76/*/ /tmp/s20/hold/h77/*/; do
  N=$(basename $C)
  $BIN_new diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
done
python3 $HERE/verdict_keys.py /tmp/s20/n118 $R > $HERE/verdict-keys-118-76385db-session22.txt
python3 $B/whole_commands.py $R /tmp/s20/hold/h78 /tmp/s20/hold/h51 /tmp/s20/hold/h68 /tmp/s20/hold/h76 /tmp/s20/hold/h77 > $HERE/whole-command-times-118-session22.txt
# 3. The coupling's and the lag's concealed cases, the library's study, 100 fresh nulls.
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out $S/t13 > $B/terms-1300000-session22/log.txt
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out $S/study > $B/study-1100000-session22/log.txt
$STUDY --per-effect 0 --null 100 --two 0 --no-dev --seed-base 1800000 --out $S/null18 > $B/null-1800000-session22/log.txt
for D in t13:terms-1300000 study:study-1100000 null18:null-1800000; do
  cp $S/${D%%:*}/study.csv $S/${D%%:*}/study.json $B/${D##*:}-session22/
done
python3 $B/compare_studies.py $B/study-1100000-session21/study.csv $B/study-1100000-session22/study.csv > $HERE/compare-study-1100000.txt
python3 $B/compare_studies.py $B/terms-1300000-session21/study.csv $B/terms-1300000-session22/study.csv > $HERE/compare-terms-1300000.txt
# 4. The real records (HSM150's six, EMPS), rank-only, the new build then the base.
for V in new base; do eval BIN=\$BIN_$V; mkdir -p $S/real/$V
  for f in ../shared/data/real/hsm150/idf_*.csv; do n=$(basename $f .csv)
    $BIN diagnose --quiet --rank-only --data $f --model examples/hsm150/model.toml --json $S/real/$V/$n.json > /dev/null 2>&1
  done
  $BIN diagnose --quiet --rank-only --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $S/real/$V/emps.json > /dev/null 2>&1
done
python3 $HERE/verdict_keys.py $S/real/base $S/real/new > $HERE/verdict-keys-real-f91ab8c-session22.txt
# 5. The one null of seeds 1800000 with a term selected, remade by the command line and ranked
#    by both builds.
$BIN_new simulate --effect none --seed 1800045 --input reversal --out $S/null45
for V in base new; do eval BIN=\$BIN_$V
  $BIN diagnose --quiet --rank-only --data $S/null45/recording.csv --model $S/null45/motor.toml --json $S/null45/$V.json
done
# 6. The review's refactor (1af2868: the transient's quick gain on the ringing's windowed
#    normal equations): the ninth set again, BIN_win a build of 1af2868, against BIN_new's.
R=$S/w81; mkdir -p $R
for C in $S/h81/*/; do N=$(basename $C)
  $BIN_win diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
done
python3 $B/session12/compare_full.py $S/n81 $R > $HERE/compare-full-810000-33d63e9-1af2868.txt
python3 $HERE/verdict_keys.py $S/n81 $R > $HERE/verdict-keys-810000-33d63e9-1af2868.txt

#!/usr/bin/env bash
# Session 26's runs, as they were made, from the root. $T/bin holds a build of this session's
# source (a noise that follows the slope: src/discover/unexplained/slope_noise.rs): motorcal and
# the examples diagnose_study, beyond_library_cases, library_residual. The base reports are
# session 25's (28169f1's discovery; b922c4d changed no report): the tenth and eleventh sets in
# /tmp/s25/n82 and /tmp/s25/n83, the 118 in /tmp/s25/n118, the studies in papers/.
set -e
HERE=papers/beyond-library/session26; B=papers/beyond-library; S=/tmp/s23; P=/tmp/s25; T=/tmp/s26
BIN=$T/bin/motorcal; STUDY=$T/bin/diagnose_study
# 1. The tenth and eleventh sets, whole commands, one at a time.
for SET in 82 83; do
  mkdir -p $T/n$SET $T/tn$SET
  for C in $P/all$SET/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $T/n$SET/$N.json --out $T/n$SET/$N.d > $T/n$SET/$N.log 2>&1
    mkdir -p $T/tn$SET/$N; ln -sf $T/n$SET/$N.json $T/tn$SET/$N/report.json
  done
  python3 $B/session12/compare_full.py $P/n$SET $T/n$SET > $HERE/compare-full-8${SET#8}0000-session25-session26.txt || true
done
python3 $B/session19/case_table.py $P/all82 $T/n82 > $HERE/case-table-820000-session26.md
python3 $B/session19/case_table.py $P/all83 $T/n83 > $HERE/case-table-830000-session26.md
(cd $B && python3 kind_table.py $P/all82:$T/tn82:session23/library-residual-820000.md) > $HERE/kind-table-820000-session26.md
(cd $B && python3 kind_table.py $P/all83:$T/tn83:session25/library-residual-830000.md) > $HERE/kind-table-830000-session26.md
(cd $B && python3 rule_breaks.py $P/all82:$T/tn82:session23/library-residual-820000.md) > $HERE/rule-breaks-820000-session26.txt
(cd $B && python3 rule_breaks.py $P/all83:$T/tn83:session25/library-residual-830000.md) > $HERE/rule-breaks-830000-session26.txt
python3 $B/whole_commands.py $T/n82 $P/all82 > $HERE/whole-command-times-820000-session26.txt
python3 $B/whole_commands.py $T/n83 $P/all83 > $HERE/whole-command-times-830000-session26.txt
touch $T/SETS_DONE
# 2. The 118 of session 20 (remade in session 23), whole commands, one at a time.
mkdir -p $T/n118
for C in $S/hold/h78/*/ $S/hold/h51/*/ $S/hold/h68/*/ $S/hold/h76/*/ $S/hold/h77/*/; do N=$(basename $C)
  $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $T/n118/$N.json --out $T/n118/$N.d > $T/n118/$N.log 2>&1
done
python3 $B/session12/compare_full.py $P/n118 $T/n118 > $HERE/compare-full-118-session25-session26.txt || true
python3 $B/session22/verdict_keys.py $P/n118 $T/n118 > $HERE/verdict-keys-118-session25-session26.txt || true
python3 $B/whole_commands.py $T/n118 $S/hold/h78 $S/hold/h51 $S/hold/h68 $S/hold/h76 $S/hold/h77 > $HERE/whole-command-times-118-session26.txt
touch $T/H118_DONE
# 3. A hundred fresh nulls; the library's study; the coupling's and the lag's concealed cases.
mkdir -p $B/null-2200000-session26 $B/null-2100000-session26 $B/study-1100000-session26 $B/terms-1300000-session26
$STUDY --per-effect 0 --null 100 --two 0 --no-dev --seed-base 2200000 --out $T/null22 > $B/null-2200000-session26/log.txt
$STUDY --per-effect 0 --null 100 --two 0 --no-dev --seed-base 2100000 --out $T/null21 > $B/null-2100000-session26/log.txt
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out $T/study > $B/study-1100000-session26/log.txt
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out $T/t13 > $B/terms-1300000-session26/log.txt
for D in null22:null-2200000 null21:null-2100000 study:study-1100000 t13:terms-1300000; do
  cp $T/${D%%:*}/study.csv $T/${D%%:*}/study.json $B/${D##*:}-session26/
done
python3 $B/compare_studies.py $B/study-1100000-session25/study.csv $B/study-1100000-session26/study.csv > $HERE/compare-study-1100000.txt || true
python3 $B/compare_studies.py $B/terms-1300000-session25/study.csv $B/terms-1300000-session26/study.csv > $HERE/compare-terms-1300000.txt || true
touch $T/STUDIES_DONE
# 4. The real records, whole commands (the verdict included; with BASE, a build of 39de1a3 =
#    HEAD's source, too) and rank-only.
BASE=/tmp/ci25/target/release/motorcal
mkdir -p $T/real $T/realw $T/realw-base
for f in ../shared/data/real/hsm150/idf_*.csv; do n=$(basename $f .csv)
  $BIN diagnose --quiet --rank-only --data $f --model examples/hsm150/model.toml --json $T/real/$n.json > /dev/null 2>&1
  $BIN diagnose --quiet --data $f --model examples/hsm150/model.toml --json $T/realw/$n.json --out $T/realw/$n.d > $T/realw/$n.log 2>&1 || true
  $BASE diagnose --quiet --data $f --model examples/hsm150/model.toml --json $T/realw-base/$n.json --out $T/realw-base/$n.d > $T/realw-base/$n.log 2>&1 || true
done
$BIN diagnose --quiet --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $T/realw/emps.json --out $T/realw/emps.d > $T/realw/emps.log 2>&1 || true
$BASE diagnose --quiet --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $T/realw-base/emps.json --out $T/realw-base/emps.d > $T/realw-base/emps.log 2>&1 || true
python3 $B/session12/compare_full.py $T/realw-base $T/realw > $HERE/compare-full-real-whole-39de1a3-session26.txt || true
$BIN diagnose --quiet --rank-only --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $T/real/emps.json > /dev/null 2>&1
python3 $B/session12/compare_full.py $S/real/new $T/real > $HERE/compare-full-real-session23-session26.txt || true
# 5. Eight fresh jitter cases (seeds 840000, made after the change, diagnosed once with each
#    build), whole commands.
$T/bin/beyond_library_cases --out $T/h84 --effects sample_jitter --per-effect 8 --seed-base 840000 > $HERE/cases-840000.log
mkdir -p $T/n84 $T/n84-base $T/tn84
for C in $T/h84/*/; do N=$(basename $C)
  $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $T/n84/$N.json --out $T/n84/$N.d > $T/n84/$N.log 2>&1
  $BASE diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $T/n84-base/$N.json > $T/n84-base/$N.log 2>&1
  mkdir -p $T/tn84/$N; ln -sf $T/n84/$N.json $T/tn84/$N/report.json
done
$T/bin/library_residual $T/h84/*/ > $HERE/library-residual-840000.md
python3 $B/session19/case_table.py $T/h84 $T/n84-base > $HERE/case-table-840000-39de1a3.md
python3 $B/session19/case_table.py $T/h84 $T/n84 > $HERE/case-table-840000-session26.md
(cd $B && python3 kind_table.py $T/h84:$T/tn84:session26/library-residual-840000.md) > $HERE/kind-table-840000-session26.md
(cd $B && python3 rule_breaks.py $T/h84:$T/tn84:session26/library-residual-840000.md) > $HERE/rule-breaks-840000-session26.txt
touch $T/ALL_DONE
# 6. The nulls whose verdict was not null, remade by `simulate` (the study's make_case: the
#    same seed, input and --conceal) and diagnosed rank-only, as the study does, by each build.
mkdir -p $T/nullchk
for spec in 2100025:reversal 2100076:constant 2200027:reversal; do s=${spec%%:*}; inp=${spec##*:}
  $BIN simulate --effect none --seed $s --input $inp --conceal --out $T/nullchk/none-$s > /dev/null 2>&1
  for b in session26:$BIN 39de1a3:$BASE; do
    ${b#*:} diagnose --quiet --rank-only --data $T/nullchk/none-$s/recording.csv --model $T/nullchk/none-$s/motor.toml --json $T/nullchk/none-$s-${b%%:*}.json > /dev/null 2>&1
    python3 -c "import json,sys; r=json.load(open(sys.argv[1])); u=r['unexplained']; print(sys.argv[2], sys.argv[3], 'selected', r['selected'], 'unexplained', u and (round(u['evidence'], 2), u['fingerprint']['kind'], u['suggestion'][:100]))" $T/nullchk/none-$s-${b%%:*}.json none-$s ${b%%:*}
  done
done > $HERE/null-alarms-remade.txt
# 7. The jitter cases' truths beside what the verdict reports.
(cd $HERE && python3 jitter_truth.py $P/all83 $T/n83 > jitter-truth-830000-session26.txt)
(cd $HERE && python3 jitter_truth.py $T/h84 $T/n84 > jitter-truth-840000-session26.txt)
(cd $HERE && python3 jitter_truth.py $T/h84 $T/n84-base > jitter-truth-840000-39de1a3.txt)
# 8. The slowest of the 118 by each build in one quiet run, alternating, three times each.
C=$(ls -d $S/hold/h*/bearing_defect-760002)
for k in 1 2 3; do for b in 39de1a3:$BASE session26:$BIN; do
  /usr/bin/time -f "${b%%:*} run $k: %e s wall" ${b#*:} diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $T/time-${b%%:*}.json > /dev/null 2>> $HERE/timing-760002-one-run.txt
done; done
# 9. The chance that two neighbours swap places under a jitter of sd s: Φ(−Δ/(√2·s)), quoted for
#    the search's cap in slope_noise.rs and the section.
python3 -c "
import math
for share in (0.25, 0.5, 1.0):
    print(f's = {share}·Δ: P(swap) = {0.5 * math.erfc(1 / (math.sqrt(2) * share) / math.sqrt(2)):.4f}')
" > $HERE/swap-chance.txt

#!/bin/sh
# Session 14's runs, as they were made. BIN_base is a build of 4ab57c1 (session 13's last
# commit), BIN_new of this session's source (the lag in closed form, a coupling above Nyquist not
# ranked); STUDY the example diagnose_study of the new build. The cases are session 9's, remade
# by its run.sh (beyond_library_cases of 4ab57c1, seeds 760000 and 770000 --volts 2) into
# /tmp/hold/h76 and h77.
set -e
HERE=$(dirname "$0"); B=$HERE/..
# 1. Quiet timing, nothing else running: per case the new build, then the old.
for C in /tmp/hold/h76/*/ /tmp/hold/h77/*/; do N=$(basename $C)
  for BUILD in new base; do eval BIN=\$BIN_$BUILD; R=/tmp/s14/q-$BUILD; mkdir -p $R
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
python3 $B/whole_commands.py /tmp/s14/q-new /tmp/hold/h76 /tmp/hold/h77 > $HERE/whole-command-times-760000-session14-quiet.txt
python3 $B/whole_commands.py /tmp/s14/q-base /tmp/hold/h76 /tmp/hold/h77 > $HERE/whole-command-times-760000-4ab57c1-quiet.txt
python3 $B/session13/verdicts.py /tmp/s14/q-base /tmp/s14/q-new > $HERE/verdicts-40-4ab57c1-session14.txt
python3 $B/session12/compare_full.py /tmp/s14/q-base /tmp/s14/q-new > $HERE/compare-full-40-4ab57c1-session14.txt
python3 $HERE/ranking_moves.py /tmp/s14/q-base /tmp/s14/q-new > $HERE/ranking-moves-40.txt
for f in /tmp/s14/q-new/*.json; do n=$(basename $f .json)
  grep -o "compliant_coupling was not ranked: [^\"]*Nyquist[^\"]*" $f | sed "s/^/$n: /" || true
done > $HERE/nyquist-notes-40.txt
# 2. The library's study and the dynamic terms' studies with the new build (from the root).
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out /tmp/s14/study > $B/study-1100000-session14/log.txt
cp /tmp/s14/study/study.csv /tmp/s14/study/study.json $B/study-1100000-session14/
python3 $B/compare_studies.py $B/study-1100000-session11/study.csv /tmp/s14/study/study.csv > $HERE/compare-study-1100000.txt
$STUDY --effects input_delay,sensor_lag,compliant_coupling --per-effect 10 --null 0 --two 0 --no-dev \
    --seed-base 1200000 --out /tmp/s14/t12 > $B/terms-1200000-session14/log.txt
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out /tmp/s14/t13 > $B/terms-1300000-session14/log.txt
for S in 1200000:t12 1300000:t13; do SEED=${S%%:*}; D=${S##*:}
  cp /tmp/s14/$D/study.csv /tmp/s14/$D/study.json $B/terms-$SEED-session14/
  python3 $B/compare_studies.py $B/terms-$SEED-session5/study.csv /tmp/s14/$D/study.csv > $HERE/compare-terms-$SEED.txt
done
# 3. The sensitivity probe on either build (a checkout of 4ab57c1 in /tmp/base, this one here).
for T in /tmp/base .; do cp $HERE/probe_sensitivities.rs $T/tests/
  (cd $T && echo "== $(git log --oneline -1 | cut -c1-7)" && cargo test --release --test probe_sensitivities -- --nocapture 2>&1 | grep -E "params|test result")
  rm $T/tests/probe_sensitivities.rs
done > $HERE/probe_sensitivities.txt
# 4. The plain model (no term: the integrator's hot path), the whole fit a user waits for, five
#    runs of each build alternating, quiet; then the chains compared byte for byte.
C=tests/fixtures/cases/coulomb_friction
for i in 1 2 3 4 5; do for b in base new; do eval BIN=\$BIN_$b; s=$(date +%s.%N)
  $BIN fit --data $C/recording.csv --model $C/motor.toml --quiet --sampler nuts-dense --k 9 --seed 1 --force --out /tmp/fitab-$b > /dev/null 2>&1
  e=$(date +%s.%N); echo "$b $(echo "$e - $s" | bc)"; done; done > $HERE/fit-plain-model-ab.txt
for k in 1 2 3 4; do cmp /tmp/fitab-base/fit-nuts-dense-chain$k.csv /tmp/fitab-new/fit-nuts-dense-chain$k.csv; done

#!/usr/bin/env bash
# Session 30 (as session 29's real.sh): the real records (HSM150's six identification records, EMPS), whole commands, one
# at a time, by session 29's build (893cc94, HEAD) then this session's (438186c: the angle in what is read of ω, knocks; REV); from the root.
# Compared by `session12/compare_full.py $T/head $T/rev`.
set -e
T=${T:-/tmp/s30/real}
for V in head:$HEAD rev:$REV; do O=$T/${V%%:*}; BIN=${V#*:}; mkdir -p $O
  for f in ../shared/data/real/hsm150/idf_*.csv; do n=$(basename $f .csv)
    $BIN diagnose --quiet --data $f --model examples/hsm150/model.toml --json $O/real-$n.json --out $O/real-$n.d > $O/real-$n.log 2>&1 || true
  done
  $BIN diagnose --quiet --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $O/real-emps.json --out $O/real-emps.d > $O/real-emps.log 2>&1 || true
done

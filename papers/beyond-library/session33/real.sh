#!/usr/bin/env bash
# Session 33: the real records (HSM150's six identification records, EMPS), whole commands, two
# at a time, by BIN (a build of 273bbd0) into $T/new; compared with session 32's reports of
# c861b10 (/tmp/s32/real/rev) by `session12/compare_full.py`. From the root.
T=${T:-/tmp/s33/real}; O=$T/new; mkdir -p $O; export BIN O
{ for f in ../shared/data/real/hsm150/idf_*.csv; do echo "$f examples/hsm150/model.toml real-$(basename $f .csv)"; done
  echo "../shared/data/real/emps/emps_estimation.csv examples/emps/model.toml real-emps"; } |
  xargs -P 2 -L 1 bash -c '$BIN diagnose --quiet --data $0 --model $1 --json $O/$2.json --out $O/$2.d > $O/$2.log 2>&1 || true'

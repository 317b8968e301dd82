#!/usr/bin/env bash
# Session 30's runs, from the root: every case of $T/cases (the 190 of session 29's
# blind_sets.sh and session 27's validate.sh, and this session's h90), whole commands, two at
# a time; a case already diagnosed into $T/NAME is skipped.
#   run.sh BIN NAME   reports into $T/NAME/CASE.json, and a tree $T/tNAME/SET/CASE/report.json
# (Session 29's run.sh quotes $2 inside its inner shell, so it wrote its reports into $T itself;
# the first 74 of session 30's head reports were made so and moved into $T/head, the rest by this.)
set -e
T=${T:-/tmp/s30/b}; BIN=$1; NAME=$2; mkdir -p $T/$NAME
export T BIN NAME
ls -d $T/cases/*/*/ | xargs -P 2 -I{} bash -c '
  C={}; N=$(basename $C); S=$(basename $(dirname $C)); mkdir -p $T/t$NAME/$S/$N
  [ -s $T/$NAME/$N.json ] || $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml \
    --json $T/$NAME/$N.json --out $T/$NAME/$N.d > $T/$NAME/$N.log 2>&1 || true
  ln -sfn $T/$NAME/$N.json $T/t$NAME/$S/$N/report.json'

#!/usr/bin/env bash
# Session 29's runs, from the root. HEAD a build of 5df5977 (session 28's), NEW of this
# session's source (the model as given's fingerprint of what it lacks beyond the library:
# `unexplained::beyond_the_library`). Cases made by blind_sets.sh (sessions 19–28's blind sets)
# and, for the sets where a law is the truth, session 27's validate.sh (h51, h68, h76, h77).
set -e
T=${T:-/tmp/s29/b}; B=papers/beyond-library; HERE=$B/session29
# 1. Every set, whole commands, two at a time (times are not compared here).
run() { # BIN NAME
  ls -d $T/cases/*/*/ | xargs -P 2 -I{} bash -c 'C={}; N=$(basename $C); S=$(basename $(dirname $C)); mkdir -p '$T'/t$2/$S/$N; '$1' diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json '$T'/$2/$N.json --out '$T'/$2/$N.d > '$T'/$2/$N.log 2>&1; ln -sfn '$T'/$2/$N.json '$T'/t$2/$S/$N/report.json'
}
[ "$1" = run ] && { mkdir -p $T/$3; run $2 $3; exit 0; }
# 2. The tables.
for R in head new; do
  for p in h78:session19/library-residual-780000.md h79:session21/library-residual-790000.md \
           h79v:session21/library-residual-790000.md h81:session22/library-residual-810000.md \
           h82:session23/library-residual-820000.md h82v:session23/library-residual-820000.md \
           h83:session25/library-residual-830000.md h83v:session25/library-residual-830000.md \
           h85v:session28/library-residual-850000.md h76:session9/library-residual-760000.md \
           h77:session9/library-residual-770000.md h68:session6/library-residual-680000.md; do
    S=${p%%:*}; L=${p##*:}
    echo "### $S"; (cd $B && python3 kind_table.py $T/cases/$S:$T/t$R/$S:$L)
  done > $HERE/kind-tables-$R.md
done
python3 $B/session12/compare_full.py $T/head $T/new > $HERE/compare-full-head-new.txt || true
python3 $B/session22/verdict_keys.py $T/head $T/new > $HERE/verdict-keys-head-new.txt || true

#!/usr/bin/env bash
# Session 31's kind tables (kind_table.py per set of sets.sh) of the reports $T/tNAME, into
# kind-tables-NAME.md. From the root.
set -e
T=${T:-/tmp/s31/b}; B=papers/beyond-library; HERE=$B/session31; NAME=$1
. $B/session31/sets.sh
for p in $SETS; do
  S=${p%%:*}; L=${p##*:}
  echo "### $S"; (cd $B && python3 kind_table.py $T/cases/$S:$T/t$NAME/$S:$L)
done > $HERE/kind-tables-$NAME.md

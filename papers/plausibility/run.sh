#!/usr/bin/env bash
# The altered recordings of papers/diagnose.md, through the command a user runs: each must be
# refused (non-zero exit, one line per finding, nothing written) with the likely cause, in ≤ 5 s.
# Writes altered/ (the files), messages.txt and times.csv.
#   papers/plausibility/run.sh [path/to/motorcal]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${1:-$root/target/release/motorcal}
shared=$root/../shared/data
python3 "$here/alter.py" "$shared" "$here"
: > "$here/messages.txt"
echo "case,exit,wall_s,named" > "$here/times.csv"
tail -n +2 "$here/altered/cases.csv" | while IFS=, read -r name model cause; do
  cause=${cause%$'\r'}
  [ "$model" = EMPS_MODEL ] && model=$root/examples/emps/model.toml
  out=$(mktemp -d)
  start=$(date +%s.%N)
  set +e
  msg=$("$bin" diagnose --data "$here/altered/$name.csv" --model "$model" --out "$out/d" 2>&1)
  code=$?
  set -e
  end=$(date +%s.%N)
  written=$(find "$out" -type f | wc -l)
  rm -rf "$out"
  named=no; grep -qi -- "$cause" <<<"$msg" && named=yes
  [ "$written" -eq 0 ] || named="wrote-files"
  printf '%s,%s,%.2f,%s\n' "$name" "$code" "$(echo "$end - $start" | bc)" "$named" >> "$here/times.csv"
  { echo "## $name (expected: $cause)"; echo '```'; echo "\$ motorcal diagnose --data altered/$name.csv --model $(basename "$(dirname "$model")")/$(basename "$model")"; echo "$msg" | sed "s|$here/||g; s|$shared/||g; s|$root/||g"; echo "exit $code"; echo '```'; echo; } >> "$here/messages.txt"
done
cat "$here/times.csv"

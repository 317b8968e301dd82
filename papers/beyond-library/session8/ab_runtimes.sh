#!/bin/sh
# Whole `motorcal diagnose` commands on the same cases with several builds, interleaved case by
# case and repeated, so that the machine's drift falls on every build alike. Prints the
# runtime_s each report gave.
#
#   ab_runtimes.sh ROUNDS "CASE_DIR …" BIN …
ROUNDS=$1; CASES=$2; shift 2
OUT=$(mktemp -d)
for i in $(seq "$ROUNDS"); do
  for C in $CASES; do
    for B in "$@"; do
      "$B" diagnose --quiet --data "$C/recording.csv" --model "$C/motor.toml" \
        --json "$OUT/r.json" > /dev/null 2>&1
      python3 -c "import json,sys; print(sys.argv[1], sys.argv[2], sys.argv[3], round(json.load(open(sys.argv[4]))['runtime_s'], 2))" \
        "$(basename "$B")" "$i" "$(basename "$C")" "$OUT/r.json"
    done
  done
done
rm -rf "$OUT"

#!/usr/bin/env bash
# Interleaved A/B of the whole `diagnose` command on the development set: for each case, the
# binary of commit A then of commit B, REPS times, one at a time; user and wall seconds into
# times.csv and each report's JSON beside it, so that selections can be compared.
#   [CASES=DIR] papers/diagnose-speed/run.sh A_BINARY B_BINARY OUT_DIR [REPS] [--rank-only]
# CASES: a folder of case folders (recording.csv, motor.toml); the development set by default.
set -euo pipefail
a=$1; b=$2; out=$3; reps=${4:-1}; extra=${5:-}
dev="${CASES:-$(dirname "$0")/../../../shared/data/concealed-dev}"
mkdir -p "$out"
echo "case,binary,rep,user_s,wall_s" > "$out/times.csv"
for rep in $(seq 1 "$reps"); do
  for d in "$dev"/*/; do
    d=${d%/}
    [ -e "$d/recording.csv" ] || continue
    c=$(basename "$d")
    for bin in "$a" "$b"; do
      n=$(basename "$bin")
      /usr/bin/time -f "$c,$n,$rep,%U,%e" -a -o "$out/times.csv" \
        "$bin" diagnose --quiet $extra --data "$d/recording.csv" --model "$d/motor.toml" \
        --json "$out/$c-$n.json" > /dev/null 2>&1
    done
  done
done

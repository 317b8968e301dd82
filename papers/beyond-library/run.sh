#!/usr/bin/env bash
# The beyond-library development set and the verdict on it: cases made by the independent RK4
# generator (examples/beyond_library_cases.rs), each diagnosed rank-only by the release binary,
# and the summary table (summarize.py), then what the library's best term leaves of each miss
# (examples/library_residual.rs). Two cases at a time on this 2-core machine.
#   papers/beyond-library/run.sh [per-effect] [seed-base]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
per=${1:-2}; seeds=${2:-510000}
cases=${CASES:-/tmp/beyond-library-cases}
cd "$root"
cargo run --release --example beyond_library_cases -- --out "$cases" --per-effect "$per" --seed-base "$seeds"
ls -d "$cases"/*/ | xargs -P 2 -I{} sh -c \
  "target/release/motorcal diagnose --quiet --rank-only --data {}recording.csv --model {}motor.toml --json {}report.json > {}report.txt 2>&1"
python3 "$here/summarize.py" "$cases" > "$here/cases.md"
cat "$here/cases.md"
# What the library's best single term leaves of each noise-free miss (the stand-in criterion).
cargo run --release --example library_residual -- "$cases"/*/ > "$here/library-residual.md"
cat "$here/library-residual.md"

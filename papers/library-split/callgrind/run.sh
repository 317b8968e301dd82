#!/usr/bin/env bash
# The criterion density benches' operations (and a NUTS chain of 200 warm-up + 100 draws on
# BM2(9)) counted in instructions by callgrind, before the split (7ef8f36) and now, interleaved:
# counts do not drift with the machine's load as times do. The driver is the bench's code with
# a fixed number of calls (30, cycling R as the bench does); only the function doing them is
# counted (--toggle-collect), not the MAP before it.
#   papers/library-split/callgrind/run.sh [new-commit]   (writes counts.csv here)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
old=/tmp/motorcal-ab-old; new=/tmp/motorcal-ab-new
git -C "$root" worktree add -f --detach "$old" 7ef8f36
git -C "$root" worktree add -f --detach "$new" "${1:-HEAD}"
sed 's/^IMPORTS$/use motorcal::app::problem::Problem;\nuse motorcal::app::run::map_estimate;/' \
  "$here/ab_count.rs" > "$old/examples/ab_count.rs"
sed 's/^IMPORTS$/use motorcal::pipeline::map_estimate;\nuse motorcal::study::Problem;/' \
  "$here/ab_count.rs" > "$new/examples/ab_count.rs"
(cd "$old" && cargo build --release --example ab_count)
(cd "$new" && cargo build --release --example ab_count)
echo "k,what,side,instructions" > "$here/counts.csv"
count() { # side k what n toggle
  local bin="$old/target/release/examples/ab_count"; [ "$1" = new ] && bin="$new/target/release/examples/ab_count"
  valgrind --tool=callgrind --collect-atstart=no --toggle-collect="*$5*" \
    --callgrind-out-file=/tmp/cg.ab.out "$bin" "$2" "$3" "$4" > /dev/null 2>&1
  echo "$2,$3,$1,$(grep -E '^(summary|totals):' /tmp/cg.ab.out | head -1 | awk '{print $2}')" >> "$here/counts.csv"
}
for k in 0 9 20; do
  for what in f64_solve log_density log_density_gradient fisher_metric; do
    for side in old new; do count $side $k $what 30 measured_density; done
  done
done
for side in old new; do count $side 9 nuts 0 measured_nuts; done
python3 "$here/ratios.py" "$here/counts.csv"

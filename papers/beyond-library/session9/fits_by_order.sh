#!/bin/sh
# fits_by_order.sh CASE K... : the gain of a ripple law sin, cos(k·θ) in the torque balance at
# each order K, through the ODE: `motorcal fit --bm 1 --map-only` on the case's recording with
# its own motor and channels plus ripple-law-model.toml's law at that k (R and the two
# coefficients calibrated), against the case's model with R calibrated alone. Prints each MAP
# line and the log likelihood's rise over the model without the law.
set -e
HERE=$(dirname "$0"); CASE=$1; shift
BIN=${MOTORCAL:-motorcal}
T=$(mktemp -d)
section() { awk -v s="[$1]" '$0 == s {on = 1; print; next} /^\[/ {on = 0} on' "$2"; }
{ echo 'schema = 2'; echo 'base = "voltage_driven"'; echo
  section motor "$CASE/motor.toml"; echo; section channels "$CASE/motor.toml"; echo; } > "$T/case.toml"
{ cat "$T/case.toml"; echo '[calibrate]'; echo '"R" = {}'; } > "$T/none.toml"
NONE=$($BIN fit --data "$CASE/recording.csv" --model "$T/none.toml" --bm 1 --map-only --out "$T/none" | grep '^MAP:')
echo "none: $NONE"
loglik() { echo "$1" | sed 's/.*log likelihood \([-0-9.]*\),.*/\1/'; }
for K in "$@"; do
  { cat "$T/case.toml"; section terms.law "$HERE/ripple-law-model.toml" | sed "s/^k = K/k = $K/"; echo
    section calibrate "$HERE/ripple-law-model.toml"; } > "$T/k.toml"
  MAP=$($BIN fit --data "$CASE/recording.csv" --model "$T/k.toml" --bm 1 --map-only --out "$T/k$K" | grep '^MAP:')
  echo "k = $K: $MAP; rise $(awk -v a="$(loglik "$MAP")" -v b="$(loglik "$NONE")" 'BEGIN {printf "%.2f", a - b}') nats"
done
rm -rf "$T"

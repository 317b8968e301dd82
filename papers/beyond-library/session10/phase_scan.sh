#!/bin/sh
# The law's likelihood against the phase of its sin, cos(6·θ) pair on cogging-770016
# (h77 of session 9: `beyond_library_cases --out DIR --effects gear_ripple,bearing_defect,
# eccentric,cogging --per-effect 5 --seed-base 770000 --volts 2`).
#   phase_scan.sh CASE_DIR MODEL_TOML
# MODEL_TOML: a diagnosis's amended model.toml of the case (its law term at k = 6, R and the
# pair calibrated). Prints, for amplitudes 0.0663, 0.1325, 0.265 N·m (½, 1, 2 × the model as
# given's fingerprint, (−0.0693, 0.1129)) and phases 0°, 30°, … 330° (sin coefficient
# amplitude·cos, cos coefficient amplitude·sin), the MAP log density with the pair held there
# (R and the noise calibrated): the start's worth. Then the MAP reached with the pair free from
# the fingerprint's own pair and from the grid's best start, (0.1325, 0) as the scan printed it.
# $MOTORCAL: the binary (default motorcal).
set -e
C=$1; M=$2; B=${MOTORCAL:-motorcal}; T=$(mktemp -d)
at() { sed -e "s/^\"torque:sin(k\*theta)\" = .*/\"torque:sin(k*theta)\" = $1/" \
           -e "s/^\"torque:cos(k\*theta)\" = .*/\"torque:cos(k*theta)\" = $2/" $M; }
echo "amplitude phase_deg sin cos held_log_density"
for amp in 0.0663 0.1325 0.2650; do for deg in 0 30 60 90 120 150 180 210 240 270 300 330; do
  a=$(python3 -c "import math; print(round($amp*math.cos(math.radians($deg)), 6))")
  b=$(python3 -c "import math; print(round($amp*math.sin(math.radians($deg)), 6))")
  at $a $b | grep -v '^"law' > $T/held.toml
  lp=$($B fit --quiet --bm 1 --data $C/recording.csv --model $T/held.toml --map-only --out $T/o | awk '/^MAP/ {print $4}')
  echo "$amp $deg $a $b ${lp%,}"
done; done
for pair in "-0.0693 0.1129" "0.1325 0"; do set -- $pair
  at $1 $2 > $T/free.toml
  echo "free from ($1, $2):"
  $B fit --quiet --bm 1 --data $C/recording.csv --model $T/free.toml --map-only --out $T/o | grep -E "^MAP|k\*theta"
done
rm -rf $T

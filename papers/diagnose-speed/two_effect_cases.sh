#!/usr/bin/env bash
# Fresh two-effect concealed cases for the timing of issue 21 (seeds 991000 on; no test or
# tuning used them): each pair of the library's thirteen static terms below, one seed each, by
# `simulate --effect a,b --conceal`. A pair the generator cannot make fair is reported and
# skipped.
#   papers/diagnose-speed/two_effect_cases.sh MOTORCAL_BINARY OUT_DIR
set -uo pipefail
bin=$1; out=$2
pairs="viscous_friction,load_torque coulomb_friction,resistance_heating torque_constant,quadratic_drag
speed_gain,current_offset voltage_drop,load_step back_emf_constant,asymmetric_friction
armature_reaction,viscous_friction load_torque,current_offset quadratic_drag,resistance_heating
coulomb_friction,speed_gain torque_constant,load_step voltage_drop,asymmetric_friction"
seed=991000
for p in $pairs; do
  seed=$((seed + 1))
  d="$out/${p/,/+}-$seed"
  if ! "$bin" simulate --effect "$p" --conceal --seed "$seed" --out "$d" > /dev/null 2> "$out/err-$seed.txt"; then
    echo "$p seed $seed: not made: $(tail -1 "$out/err-$seed.txt")"
    rm -rf "$d"
  fi
done

#!/usr/bin/env bash
# The slowest slow records timed quietly, BASE (bdcb9c3) and NEW (the spot) alternating, twice
# each, one at a time, whole commands. From the root, after validate.sh cases.
T=${T:-/tmp/s28/v}; BASE=${BASE:-/tmp/s28/bin/motorcal-base}; NEW=${NEW:-/tmp/s28/bin/motorcal-final}
for N in cogging-770012 cogging-770008 bearing_defect-770014; do C=$T/cases/h77/$N
  for rep in 1 2; do for B in BASE NEW; do BIN=${!B}
    s=$(date +%s.%N)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json /tmp/s28/time.json --out /tmp/s28/time.d > /dev/null 2>&1
    e=$(date +%s.%N)
    printf '%s %s rep %d: %.1f s\n' $N $B $rep $(echo "$e - $s" | bc)
  done; done
done

#!/usr/bin/env bash
# Interleaved A/B of `motorcal diagnose` on the development set: old (7ef8f36) and new binaries,
# three repeats, the whole command's wall time per case, and the JSON compared apart from run times.
set -u
OLD=/tmp/ab/motorcal-old; NEW=/tmp/ab/motorcal-new
DEV=/work/shared/data/concealed-dev
echo "rep,case,build,wall_s" > /tmp/ab/times.csv
for rep in 1 2 3; do
  for i in $(seq -w 1 14); do
    for b in old new; do
      bin=$OLD; [ $b = new ] && bin=$NEW
      s=$(date +%s.%N)
      $bin diagnose --data $DEV/case$i/recording.csv --model $DEV/case$i/motor.toml --quiet --json /tmp/ab/$b-case$i-r$rep.json > /dev/null 2>&1
      e=$(date +%s.%N)
      echo "$rep,case$i,$b,$(echo "$e - $s" | bc)" >> /tmp/ab/times.csv
    done
  done
done

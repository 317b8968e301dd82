#!/usr/bin/env bash
# nutpie with its low-rank modified mass matrix (core 0; seeds 0 1 2 in turn at each K) beside
# motorcal's bench (core 1, again and again while nutpie runs), on the peers' data and model
# (../shared/peers/nutpie_closed.py --low-rank: the same PyMC model, the ODE in closed form).
# times.log pairs each nutpie run with the runs of ours that overlapped it.
# usage (from the repository root, with a Python that has nutpie 0.16.8 and pymc 5.28.5):
#   [KS="9 20"] [SEEDS="0 1 2"] [PY=python] bash papers/john2018/peers/side-by-side-lowrank/run.sh [OUTDIR]
# then: python3 papers/john2018/peers/side-by-side-lowrank/ratio.py OUTDIR
set -euo pipefail
PY="${PY:-python3}"
KS="${KS:-9 20}"
SEEDS="${SEEDS:-0 1 2}"
SAMPLERS="${SAMPLERS:-laplace-is,nuts-dense}"
PEERS="$(cd "$(pwd)/../shared/peers" && pwd)"
BIN="$(pwd)/target/release/motorcal"
MODEL="$(pwd)/examples/paper/motor.toml"
HERE="$(mkdir -p "${1:-$(dirname "$0")}" && cd "${1:-$(dirname "$0")}" && pwd)"
cd "$HERE"
load() { cut -d' ' -f1 /proc/loadavg; }
for K in $KS; do
  echo "K $K start $(date +%s.%N) load $(load)" >> times.log
  rm -f nutpie.done
  (
    for s in $SEEDS; do
      OMP_NUM_THREADS=1 taskset -c 0 "$PY" "$PEERS/nutpie_closed.py" --K "$K" --seed "$s" --low-rank \
        --out "$HERE/nutpie_k${K}_s$s.json" > "nutpie_k${K}_s$s.log" 2>&1
      echo "nutpie K $K seed $s end $(date +%s.%N)" >> times.log
    done
    touch nutpie.done
  ) &
  i=0
  while [ ! -e nutpie.done ]; do
    i=$((i + 1))
    echo "ours K $K run $i start $(date +%s.%N)" >> times.log
    taskset -c 1 "$BIN" bench --k "$K" --threads 1 --samplers "$SAMPLERS" \
      --data "$PEERS/data/paper_seed1.csv" --model "$MODEL" \
      --out "/tmp/motorcal-lowrank-$K-$i" --json "motorcal_k${K}_run$i.json" --quiet \
      > "motorcal_k${K}_run$i.log" 2>&1
    echo "ours K $K run $i end $(date +%s.%N) load $(load)" >> times.log
  done
  wait
  rm -f nutpie.done
done

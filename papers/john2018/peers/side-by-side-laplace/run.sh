#!/usr/bin/env bash
# nutpie (core 0, seeds 0 1 2 in turn) beside motorcal's bench at K = 9 (core 1, again and again
# while nutpie runs); times.log pairs each nutpie seed with the runs of ours that overlapped it.
# usage (from the repository root):
#   [SEEDS="0 1 2"] [PY=python-with-nutpie] bash papers/john2018/peers/side-by-side-laplace/run.sh [OUTDIR]
# then: python3 papers/john2018/peers/side-by-side-cost/ratio.py OUTDIR
set -euo pipefail
PY="${PY:-/work/peers-venv/bin/python}"
SEEDS="${SEEDS:-0 1 2}"
PEERS="$(cd "$(pwd)/../shared/peers" && pwd)"
BIN="$(pwd)/target/release/motorcal"
MODEL="$(pwd)/examples/paper/motor.toml"
HERE="$(mkdir -p "${1:-$(dirname "$0")}" && cd "${1:-$(dirname "$0")}" && pwd)"
cd "$HERE"
load() { cut -d' ' -f1 /proc/loadavg; }
echo "start $(date +%s.%N) load $(load)" > times.log
(
  for s in $SEEDS; do
    OMP_NUM_THREADS=1 taskset -c 0 "$PY" "$PEERS/nutpie_closed.py" --K 9 --seed $s \
      --out "$HERE/nutpie_k9_s$s.json" > "nutpie_k9_s$s.log" 2>&1
    echo "nutpie seed $s end $(date +%s.%N)" >> times.log
  done
  touch nutpie.done
) &
rm -f nutpie.done
i=0
while [ ! -e nutpie.done ]; do
  i=$((i + 1))
  echo "ours $i start $(date +%s.%N)" >> times.log
  taskset -c 1 "$BIN" bench --k 9 --threads 1 --samplers nuts-dense,hmc-dense,mala,fisher-mala \
    --data "$PEERS/data/paper_seed1.csv" --model "$MODEL" \
    --out "/tmp/motorcal-side-by-side-$i" --json "motorcal_k9_run$i.json" --quiet > "motorcal_k9_run$i.log" 2>&1
  echo "ours $i end $(date +%s.%N) load $(load)" >> times.log
done
wait
rm -f nutpie.done

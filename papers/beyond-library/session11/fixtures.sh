#!/bin/sh
# The three angle fixtures the order's whole-order twin is about, diagnosed by each build:
# BINS="name=path ..." (session 11: 595d721, 78271af = the reverted quarter rule, 863f82b).
# Prints the model as given's fingerprint (first order) and the law discovered (through the ODE).
F=$(dirname "$0")/../../../tests/fixtures/beyond
for C in cogging-770016 cogging-530007 bearing_defect-770014; do
  for B in $BINS; do N=${B%%=*}; BIN=${B#*=}; T=$(mktemp -d)
    $BIN diagnose --quiet --data $F/$C/recording.csv --model $F/$C/motor.toml --json $T/r.json --out $T/d > /dev/null
    python3 - "$C" "$N" "$T/r.json" <<'PY'
import json, sys
c, n, p = sys.argv[1:]
r = json.load(open(p))
f = (r["unexplained_as_given"] or {}).get("fingerprint") or {}
fs = ", ".join(x["name"] for x in f.get("functions", []))
d = r["discovered"]
eq = d["equation"] if d else None
score = f'{d["score"]:.2f}' if d else "-"
print(f"{c} {n}: first order {fs} at k {f.get('k')} ({f.get('score', float('nan')):.2f} nats); "
      f"law {eq}, the law's score {score}")
PY
    rm -rf $T
  done
done

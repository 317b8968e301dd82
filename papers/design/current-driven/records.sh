#!/bin/sh
# Session 13: issue 20's "20 noisy records per truth" on the current-driven designs of run.sh.
# Run run.sh first (same W). For each tie, each candidate is the truth at its MAP on the constant
# 1-A record (design.json's `candidates_at`); 20 records (seeds 1001-1020, σ_ω = 1 rad/s) of the
# designed current are ranked twice by `diagnose --rank-only`: between the pair
# (`--candidates a,b`) and over the whole library. BIN is a build of the commit in README.md.
set -e
BIN=${BIN:-motorcal}
HERE=$(cd "$(dirname "$0")" && pwd); ROOT=$HERE/../../..
FIX=$ROOT/tests/fixtures/design/current_driven.toml
W=${W:-/tmp/design-current}
for PAIR in coulomb_friction,load_torque viscous_friction,quadratic_drag; do
  D=$W/${PAIR%%,*}
  for TRUTH in ${PAIR%%,*} ${PAIR#*,}; do
    T=$D/records/$TRUTH; rm -rf $T; mkdir -p $T
    # The truth file: the fixture with J and the term at the candidate's MAP.
    python3 - "$FIX" "$D/design/design.json" "$TRUTH" > $T/truth.toml <<'PY'
import json, sys
fixture, design, truth = sys.argv[1:]
values = json.load(open(design))["candidates_at"]["values"][truth]
term = [f"{k.split('.', 1)[1]} = {v!r}" for k, v in values.items() if "." in k]
section = ""
for line in open(fixture).read().splitlines():
    if line.startswith("["):
        section = line
    if section == "[motor]" and line.startswith("J = "):
        line = f"J = {values['J']!r}"
    if line == "[drive]":
        print(f"[terms.{truth}]\n" + "\n".join(term) + "\n")
    print(line)
PY
    for SEED in $(seq 1001 1020); do
      R=$T/$SEED
      $BIN simulate --truth $T/truth.toml --nominal $FIX --input $D/design/input.csv --noise-sd 0 1 \
          --seed $SEED --out $R > /dev/null
      $BIN diagnose --quiet --rank-only --data $R/recording.csv --model $FIX --candidates $PAIR \
          --json $R/pair.json --out $R/pair > /dev/null
      $BIN diagnose --quiet --rank-only --data $R/recording.csv --model $FIX \
          --json $R/whole.json --out $R/whole > /dev/null
    done
  done
done
python3 - "$W" <<'PY'
import csv, json, sys, glob, os
w = sys.argv[1]
print("| truth | rival | pair: truth selected (of 20) | truth's lead over rival, min / median (nats) | whole library: truth selected | truth selected or tied | whole library's selections |")
print("|---|---|---|---|---|---|---|")
for pair in (("coulomb_friction", "load_torque"), ("viscous_friction", "quadratic_drag")):
    for truth in pair:
        rival = pair[1] if truth == pair[0] else pair[0]
        runs = sorted(glob.glob(f"{w}/{pair[0]}/records/{truth}/*/pair.json"))
        leads, pair_hits, whole_hits, tied_hits, picks, behind = [], 0, 0, 0, {}, []
        for p in runs:
            r = json.load(open(p))
            score = {e["effect"]: e["score"] for e in r["ranking"]}
            leads.append(score.get(truth, float("nan")) - score.get(rival, float("nan")))
            pair_hits += r["selected"] == truth
            q = json.load(open(os.path.join(os.path.dirname(p), "whole.json")))
            whole_hits += q["selected"] == truth
            whole = {e["effect"]: e["score"] for e in q["ranking"]}
            if q["selected"] != truth:
                behind.append((max(whole.values()), whole.get(truth, float("nan"))))
            tied_hits += q["selected"] == truth or truth in (q.get("ties") or [])
            name = str(q["selected"]) + ("" if not q.get("ties") else " (ties " + ", ".join(q["ties"]) + ")")
            picks[name] = picks.get(name, 0) + 1
        leads.sort()
        med = leads[len(leads) // 2] if leads else float("nan")
        pk = "; ".join(f"{k} {v}" for k, v in sorted(picks.items(), key=lambda kv: -kv[1]))
        print(f"| {truth} | {rival} | {pair_hits} of {len(runs)} | {leads[0]:.1f} / {med:.1f} | {whole_hits} | {tied_hits} | {pk} |")
        # Where the whole library put another term on top: how far below it the truth scored.
        below = [top - own for top, own in behind]
        if below:
            print(f"|   | where {truth} was not on top ({len(below)}): it scored at most {max(below):.3f} nats below the top |")
# The speeds each designed record reaches (the noise included): whether a design reverses.
for pair in (("coulomb_friction", "load_torque"), ("viscous_friction", "quadratic_drag")):
    lows, highs = [], []
    for p in glob.glob(f"{w}/{pair[0]}/records/*/*/recording.csv"):
        rows = list(csv.DictReader(open(p)))
        speeds = [float(r["omega"]) for r in rows]
        lows.append(min(speeds)); highs.append(max(speeds))
    print(f"{pair[0]}'s design: omega from {min(lows):.1f} to {max(highs):.1f} rad/s over its {len(lows)} records")
PY

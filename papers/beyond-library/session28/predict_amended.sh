#!/usr/bin/env bash
# The amended model.toml that `diagnose --out` writes for encoder_missing_line-835002 (its law
# the spot in measured ω) read back by `predict` on the same record, beside the nominal model:
# the ω residual's RMS against the record's own noise (recording − truth). From the root.
set -e
T=${T:-/tmp/s28/v}; BIN=${BIN:-target/release/motorcal}; C=$T/cases/h83v/encoder_missing_line-835002
$BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $T/p835002.json --out $T/p835002.d > /dev/null
echo "## the amended model (the spot's law)"; $BIN predict --model $T/p835002.d/model.toml --data $C/recording.csv
echo "## the nominal model"; $BIN predict --model $C/motor.toml --data $C/recording.csv
python3 - $C <<'PY'
import csv, math, sys
rec = list(csv.DictReader(open(sys.argv[1] + "/recording.csv")))
tru = list(csv.DictReader(open(sys.argv[1] + "/truth.csv")))
d = [float(a["omega"]) - float(b["omega"]) for a, b in zip(rec, tru)]
print(f"## the record's own noise on omega (RMS of recording - truth): {math.sqrt(sum(x * x for x in d) / len(d)):.4f} rad/s")
PY

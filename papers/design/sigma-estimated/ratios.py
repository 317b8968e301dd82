"""Reads out.txt (run.sh's output) and prints, for each truth of the design_study runs, the
expected gap with σ estimated, the one at the σ given and the 20 records' lead, with how far
the records' mean lies from the expected gap in its sds and how many times the figure at the σ
given is the records' mean and how far it lies above the expected gap; then the same for the current-driven loop's one record each."""
import re
import sys

text = open(sys.argv[1] if len(sys.argv) > 1 else "out.txt").read()
case = None
expected = {}
print("case | truth | expected ± sd | at σ given | records' lead | (records − expected)/sd | at σ given / records | at σ given − expected")
for line in text.splitlines():
    m = re.match(r"\$ cargo run .* separate (\S+) ", line)
    if m:
        case, expected = m.group(1), {}
        continue
    m = re.match(r"\s+(\w+) as truth over (\w+): ([-\d.]+) ± ([\d.]+), σ estimated \(at the σ given ([-\d.]+)", line)
    if m and case:
        expected[m.group(1)] = tuple(float(m.group(i)) for i in (3, 4, 5))
        continue
    m = re.match(r"\s+(\w+) as truth, 20 records .* its lead over the best other ([-\d.]+) ± ([\d.]+) nats", line)
    if m and case:
        e, sd, known = expected[m.group(1)]
        lead, lead_sd = float(m.group(2)), float(m.group(3))
        print(f"{case} | {m.group(1)} | {e:.2f} ± {sd:.2f} | {known:.2f} | {lead:.2f} ± {lead_sd:.2f} | "
              f"{(lead - e) / sd:+.2f} | {known / lead:.2f} | {known - e:+.2f}")
print("current-driven | truth | expected ± sd | on the record | (record − expected)/sd")
for m in re.finditer(r"(\w+) \(truth\) vs \w+: designed ([\d.]+) ± ([\d.]+) nats.*a lead of ([\d.]+) nats", text):
    e, sd, lead = (float(m.group(i)) for i in (2, 3, 4))
    print(f"current-driven | {m.group(1)} | {e:.1f} ± {sd:.1f} | {lead:.1f} | {(lead - e) / sd:+.2f}")

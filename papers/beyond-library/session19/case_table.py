#!/usr/bin/env python3
"""One line per case of a set: the truth's fingerprint, what the whole command selected, the
model as given's fingerprint, the verdict after, the law discovered.

    case_table.py CASES_DIR REPORTS_DIR   (REPORTS_DIR/NAME.json, `motorcal diagnose --json`)"""
import glob, json, os, sys

cases, reports = sys.argv[1:3]


def fingerprint(u):
    if not u:
        return "—"
    f = u["fingerprint"]
    s = f["kind"]
    if s == "oscillation":
        s += f" {f.get('frequency_hz', 0):.1f} Hz ζ {f.get('damping_ratio') or 0:.2f} on {f.get('channel')}, ringing {f.get('ringing')}"
    if s in ("delay", "lag"):
        s += f" {f['seconds'] * 1e3:.3f} ms {f.get('channel', '')}"
    if s == "state":
        s += f" {f.get('balance')}: " + ", ".join(x["name"] for x in f.get("functions", []))
    if s == "drift":
        s += " " + f.get("variable", "")
    return s + f" ({u.get('evidence', 0):.1f} nats)"


print("| case | type, miss | truth | selected | the model as given | verdict after | law |")
print("|---|---|---|---|---|---|---|")
for d in sorted(glob.glob(f"{cases}/*/")):
    n = os.path.basename(d[:-1])
    a = json.load(open(d + "answer.json"))
    r = json.load(open(f"{reports}/{n}.json"))
    fp = a["fingerprint"]
    truth = fp["kind"]
    if "frequency_hz" in fp:
        truth += f" {fp['frequency_hz']:.1f} Hz"
    if "seconds" in fp:
        truth += f" {fp['seconds'] * 1e3:.3f} ms"
    law = r.get("discovered")
    law = law["equation"] if law else "—"
    print(f"| {n} | {a['type']}, {a['miss_nats']:.0f} | {truth} | {' + '.join(r['selected_set']) or 'none'} | "
          f"{fingerprint(r.get('unexplained_as_given'))} | {fingerprint(r.get('unexplained'))} | {law} |")

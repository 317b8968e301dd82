#!/usr/bin/env python3
"""The model as given's fingerprint, its alternatives, the best single library terms and the
selection, per case, as the reports of one build hold them:

    as_given_cases.py REPORTS_DIR CASE ...   (REPORTS_DIR/CASE.json, `motorcal diagnose --json`)
"""
import json, sys


def fp(f):
    k = f["kind"]
    if k in ("state", "drift"):
        return f"{k} {f['balance']}: {','.join(x['name'] for x in f['functions'])} ({f['score']:+.1f})"
    if k == "oscillation":
        return f"oscillation {f['frequency_hz']:.2f} Hz on {f['channel']}, ringing {f['ringing']} ({f['score']:+.1f})"
    return f"{k} ({f.get('score', float('nan')):+.1f})"


reports = sys.argv[1]
for case in sys.argv[2:]:
    r = json.load(open(f"{reports}/{case}.json"))
    g = r["unexplained_as_given"]
    singles = [c for c in r["ranking"] if "+" not in c["effect"] and c["effect"] != "law"]
    law = [c for c in r["ranking"] if c["effect"] == "law"]
    print(f"{case}:")
    print(f"  as given: {fp(g['fingerprint']) if g else '—'}")
    for a in (g or {}).get("alternatives", []):
        print(f"    alternative: {fp(a)}")
    print("  best single library terms: " + ", ".join(f"{c['effect']} {c['score']:+.1f}" for c in singles[:3]))
    print(f"  the law alone through the ODE: {law[0]['score']:+.1f}" if law else "  the law alone: not selected alone")
    print(f"  selected: {' + '.join(r['selected_set']) or 'none'}")

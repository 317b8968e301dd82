#!/usr/bin/env python3
"""The verdict on each beyond-library case against its truth, as a Markdown table and a tally."""
import json, os, sys

d = sys.argv[1]
rows, tally = [], {}
for c in sorted(os.listdir(d)):
    p = os.path.join(d, c)
    if not os.path.exists(f"{p}/report.json"):
        continue
    a = json.load(open(f"{p}/answer.json")); r = json.load(open(f"{p}/report.json"))
    u = r.get("unexplained"); truth = a["fingerprint"]
    fp = u["fingerprint"] if u else None
    # The verdict on the model as given (before any term): the fingerprint of the whole miss.
    g = r.get("unexplained_as_given")
    fp_given = g["fingerprint"] if g else None
    def show(f):
        if not f: return "—"
        k = f["kind"]
        if k == "oscillation":
            z = f.get("damping_ratio")
            return f"oscillation {f['frequency_hz']:.1f} Hz on {f['channel']}, {'rings' if f['ringing'] else 'runs on'}" + (f", ζ {z:.3f}" if z is not None else "")
        if k == "delay": return f"delay {f['seconds']*1e3:.3f} ms"
        if k == "lag": return f"lag on {f['channel']} {f['seconds']*1e3:.3f} ms"
        if k == "state": return f"state ({f['balance']}): {', '.join(x['name'] for x in f['functions'])}"
        if k == "drift": return f"drift: {f['variable']}"
        return k
    def show_truth(t):
        k = t["kind"]
        if k == "oscillation":
            f = f"{t['frequency_hz']:.1f} Hz " if "frequency_hz" in t else ""
            return f"oscillation {f}({'rings' if t['ringing'] else 'runs on'})"
        if k in ("delay", "lag"): return f"{k}{' on '+t['channel'] if k=='lag' else ''} {t['seconds']*1e3:.3f} ms"
        if k == "state": return f"state{' ('+t['balance']+')' if 'balance' in t else ''}: {', '.join(t['functions'])}"
        return f"{k}: {t.get('variable','')}"
    def law(x):
        # The equation as the report prints it, its 95% intervals shortened.
        return x["equation"].replace(" [95%: ", " [") if x else "—"
    kind_right = bool(fp_given) and fp_given["kind"] == truth["kind"]
    said_nothing = not u and not r["selected_set"]
    # The dynamic terms and the law are what a fingerprint names; any other selection with the
    # verdict null is a library term standing in for the effect.
    named = {"input_delay", "sensor_lag", "compliant_coupling", "law"}
    by_fingerprint = any(s in named for s in r["selected_set"])
    library_alone = not u and bool(r["selected_set"]) and not by_fingerprint
    key = a["effect"]
    t = tally.setdefault(key, [0, 0, 0, 0, 0])
    t[0] += 1; t[1] += bool(u); t[2] += kind_right; t[3] += by_fingerprint; t[4] += library_alone
    rows.append(f"| {c} | {a['type']} | {a['miss_nats']:.0f} | {show_truth(truth)} | {' + '.join(r['selected_set']) or 'none'} | "
                f"{'%+.1f' % u['evidence'] if u else 'null'} | {show(fp)} | {show(fp_given)} | {law(r.get('discovered'))} | {'nothing missing found' if said_nothing else ''} |")
print("| case | type | miss (nats) | truth | selected | unexplained | fingerprint | fingerprint of the model as given | discovered law | |")
print("|---|---|---|---|---|---|---|---|---|---|")
print("\n".join(rows))
print()
print("| effect | cases | unexplained not null after | the model as given's fingerprint of the right kind | a dynamic term or law selected | a library term alone, verdict null |")
print("|---|---|---|---|---|---|")
for k, (n, u, kr, fp, lib) in sorted(tally.items()):
    print(f"| {k} | {n} | {u} | {kr} | {fp} | {lib} |")
n = sum(t[0] for t in tally.values()); kr = sum(t[2] for t in tally.values())
print(f"\nfingerprint of the model as given of the truth's kind: {kr} of {n}")

"""For jitter cases where a library term was selected and the verdict is null: the selected
set's score over the model as given (the shift an as-given alternative must clear), the as-given
verdict's fingerprint and alternatives with their scores, and what each clears by.
Usage: jitter_lag.py REPORT.json..."""
import json
import sys

print("case | selected | its score over none | as-given leader (score) | as-given alternatives | leader − selected's score | verdict | the leader's τ ± sd [ms]")
for path in sys.argv[1:]:
    r = json.load(open(path))
    none = next(e["score"] for e in r["ranking"] if e["effect"] == "none")
    chosen = next((e["score"] for e in r["ranking"] if e["effect"] == r["selected"]), float("nan"))
    a = r["unexplained_as_given"] or {}
    f = a.get("fingerprint", {})
    lead = f.get("score", float("nan"))
    alts = ", ".join(f"{x['kind']} {x['score']:.2f}" for x in a.get("alternatives", []))
    u = r["unexplained"]
    name = path.rsplit("/", 1)[-1].removesuffix(".json")
    print(f"{name} | {r['selected']} | {chosen - none:.2f} | {f.get('kind')} {f.get('channel', '')} ({lead:.2f}) | {alts or '—'} | "
          f"{lead - (chosen - none):+.2f} | {u and u['fingerprint']['kind']} | "
          + (f"{f['seconds'] * 1e3:.3f} ± {f['sd'] * 1e3:.3f}" if "seconds" in f else "—"))

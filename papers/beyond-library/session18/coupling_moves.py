"""Per case of two report folders, where the compliant coupling's ranked score moved by more
than half a nat (or it was ranked in one only): its score and f_r in each, the top of the new
ranking, how far under it the coupling stands, and the selections; last, where it rose, the
least such distance. Usage: coupling_moves.py OLD NEW"""
import glob, json, os, sys

old, new = sys.argv[1:]
def coupling(r):
    c = [x for x in r["ranking"] if x["effect"] == "compliant_coupling"]
    return (c[0]["score"], c[0]["params"].get("f_r")) if c else (None, None)
fmt = lambda v: "—" if v is None else f"{v:.1f}"
print("| case | coupling score | f_r [Hz] | top of the new ranking | under the top | selected (old → new) |")
print("|---|---|---|---|---|---|")
rose = []
for p in sorted(glob.glob(f"{old}/*.json")):
    n = os.path.basename(p)[:-5]
    a, b = json.load(open(p)), json.load(open(f"{new}/{n}.json"))
    (sa, fa), (sb, fb) = coupling(a), coupling(b)
    if sa is None and sb is None or (sa is not None and sb is not None and abs(sa - sb) <= 0.5):
        continue
    top = b["ranking"][0]
    under = None if sb is None else top["score"] - sb
    if sb is not None and (sa is None or sb > sa):
        rose.append((under, n))
    print(f"| {n} | {fmt(sa)} → {fmt(sb)} | {fmt(fa)} → {fmt(fb)} | {top['effect']} {top['score']:.1f} | "
          f"{fmt(under)} | {'+'.join(a['selected_set']) or 'none'} → {'+'.join(b['selected_set']) or 'none'} |")
if rose:
    least = min(rose)
    print(f"\nrose (or ranked only now) on {len(rose)}; the least distance under the top {least[0]:.1f} nats ({least[1]})")

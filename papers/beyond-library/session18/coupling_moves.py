"""Per case of two report folders, where the compliant coupling's ranked score moved by more
than half a nat (or it was ranked in one only): its score and f_r in each, the top of the new
ranking and the selections. Usage: coupling_moves.py OLD NEW"""
import glob, json, os, sys

old, new = sys.argv[1:]
def coupling(r):
    c = [x for x in r["ranking"] if x["effect"] == "compliant_coupling"]
    return (c[0]["score"], c[0]["params"].get("f_r")) if c else (None, None)
fmt = lambda v: "—" if v is None else f"{v:.1f}"
print("| case | coupling score | f_r [Hz] | top of the new ranking | selected (old → new) |")
print("|---|---|---|---|---|")
for p in sorted(glob.glob(f"{old}/*.json")):
    n = os.path.basename(p)[:-5]
    a, b = json.load(open(p)), json.load(open(f"{new}/{n}.json"))
    (sa, fa), (sb, fb) = coupling(a), coupling(b)
    if sa is None and sb is None or (sa is not None and sb is not None and abs(sa - sb) <= 0.5):
        continue
    top = b["ranking"][0]
    print(f"| {n} | {fmt(sa)} → {fmt(sb)} | {fmt(fa)} → {fmt(fb)} | {top['effect']} {top['score']:.1f} | "
          f"{'+'.join(a['selected_set']) or 'none'} → {'+'.join(b['selected_set']) or 'none'} |")

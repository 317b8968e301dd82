"""How far each ranked candidate's score moved between two runs of whole-command reports, per
effect: the largest |Δscore| over the cases, and the case it is on. Usage: ranking_moves.py A B"""
import glob, json, os, sys

a_dir, b_dir = sys.argv[1:]
moves = {}
for p in sorted(glob.glob(f"{a_dir}/*.json")):
    n = os.path.basename(p)[:-5]
    a, b = json.load(open(p)), json.load(open(f"{b_dir}/{n}.json"))
    sa = {str(c["effect"]): c["score"] for c in a["ranking"]}
    sb = {str(c["effect"]): c["score"] for c in b["ranking"]}
    for e in sorted(set(sa) | set(sb)):
        if e in sa and e in sb:
            d = abs(sa[e] - sb[e])
            if d > moves.get(e, (-1, ""))[0]:
                moves[e] = (d, n)
        else:
            print(f"{n}: {e} ranked in {'the first' if e in sa else 'the second'} run only")
print("| candidate | largest score change (nats) | case |")
print("|---|---|---|")
for e, (d, n) in sorted(moves.items(), key=lambda kv: -kv[1][0]):
    print(f"| {e} | {d:.2e} | {n} |")

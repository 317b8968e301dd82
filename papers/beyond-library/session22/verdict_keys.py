import json,sys,os
A,B=sys.argv[1],sys.argv[2]
def key(r):
    g=r.get('unexplained_as_given'); u=r.get('unexplained'); d=r.get('discovered')
    fk=lambda x: None if not x else (x['fingerprint']['kind'], x['fingerprint'].get('channel'), x['fingerprint'].get('ringing'), round(x['evidence'],1))
    return (r.get('selected'), fk(g), fk(u), d and [f['name'] for f in d['functions']])
same=0; diff=[]
for f in sorted(os.listdir(A)):
    if not f.endswith('.json'): continue
    if not os.path.exists(os.path.join(B,f)): continue
    a=key(json.load(open(os.path.join(A,f)))); b=key(json.load(open(os.path.join(B,f))))
    if a==b: same+=1
    else: diff.append((f[:-5],a,b))
for d in diff: print(f"{d[0]}:\n  before {d[1]}\n  after  {d[2]}")
print(f"{same} the same in what is selected, the two verdicts' kind, channel, ringing and evidence (0.1 nat), and the law's functions; {len(diff)} differ")

"""Session 29's test of a law that holds through the record (a Chow test): the model as given's
leading state or drift law refitted with its coefficients free on each half of the record, and
between the input's steps, its gain less ½·ln N per added coefficient ("net"). Made with
split-diagnostic.patch applied to d0c4e4e's parent and every case run as
`MOTORCAL_DEBUG_SPLIT=1 motorcal diagnose --quiet --rank-only … --json /tmp/s29/split/CASE.json
2> /tmp/s29/split/CASE.err`; cases from blind_sets.sh and session 27's validate.sh. Prints
each case whose as-given leader is a law.
"""
import json,glob,os,re,sys
rows=[]
for f in sorted(glob.glob('/tmp/s29/split/*.json')):
    n=os.path.basename(f)[:-5]
    r=json.load(open(f))
    a=json.load(open(glob.glob('/tmp/s29/b/cases/*/'+n+'/answer.json')[0]))
    g=r.get('unexplained_as_given')
    if not g or g['fingerprint']['kind'] not in ('state','drift'): 
        rows.append((n,a['fingerprint']['kind'],g['fingerprint']['kind'] if g else '-',None,None,None,'')); continue
    fp=g['fingerprint']; fn=','.join(x['name'] for x in fp['functions'])
    m=None
    for line in open(f[:-5]+'.err'):
        if line.startswith('SPLIT '+fp['balance']+' ') and line.rstrip().endswith('| '+fn):
            m=line; break
    if m:
        mid=float(re.search(r'mid: gain \S+ price \S+ net (\S+)',m).group(1)); st=float(re.search(r'steps\(\d+\): gain \S+ price \S+ net (\S+)',m).group(1))
    else: mid=st=None
    rows.append((n,a['fingerprint']['kind'],fp['kind'],fp['score'],mid,st,fp['balance']+':'+fn))
for r in rows:
    if r[3] is None: continue
    print(f"{r[0]:32s} truth={r[1]:11s} given={r[2]:6s} score={r[3]:7.1f} mid={r[4] if r[4] is None else round(r[4],1)!s:>7s} steps={r[5] if r[5] is None else round(r[5],1)!s:>7s}  {r[6][:70]}")

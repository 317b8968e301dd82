import json,glob,sys
skip={'runtime_s','ranking_s','selection_s','outputs'}
def strip(d):
    if isinstance(d,dict):
        out={}
        for k,v in d.items():
            if k in skip or k=='convergence': 
                if k=='convergence': out[k]={s:{kk:vv for kk,vv in c.items() if 'wall' not in kk and 'second' not in kk} for s,c in v.items()}
                continue
            out[k]=strip(v)
        return out
    if isinstance(d,list): return [strip(x) for x in d]
    return d
for i in range(1,15):
    o=f'/tmp/ab/old-case{i:02d}-r1.json'; n=f'/tmp/ab/new-case{i:02d}-r1.json'
    try: a=json.load(open(o)); b=json.load(open(n))
    except Exception as e: print(i,'missing'); continue
    sa,sb=strip(a),strip(b)
    same = sa==sb
    print(f'case{i:02d}', a['selected'], b['selected'], 'identical' if same else 'DIFFERENT')
    if not same:
        for k in sa:
            if sa.get(k)!=sb.get(k): print('   key',k, str(sa.get(k))[:150], '|', str(sb.get(k))[:150])

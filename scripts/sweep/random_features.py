# Random feature sets: 3 connected chains of 5-20 mesh edges each (random walks, no repeated vertex).
# Usage: python3 scripts/sweep/random_features.py MESH.obj OUT.json SEED
# (a features file for `conemap quads --features`)
import sys, json, random
from collections import defaultdict
path, out, seed = sys.argv[1], sys.argv[2], int(sys.argv[3])
V, F = [], []
for line in open(path):
    p = line.split()
    if not p: continue
    if p[0] == 'v': V.append(tuple(float(x) for x in p[1:4]))
    elif p[0] == 'f': F.append([int(x.split('/')[0]) - 1 for x in p[1:]])
adj = defaultdict(set)
for f in F:
    for i in range(len(f)):
        a, b = f[i], f[(i + 1) % len(f)]
        adj[a].add(b); adj[b].add(a)
rng = random.Random(seed)
edges, used = [], set()
for c in range(3):
    for attempt in range(100):
        L = rng.randint(5, 20)
        v = rng.randrange(len(V))
        if v in used: continue
        chain = [v]; seen = {v}
        while len(chain) - 1 < L:
            nb = [w for w in adj[chain[-1]] if w not in seen and w not in used]
            if not nb: break
            w = rng.choice(nb); chain.append(w); seen.add(w)
        if len(chain) - 1 >= 5: break
    used |= set(chain)
    edges += [[list(V[a]), list(V[b])] for a, b in zip(chain, chain[1:])]
    print(f"chain {c}: {len(chain)-1} edges", file=sys.stderr)
json.dump({"edges": edges}, open(out, 'w'))

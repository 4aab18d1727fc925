#!/usr/bin/python3
"""Compares every dataset (but /config) of every policy file in BASE_DIR with the same file in
NEW_DIR, bit for bit (scripts/policy_cases writes them). Usage: compare_policies.py BASE_DIR NEW_DIR.
Exit status 1 when any file or dataset is missing or differs."""
import sys, os, h5py, numpy as np
base, new = sys.argv[1], sys.argv[2]
bad = 0; n = 0
for f in sorted(os.listdir(base)):
    if not f.endswith('.h5'): continue
    p = os.path.join(new, f)
    if not os.path.exists(p): print('MISSING', f); bad += 1; continue
    with h5py.File(os.path.join(base, f)) as a, h5py.File(p) as b:
        names = []
        a.visititems(lambda k, v: names.append(k) if isinstance(v, h5py.Dataset) else None)
        for k in names:
            if k == 'config': continue
            n += 1
            if k not in b: print('MISSING dataset', f, k); bad += 1; continue
            x, y = a[k][()], b[k][()]
            if x.shape != y.shape or not np.array_equal(np.asarray(x).view(np.uint8), np.asarray(y).astype(x.dtype).view(np.uint8)):
                print('DIFF', f, k); bad += 1
print(f'{n} datasets compared, {bad} differ')
sys.exit(1 if bad else 0)

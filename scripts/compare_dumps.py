#!/usr/bin/python3
"""Compare the answers of two builds: two files written by
`idcol_prof dump FILE` (every pose of every pair of the paper sweep, cold and
warm). Prints, per pair and mode, how many statuses differ and the largest
relative difference of alpha* and of x (|dx| / |x|), and exits 1 if any
status differs or either difference is above the tolerance.

    scripts/compare_dumps.py before.bin after.bin [--tol 1e-12]
"""
import argparse
import sys

import numpy as np

PAIRS = []
NAMES = ["Poly", "TC", "SE", "SEC", "Ellip"]
for i in range(len(NAMES)):
    for j in range(i, len(NAMES)):
        PAIRS.append(NAMES[i] + "-" + NAMES[j])
POSES = 20000


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--tol", type=float, default=1e-12)
    a = ap.parse_args()
    A = np.fromfile(a.before).reshape(len(PAIRS), 2, POSES, 6)
    B = np.fromfile(a.after).reshape(len(PAIRS), 2, POSES, 6)
    bad = False
    print(f"{'pair':12} {'mode':5} {'status':>7} {'iters':>9} {'max rel alpha':>14} {'max rel x':>10}")
    for p, name in enumerate(PAIRS):
        for m, mode in enumerate(["cold", "warm"]):
            a_, b_ = A[p, m], B[p, m]
            st = int(np.sum(a_[:, 0] != b_[:, 0]))
            ok = (a_[:, 0] == 0) & (b_[:, 0] == 0)
            its = b_[:, 1].sum() - a_[:, 1].sum()
            da = np.abs(b_[ok, 2] - a_[ok, 2]) / np.abs(a_[ok, 2])
            xn = np.linalg.norm(a_[ok, 3:6], axis=1)
            dx = np.linalg.norm(b_[ok, 3:6] - a_[ok, 3:6], axis=1) / np.maximum(xn, 1e-300)
            ma = da.max() if da.size else 0.0
            mx = dx.max() if dx.size else 0.0
            bad |= st > 0 or ma > a.tol or mx > a.tol
            print(f"{name:12} {mode:5} {st:7d} {int(its):+9d} {ma:14.3e} {mx:10.3e}")
    print("FAIL" if bad else f"same to {a.tol:g}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""A point robot among 100 bodies, moved by gradient steps through the batch.

The robot is a small sphere (radius ROBOT_R) whose centre q moves in 3-D
from START to GOAL through 100 obstacles of the five shape families, placed
at seeded random world poses X_Wi = (R_Wi, p_Wi). Each step makes ONE call
to idcol.solve_batch over all 100 (obstacle, robot) pairs, with the
obstacle as body 1 and the robot as body 2 at

    X_12 = X_Wi^-1 X_W2:  R_12 = R_Wi^T,  p_12 = R_Wi^T (q - p_Wi)

and reads back, per row, the gap and d gap/d xi (xi = (w, v), the body twist
of X_12). The robot does not rotate (R_W2 = I), so a world translation dq of
the robot moves X_12 by the body twist v = R_W2^T dq = dq: d gap/dq is the
v-part dgap_dxi[:, 3:] itself.

The cost is the potential
    U(q) = 1/2 |q - GOAL|^2 + K/2 sum_i max(0, CLEARANCE - gap_i(q))^2
and each step moves q by -STEP * grad U, the step clipped to MAX_STEP so
that the robot never jumps through a thin obstacle. The run stops at the
goal (|q - GOAL| < TOL) or after `steps` steps.

The path is checked independently of the batch: at every step's position a
cold idcol.solve per obstacle must converge with alpha* > 1 (separated).

usage: scripts/examples/point_robot_gradient.py [--steps 400] [--seed 0]
Prints a summary; exit status 1 if the robot collides or misses the goal.
"""
import argparse
import sys
import time

import numpy as np
import scipy.spatial.transform

import idcol

START = np.array([-6.0, 0.0, 0.0])
GOAL = np.array([6.0, 0.0, 0.0])
ROBOT_R = 0.1        # m
CLEARANCE = 0.3      # m: the repulsion acts below this gap
K = 40.0             # repulsion weight (1/m^2 of U per m^2 of intrusion)
STEP = 0.05          # gradient step (m per unit of |grad U|)
MAX_STEP = 0.05      # m per step at most
TOL = 0.05           # m: at the goal


def obstacles(seed=0, n=100):
    """n seeded obstacles of mixed families at random world poses in the box
    [-4.5, 4.5] x [-2, 2] x [-2, 2], none within 1 m of START or GOAL."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        kind = len(out) % 5
        s = rng.uniform(0.25, 0.5)
        if kind == 0:
            body = idcol.Sphere(R=s)
        elif kind == 1:
            body = idcol.Superellipsoid(a=s, b=0.7 * s, c=0.5 * s, n=rng.choice([1.0, 2.0, 4.0]))
        elif kind == 2:
            body = idcol.SuperellipticCylinder(R=0.5 * s, h=s, n=4.0)
        elif kind == 3:
            V = rng.normal(size=(10, 3))
            V = s * V / np.linalg.norm(V, axis=1)[:, None]
            body = idcol.SmoothPolytope.from_vertices(V - V.mean(axis=0), beta=20.0, L=s)
        else:
            body = idcol.SmoothTruncatedCone(Rb=0.6 * s, Rt=0.3 * s, a=0.5 * s, b=0.5 * s, beta=20.0)
        p = rng.uniform([-4.5, -2.0, -2.0], [4.5, 2.0, 2.0])
        if min(np.linalg.norm(p - START), np.linalg.norm(p - GOAL)) < 1.0:
            continue
        R = scipy.spatial.transform.Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
        out.append((body, R, p))
    return out


def gaps_and_gradients(obs, robot, q, threads=0):
    """(gap (n,), d gap/dq (n, 3)) of the robot at q against every obstacle,
    one batched call; raises if a row did not converge."""
    R_W = np.array([o[1] for o in obs])
    p_W = np.array([o[2] for o in obs])
    R_12 = np.transpose(R_W, (0, 2, 1))
    p_12 = np.einsum("kji,kj->ki", R_W, q[None, :] - p_W)   # R_Wi^T (q - p_Wi)
    out = idcol.solve_batch([o[0] for o in obs], robot, R_12, p_12, derivatives=True, threads=threads)
    if not out.converged.all():
        bad = np.flatnonzero(~out.converged)
        raise RuntimeError("rows %s did not converge: %s" % (bad[:5], [idcol.SolveStatus(s) for s in out.status[bad[:5]]]))
    return out.gap, out.dgap_dxi[:, 3:]


def potential(gap, q):
    return 0.5 * np.sum((q - GOAL) ** 2) + 0.5 * K * np.sum(np.maximum(0.0, CLEARANCE - gap) ** 2)


def gradient(gap, dgap_dq, q):
    push = np.maximum(0.0, CLEARANCE - gap)
    return (q - GOAL) - K * (push[:, None] * dgap_dq).sum(axis=0)


def check(obs, robot, path):
    """Cold single solves (not the batch): alpha* > 1 for every obstacle at
    every position of the path."""
    worst = np.inf
    for q in path:
        for body, R_W, p_W in obs:
            res = idcol.solve(body, robot, R_W.T, R_W.T @ (q - p_W))
            if not res.converged:
                return {"ok": False, "min_alpha": np.nan}
            worst = min(worst, res.alpha)
    return {"ok": bool(worst > 1.0), "min_alpha": float(worst), "solves": len(path) * len(obs)}


def run(steps=400, seed=0, threads=0):
    obs = obstacles(seed)
    robot = idcol.Sphere(R=ROBOT_R)
    q = START.copy()
    path, costs, min_gap = [q.copy()], [], np.inf
    t0 = time.perf_counter()
    for _ in range(steps):
        gap, dgap_dq = gaps_and_gradients(obs, robot, q, threads)
        min_gap = min(min_gap, float(gap.min()))
        costs.append(potential(gap, q))
        if np.linalg.norm(q - GOAL) < TOL:
            break
        d = -STEP * gradient(gap, dgap_dq, q)
        n = np.linalg.norm(d)
        if n > MAX_STEP:
            d *= MAX_STEP / n
        q = q + d
        path.append(q.copy())
    elapsed = time.perf_counter() - t0
    path = np.array(path)
    return path, {
        "reached": bool(np.linalg.norm(path[-1] - GOAL) < TOL),
        "steps": len(path) - 1,
        "batches": len(costs),
        "min_gap": min_gap,
        "length": float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1))),
        "costs": costs,
        "seconds": elapsed,
        "obstacles": obs,
        "robot": robot,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=0)
    args = ap.parse_args()
    path, s = run(args.steps, args.seed, args.threads)
    c = check(s["obstacles"], s["robot"], path)
    print("%d steps, %d batches of %d rows in %.2f s; path length %.3f m (straight line %.1f m); "
          "min gap %.4f m; goal %s" % (s["steps"], s["batches"], len(s["obstacles"]), s["seconds"], s["length"],
                                      np.linalg.norm(GOAL - START), s["min_gap"],
                                      "reached" if s["reached"] else "NOT reached"))
    print("check (%d cold solves): min alpha* %.4f -> %s" % (c.get("solves", 0), c["min_alpha"],
                                                             "collision free" if c["ok"] else "COLLISION"))
    return 0 if c["ok"] and s["reached"] else 1


if __name__ == "__main__":
    sys.exit(main())

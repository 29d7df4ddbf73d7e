#!/usr/bin/python3
"""Gradient-based kinematic path planning with iDCOL collision constraints.

In the spirit of the paper's planning application: a body (an ellipsoid, the
"robot") moves in the plane z = 0 from a start to a goal through a field of
obstacles of five families (sphere, superellipsoid, superelliptic cylinder,
smooth polytope, smooth truncated cone). The decision variables are the
interior waypoints (x, y, yaw) of the path; the objective is the sum of
squared steps (a short, evenly spaced path that turns little); the
constraints are alpha*(pose i, obstacle j) >= 1 + margin for every waypoint
and segment midpoint and every obstacle,
with their gradients from idcol (d alpha*/d xi, one batched call per
evaluation over all waypoint-obstacle pairs, mixed shape families). SciPy's
SLSQP solves it.

Every body is mirror-symmetric about z = 0 and centred on it, so the contact
of the robot with each obstacle lies in that plane and the figure (a top
view of the cross-sections at z = 0) shows the true clearances.

The result is checked independently of the optimiser: at every final waypoint
and at 8 evenly spaced poses along every segment, a cold single solve
(idcol.solve, not the batch) must converge with alpha* > 1 against every
obstacle, and points sampled on the robot's surface must lie outside every
obstacle (phi > 0, shape evaluation only).

usage: scripts/examples/plan_path.py [-o results/plan_path.png] [--waypoints 40]
Writes the figure and prints a summary; exit status 1 if the check fails.
"""
import argparse
import math
import os
import sys
import time

import numpy as np
import scipy.optimize

import idcol

MARGIN = 0.08          # constraints alpha* >= 1 + MARGIN
START = np.array([-5.0, -0.4, 0.0])   # x, y (m), yaw (rad)
GOAL = np.array([5.0, 0.6, 0.0])


def rot_z(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def robot():
    return idcol.Superellipsoid(a=0.45, b=0.22, c=0.22, n=1)


def obstacles():
    """(name, shape, R_W, p_W): each symmetric about the plane z = 0."""
    hexagon = [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)]
    prism = np.array([[0.75 * c, 0.75 * s, z] for c, s in hexagon for z in (-0.6, 0.6)])
    # The cylinder's axis y1 is turned to the vertical (z), so its cross-section is a disc.
    vertical = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]).T
    return [
        ("sphere", idcol.Sphere(R=0.8), np.eye(3), np.array([-3.2, 0.3, 0.0])),
        ("superellipsoid (n = 4)", idcol.Superellipsoid(a=0.7, b=1.1, c=0.6, n=4), rot_z(0.5), np.array([-0.5, -1.2, 0.0])),
        ("superelliptic cylinder (n = 6)", idcol.SuperellipticCylinder(R=0.65, h=1.0, n=6), vertical, np.array([-1.0, 1.9, 0.0])),
        ("smooth polytope (prism, beta = 20)", idcol.SmoothPolytope.from_vertices(prism, beta=20), rot_z(0.2), np.array([1.5, 0.6, 0.0])),
        ("smooth truncated cone (beta = 20)", idcol.SmoothTruncatedCone(Rb=0.7, Rt=0.3, a=0.8, b=0.8, beta=20), rot_z(-1.1), np.array([3.7, -0.4, 0.0])),
        ("sphere", idcol.Sphere(R=0.5), np.eye(3), np.array([3.6, 2.1, 0.0])),
    ]


class Problem:
    """Constraints alpha*_ij >= 1 + MARGIN and their gradients, one batch per
    evaluation, at every interior waypoint and at the midpoint of every
    segment (the pose halfway between two waypoints, so the path does not cut
    corners between them). Obstacle j is body 1 (fixed at X_W1), the robot
    body 2 at X_W2 = (R_z(yaw), (x, y, 0)); X_12 = X_W1^-1 X_W2. A body twist
    xi2 of X_W2 moves X_12 by the same twist (idcol.relative_twist_jacobians:
    dxi/dxi2 = I), so with R2 = R_z(yaw): d/dyaw = d/dw_z and
    d/d(x, y) = (d/dv @ R2^T) restricted to x, y."""

    def __init__(self, n_waypoints, midpoints=True, threads=0):
        self.robot = robot()
        self.obs = obstacles()
        self.m = n_waypoints
        self.midpoints = midpoints
        self.threads = threads
        # Rows: interior waypoints 1..m-2, then segment midpoints 0..m-2.
        self.n_poses = (n_waypoints - 2) + (n_waypoints - 1 if midpoints else 0)
        self.pairs = [(o[1], self.robot) for _ in range(self.n_poses) for o in self.obs]
        self.cache_x = None
        self.evaluations = 0

    def poses(self, path):
        """Relative poses X_12 for every (pose of `path`, obstacle)."""
        R, p = [], []
        for x, y, yaw in path:
            R2, p2 = rot_z(yaw), np.array([x, y, 0.0])
            for _, _, R1, p1 in self.obs:
                R.append(R1.T @ R2)
                p.append(R1.T @ (p2 - p1))
        return np.array(R), np.array(p)

    def constrained_poses(self, z):
        P = full_path(z)
        return np.vstack([P[1:-1], 0.5 * (P[:-1] + P[1:])]) if self.midpoints else P[1:-1]

    def evaluate(self, z):
        if self.cache_x is not None and np.array_equal(z, self.cache_x):
            return
        poses = self.constrained_poses(z)
        R, p = self.poses(poses)
        out = idcol.solve_batch(self.pairs, R, p, derivatives=True, threads=self.threads, kinematics=False)
        self.evaluations += 1
        if not out.converged.all():
            bad = np.flatnonzero(~out.converged)
            raise RuntimeError("solve failed at rows %s: %s" % (bad[:5], [idcol.SolveStatus(s) for s in out.status[bad[:5]]]))
        nobs, m = len(self.obs), self.m
        J = np.zeros((len(out.alpha), z.size))
        for i, (x, y, yaw) in enumerate(poses):
            rows = slice(i * nobs, (i + 1) * nobs)
            d = out.dalpha_dxi[rows]
            g = np.empty((nobs, 3))
            g[:, :2] = (d[:, 3:] @ rot_z(yaw).T)[:, :2]
            g[:, 2] = d[:, 2]
            if i < m - 2:          # interior waypoint i + 1: variables 3i..3i+2
                J[rows, 3 * i:3 * i + 3] = g
            else:                  # midpoint of segment s = (s, s+1): half to each interior end
                seg = i - (m - 2)
                for w in (seg, seg + 1):
                    if 1 <= w <= m - 2:
                        J[rows, 3 * (w - 1):3 * (w - 1) + 3] += 0.5 * g
        self.cache_x = z.copy()
        self.alpha, self.jac = out.alpha.copy(), J

    def constraint(self, z):
        self.evaluate(z)
        return self.alpha - (1.0 + MARGIN)

    def constraint_jac(self, z):
        self.evaluate(z)
        return self.jac


def full_path(z):
    return np.vstack([START, z.reshape(-1, 3), GOAL])


def objective(z):
    P = full_path(z)
    d = np.diff(P, axis=0)
    return float(np.sum(d[:, :2] ** 2) + 0.3 * np.sum(d[:, 2] ** 2))


def objective_grad(z):
    P = full_path(z)
    d = np.diff(P, axis=0) * np.array([1.0, 1.0, 0.3])
    g = 2 * (d[:-1] - d[1:])
    return g.ravel()


def initial_path(m):
    """The straight line (through the obstacles), bent slightly so the
    optimiser is not started on a symmetry."""
    s = np.linspace(0.0, 1.0, m)[1:-1, None]
    P = START + s * (GOAL - START)
    P[:, 1] += 0.3 * np.sin(math.pi * s[:, 0])
    return P


def check(path, samples=400):
    """Independent check of a path: cold single solves and surface samples."""
    body = robot()
    rng = np.random.default_rng(0)
    d = rng.normal(size=(samples, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    # Points on the ellipsoid: each unit direction scaled to phi = 0.
    surface = d / np.sqrt(np.sum((d / np.array([0.45, 0.22, 0.22])) ** 2, axis=1))[:, None]
    min_alpha, min_phi, solves = np.inf, np.inf, 0
    for x, y, yaw in path:
        R2, p2 = rot_z(yaw), np.array([x, y, 0.0])
        pts_W = surface @ R2.T + p2
        for _, shape, R1, p1 in obstacles():
            res = idcol.solve(shape, body, R1.T @ R2, R1.T @ (p2 - p1))
            solves += 1
            if not res.converged:
                return {"ok": False, "reason": "solve %s" % res.status, "solves": solves}
            min_alpha = min(min_alpha, res.alpha)
            pts_1 = (pts_W - p1) @ R1
            min_phi = min(min_phi, min(shape.eval(q)[0] for q in pts_1))
    return {"ok": bool(min_alpha > 1.0 and min_phi > 0.0), "min_alpha": min_alpha, "min_phi": min_phi,
            "solves": solves}


def densify(path, per_segment=8):
    t = np.linspace(0, 1, per_segment, endpoint=False)[:, None]
    return np.vstack([a + t * (b - a) for a, b in zip(path[:-1], path[1:])] + [path[-1:]])


def plot(out_png, path0, path, prob, summary):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fig = plt.figure(figsize=(11.5, 7.2))
    ax = fig.add_axes([0.07, 0.36, 0.62, 0.58])
    ax2 = fig.add_axes([0.07, 0.08, 0.62, 0.19])
    colours = ["#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#4c72b0"]
    xs, ys = np.linspace(-6.0, 6.0, 361), np.linspace(-3.0, 3.0, 181)
    X, Y = np.meshgrid(xs, ys)
    legend = []
    seen = set()
    for (name, shape, R1, p1), col in zip(prob.obs, colours):
        pts = (np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1) - p1) @ R1
        phi = np.array([shape.eval(q)[0] for q in pts]).reshape(X.shape)
        ax.contourf(X, Y, phi, levels=[-1e9, 0.0], colors=[col], alpha=0.55)
        ax.contour(X, Y, phi, levels=[0.0], colors=[col], linewidths=1.2)
        if name not in seen:
            legend.append(Patch(facecolor=col, alpha=0.55, edgecolor=col, label=name))
            seen.add(name)
    ax.plot(path0[:, 0], path0[:, 1], "--", color="0.45", lw=1.2)
    ax.plot(path[:, 0], path[:, 1], "-o", color="k", ms=2.5, lw=1.3)
    t = np.linspace(0, 2 * math.pi, 60)
    for x, y, yaw in path[::3]:
        e = np.stack([0.45 * np.cos(t), 0.22 * np.sin(t)], axis=1) @ rot_z(yaw)[:2, :2].T
        ax.plot(x + e[:, 0], y + e[:, 1], color="#937860", lw=0.9)
    ax.plot(*START[:2], "s", color="tab:green", ms=8)
    ax.plot(*GOAL[:2], "*", color="tab:red", ms=12)
    ax.set_aspect("equal")
    ax.set_xlim(-6, 6)
    ax.set_ylim(-3, 3)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Top view at z = 0: path optimised with SLSQP under alpha* >= %.2f constraints" % (1 + MARGIN))
    legend += [Line2D([], [], ls="--", color="0.45", label="initial guess (bent straight line)"),
               Line2D([], [], ls="-", marker="o", ms=2.5, color="k", label="optimised path (waypoints)"),
               Line2D([], [], color="#937860", label="robot ellipsoid (every 3rd waypoint)"),
               Line2D([], [], ls="", marker="s", color="tab:green", label="start"),
               Line2D([], [], ls="", marker="*", ms=10, color="tab:red", label="goal")]
    fig.legend(handles=legend, loc="upper left", bbox_to_anchor=(0.71, 0.94), frameon=False, fontsize=9,
               title="obstacles and paths", title_fontsize=9, alignment="left")

    a0 = min_alpha_per_waypoint(prob, path0)
    a1 = min_alpha_per_waypoint(prob, path)
    k = np.arange(1, len(a0) + 1)
    ax2.plot(k, a0, "--", color="0.45", label="initial guess")
    ax2.plot(k, a1, "-o", color="k", ms=2.5, label="optimised path")
    ax2.set_ylim(0.0, max(a0.max(), a1.max()) * 1.1)
    ax2.set_xlim(0, len(k) + 1)
    ax2.axhline(1.0, color="tab:red", lw=1.0, label="alpha* = 1 (contact)")
    ax2.axhline(1.0 + MARGIN, color="tab:red", lw=0.8, ls=":", label="constraint 1 + margin")
    ax2.set_xlabel("interior waypoint index")
    ax2.set_ylabel("smallest alpha* (-)")
    ax2.set_title("Smallest alpha* over the obstacles at each waypoint", fontsize=10)
    ax2.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False, fontsize=9)
    fig.text(0.71, 0.56, "\n".join([
        "SLSQP: %d iterations, %.1f s" % (summary["nit"], summary["seconds"]),
        "%d constraint evaluations, each one" % summary["evaluations"],
        "idcol.solve_batch of %d mixed pairs" % len(prob.pairs),
        "with d alpha*/d xi, at the waypoints",
        "and the segment midpoints.",
        "Independent check (cold single solves):",
        "  min alpha* at waypoints %.4f" % summary["check"]["min_alpha"],
        "  min alpha* at 8 poses/segment %.4f" % summary["between"]["min_alpha"],
    ]), fontsize=9, va="top")
    os.makedirs(os.path.dirname(os.path.abspath(out_png)), exist_ok=True)
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def min_alpha_per_waypoint(prob, path):
    R, p = prob.poses(path[1:-1])
    out = idcol.solve_batch([(o[1], prob.robot) for _ in path[1:-1] for o in prob.obs], R, p)
    return out.alpha.reshape(len(path) - 2, len(prob.obs)).min(axis=1)


def run(out_png, waypoints=40, threads=0):
    t0 = time.perf_counter()
    prob = Problem(waypoints, midpoints=True, threads=threads)
    z0 = initial_path(waypoints).ravel()
    res = scipy.optimize.minimize(
        objective, z0, jac=objective_grad, method="SLSQP",
        constraints=[{"type": "ineq", "fun": prob.constraint, "jac": prob.constraint_jac}],
        options={"maxiter": 300, "ftol": 1e-9})
    seconds = time.perf_counter() - t0
    path, path0 = full_path(res.x), full_path(z0)
    summary = {"success": bool(res.success), "message": res.message, "nit": int(res.nit),
               "evaluations": prob.evaluations, "seconds": seconds,
               "min_constraint": float(prob.constraint(res.x).min()),
               "check": check(path), "between": check(densify(path), samples=100),
               "length": float(np.sum(np.linalg.norm(np.diff(path[:, :2], axis=0), axis=1)))}
    if out_png:
        plot(out_png, path0, path, prob, summary)
    return path, summary


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--out", default=os.path.join(os.path.dirname(__file__), "..", "..", "results", "plan_path.png"))
    ap.add_argument("--waypoints", type=int, default=40)
    ap.add_argument("--threads", type=int, default=0)
    args = ap.parse_args(argv)
    path, s = run(args.out, args.waypoints, args.threads)
    print("SLSQP: %s (%d iterations, %d batched constraint evaluations, %.2f s)" % (
        s["message"], s["nit"], s["evaluations"], s["seconds"]))
    print("path length %.3f m; min alpha* - (1 + margin) over constraints %.2e" % (s["length"], s["min_constraint"]))
    c, b = s["check"], s["between"]
    print("check at %d waypoints (%d cold single solves): min alpha* %.4f, min phi of robot surface samples %.4f -> %s" % (
        len(path), c["solves"], c["min_alpha"], c["min_phi"], "collision free" if c["ok"] else "FAILED"))
    print("check at 8 poses per segment (%d cold single solves): min alpha* %.4f, min phi %.4f -> %s" % (
        b["solves"], b["min_alpha"], b["min_phi"], "collision free" if b["ok"] else "FAILED"))
    print("figure: %s" % os.path.normpath(args.out))
    return 0 if (s["success"] and c["ok"] and b["ok"]) else 1


if __name__ == "__main__":
    sys.exit(main())

"""Typed use of the public API, checked by mypy --strict against the stubs
(test_stubs.py): every call here must type-check without ignores."""
from typing import Dict, List, Optional

import numpy as np
from numpy.typing import NDArray

import idcol


def plan_step(robot: idcol.Shape, obstacles: List[idcol.Shape], q: NDArray[np.float64]) -> NDArray[np.float64]:
    """One gradient step of a point robot away from every obstacle."""
    n = len(obstacles)
    R = np.repeat(np.eye(3)[None], n, axis=0)
    p = np.repeat(q[None], n, axis=0)
    out: idcol.BatchResult = idcol.solve_batch(obstacles, robot, R, p, derivatives=True, threads=1)
    grad: Optional[NDArray[np.float64]] = out.dgap_dxi
    assert grad is not None and out.gap is not None
    step: NDArray[np.float64] = grad[:, 3:].sum(axis=0)
    return q + 0.01 * step


def one_query() -> float:
    a = idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8)
    b = idcol.SmoothPolytope.from_vertices(np.vstack([np.eye(3), -np.ones((1, 3))]), beta=20.0)
    opt = idcol.SolverOptions(tolerance=1e-11)
    opt.max_iterations = 80
    ws = idcol.WarmStart()
    res: idcol.SolveResult = idcol.solve(a, b, np.eye(3), [3.0, 0.5, 0.0], options=opt, derivatives=True,
                                         warm_start=ws)
    if res.status == idcol.SolveStatus.Converged:
        k = idcol.contact_kinematics(res, derivatives=True)
        d1, d2 = idcol.relative_twist_jacobians(np.eye(3), [3.0, 0.5, 0.0])
        g: NDArray[np.float64] = idcol.alpha_gradient(res) @ d1
        return float(k.gap + g.sum())
    pair = idcol.ContactPair(a, b, opt)
    return pair.solve(np.eye(3), [3.0, 0.5, 0.0]).alpha


def sweep(a: idcol.Shape, b: idcol.Shape, p0: NDArray[np.float64], p1: NDArray[np.float64]) -> Dict[int, str]:
    """Time of impact of many motions; the rows it refused and why."""
    R = np.repeat(np.eye(3)[None], len(p0), axis=0)
    out: idcol.ToiBatchResult = idcol.time_of_impact_batch(a, b, R, p0, R, p1, threads=0)
    hit: NDArray[np.bool_] = out.status == int(idcol.ToiStatus.Impact)
    assert len(out) == len(hit)
    return out.errors

"""idcol.time_of_impact and its batch: the two-sphere quadratic, tunnelling
through a thin plate, dt*/d(X0, X1) against finite differences through the
SE(3) exponential (scipy's matrix exponential, not the library's), the batch
against the loop of single queries, and bad input."""
import re

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

import idcol

I3 = np.eye(3)


def quadratic_toi(p0, p1, R):
    d = p1 - p0
    a, b, c = d @ d, 2 * p0 @ d, p0 @ p0 - R * R
    disc = b * b - 4 * a * c
    if disc < 0:
        return None
    t = (-b - np.sqrt(disc)) / (2 * a)
    return t if 0 <= t <= 1 else None


def hat(xi):
    w, v = xi[:3], xi[3:]
    M = np.zeros((4, 4))
    M[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    M[:3, 3] = v
    return M


def compose(R, p, xi):
    """(R, p) exp(xi^), xi = (w, v)."""
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    T = T @ expm(hat(xi))
    return T[:3, :3], T[:3, 3]


def test_two_spheres_in_translation_match_the_quadratic():
    a, b = idcol.Sphere(0.3), idcol.Sphere(0.2)
    p0, p1 = np.array([-2.0, 0.1, 0.05]), np.array([2.0, -0.1, 0.2])
    r = idcol.time_of_impact(a, b, I3, p0, I3, p1)
    assert r.status == idcol.ToiStatus.Impact
    assert r.t == pytest.approx(quadratic_toi(p0, p1, 0.5), abs=1e-9)
    assert r.contact.alpha == pytest.approx(1.0, abs=1e-8)
    np.testing.assert_allclose(r.p, p0 + r.t * (p1 - p0), atol=1e-15)
    assert r.t_free <= r.t and r.solves >= 1


def test_tunnelling_through_a_thin_plate_is_caught():
    plate = idcol.SmoothPolytope(
        [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], [1, 1, 1, 1, 0.005, 0.005], 2000.0)
    ball = idcol.Sphere(0.02)
    r = idcol.time_of_impact(plate, ball, I3, [0.1, -0.2, -1.0], I3, [0.12, -0.18, 1.0])
    assert r.status == idcol.ToiStatus.Impact
    assert (1 - 0.005 - 0.02) / 2 - 1e-10 <= r.t <= (1 - 0.0041 - 0.02) / 2


def test_statuses():
    a, b = idcol.Sphere(0.3), idcol.Sphere(0.2)
    assert idcol.time_of_impact(a, b, I3, [0.3, 0, 0], I3, [2, 0, 0]).status == idcol.ToiStatus.InitiallyInContact
    r = idcol.time_of_impact(a, b, I3, [1, 0, 0], I3, [3, 0, 0])
    assert r.status == idcol.ToiStatus.NoImpact and r.t_free == 1.0


def test_derivatives_match_finite_differences():
    a, b = idcol.Sphere(0.25), idcol.Superellipsoid(0.8, 0.3, 0.2, 1.0)
    R0 = Rotation.from_rotvec([0.3, 0.2, 0.1]).as_matrix()
    R1 = Rotation.from_rotvec([0.9, -0.4, 0.5]).as_matrix()
    p0, p1 = np.array([-1.5, 0.2, 0.1]), np.array([1.0, -0.1, 0.3])
    opt = idcol.ToiOptions(alpha_tolerance=1e-12, t_tolerance=1e-13, solver=idcol.SolverOptions(tolerance=1e-13))
    r = idcol.time_of_impact(a, b, R0, p0, R1, p1, options=opt)
    assert r.status == idcol.ToiStatus.Impact and r.has_derivatives
    h = 1e-5
    for end in range(2):
        fd = np.zeros(6)
        for i in range(6):
            e = np.zeros(6)
            e[i] = h
            ts = []
            for sgn in (1, -1):
                if end == 0:
                    Rp, pp = compose(R0, p0, sgn * e)
                    q = idcol.time_of_impact(a, b, Rp, pp, R1, p1, options=opt)
                else:
                    Rp, pp = compose(R1, p1, sgn * e)
                    q = idcol.time_of_impact(a, b, R0, p0, Rp, pp, options=opt)
                assert q.status == idcol.ToiStatus.Impact
                ts.append(q.t)
            fd[i] = (ts[0] - ts[1]) / (2 * h)
        ift = r.dt_dX0 if end == 0 else r.dt_dX1
        np.testing.assert_allclose(ift, fd, atol=1e-5 * max(1, np.abs(fd).max()))


def test_batch_matches_the_loop_for_any_thread_count():
    a, b = idcol.Sphere(0.3), idcol.Superellipsoid(0.4, 0.2, 0.1, 2.0)
    n = 60
    rng = np.random.default_rng(9)
    R0 = Rotation.random(n, random_state=3).as_matrix()
    R1 = Rotation.random(n, random_state=4).as_matrix()
    R1[: n // 2] = R0[: n // 2]  # half pure translations
    p0 = rng.uniform(-2, 2, (n, 3))
    p0 *= (1.2 + np.abs(rng.uniform(0, 1, (n, 1)))) / np.linalg.norm(p0, axis=1, keepdims=True)
    p1 = rng.uniform(-2, 2, (n, 3))
    out1 = idcol.time_of_impact_batch(a, b, R0, p0, R1, p1)
    out2 = idcol.time_of_impact_batch(a, b, R0, p0, R1, p1, threads=2)
    for out in (out1, out2):
        for k in range(n):
            r = idcol.time_of_impact(a, b, R0[k], p0[k], R1[k], p1[k])
            assert out.status[k] == int(r.status)
            assert out.t[k] == r.t
            assert out.solves[k] == r.solves
    hits = int(np.sum(out1.status == int(idcol.ToiStatus.Impact)))
    misses = int(np.sum(out1.status == int(idcol.ToiStatus.NoImpact)))
    assert hits > 5 and misses > 5
    assert out1.dt_dX0.shape == (n, 6)


def test_bad_input():
    a, b = idcol.Sphere(0.3), idcol.Sphere(0.2)
    with pytest.raises(ValueError, match=r"^p0\[1\] = nan is not finite$"):
        idcol.time_of_impact(a, b, I3, [1, np.nan, 0], I3, [2, 0, 0])
    with pytest.raises(ValueError, match="leaves the double range"):
        idcol.time_of_impact(a, b, I3, [-1e308, 0, 0], I3, [1.7e308, 0, 0])
    with pytest.raises(ValueError, match=r"R1 must have shape \(3, 3\)"):
        idcol.time_of_impact(a, b, I3, [1, 0, 0], np.eye(2), [2, 0, 0])
    with pytest.raises(ValueError, match="t_tolerance"):
        idcol.ToiOptions(t_tolerance=-1.0)
    with pytest.raises(TypeError):
        idcol.time_of_impact(a, "sphere", I3, [1, 0, 0], I3, [2, 0, 0])
    with pytest.raises(TypeError, match="R0 must hold real numbers"):
        idcol.time_of_impact(a, b, I3.astype(complex), [1, 0, 0], I3, [2, 0, 0])
    R = np.repeat(I3[None], 3, axis=0)
    p0 = np.array([[1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]])
    with pytest.raises(ValueError, match=r"R0, p0, R1, p1 must hold the same number of motions"):
        idcol.time_of_impact_batch(a, b, R, p0, R[:2], p0[:2])
    with pytest.raises(ValueError, match=r"p1 must have shape \(N, 3\), got \(3, 2\)"):
        idcol.time_of_impact_batch(a, b, R, p0, R, p0[:, :2])
    with pytest.raises(ValueError, match=r"threads must be >= 0"):
        idcol.time_of_impact_batch(a, b, R, p0, R, p0 + 1, threads=-1)


def test_batch_marks_a_bad_row_and_answers_the_others():
    """As solve_batch: one motion that time_of_impact would refuse (a NaN or
    Inf entry, a rotation that is not one, a displacement that overflows)
    is that row's InvalidInput, with NaN times, no solves and its message in
    errors; every other row is the single query's answer, for any thread
    count."""
    a, b = idcol.Sphere(0.3), idcol.Sphere(0.2)
    n = 8
    R0, R1 = np.repeat(I3[None], n, 0), np.repeat(I3[None], n, 0)
    p0 = np.array([[2.0, 0.05 * k, 0.0] for k in range(n)])
    p1 = p0 - [4.0, 0.0, 0.0]
    p0[1, 1] = np.nan
    R1[3] = np.diag([1.0, -1.0, 1.0])
    R0[4] = 2 * I3
    p0[6], p1[6] = [-1e308, 0, 0], [1.7e308, 0, 0]
    bad = {1: r"^p0\[1\]\[1\] = nan is not finite$",
           3: r"^R1\[3\] has determinant -1\.0: a reflection, not a rotation$",
           4: r"^R0\[4\] is not a rotation: \|\|R\^T R - I\|\|_F = 5\.2 > 1e-09",
           6: r"^time_of_impact: the displacement .* leaves the double range$"}
    for threads in (1, 3, 0):
        out = idcol.time_of_impact_batch(a, b, R0, p0, R1, p1, threads=threads)
        assert sorted(out.errors) == sorted(bad)
        for k in range(n):
            if k in bad:
                assert out.status[k] == idcol.ToiStatus.InvalidInput and out.solves[k] == 0
                assert np.isnan([out.t[k], out.t_free[k], out.alpha[k]]).all() and np.isnan(out.dt_dX0[k]).all()
                assert not out.has_derivatives[k]
                assert re.match(bad[k], out.errors[k]), out.errors[k]
                continue
            r = idcol.time_of_impact(a, b, R0[k], p0[k], R1[k], p1[k])
            assert out.status[k] == r.status == idcol.ToiStatus.Impact
            assert out.t[k] == r.t and out.solves[k] == r.solves and out.alpha[k] == r.contact.alpha
            assert np.array_equal(out.dt_dX1[k], r.dt_dX1)
    assert repr(out) == "ToiBatchResult(N=8, impact=4, invalid_input=4)"
    out.errors.clear()  # a copy
    assert len(out.errors) == 4
    for name in ("status", "t", "t_free", "alpha", "solves", "has_derivatives", "dt_dX0", "dt_dX1"):
        assert not getattr(out, name).flags.writeable, name

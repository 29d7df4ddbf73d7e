"""Derivatives from NumPy against Richardson central differences through the
SE(3) exponential (scipy.linalg.expm, not idcol's), with the frames and the
twist ordering (w, v) of the docstrings."""
import numpy as np
import pytest

import idcol
from _helpers import paper_shapes, perturb, random_poses

TIGHT = idcol.SolverOptions(tolerance=1e-13, derivatives=True)
H = 1e-5      # rad, or units of the pair length L
TOL = 1e-5    # relative, as core/src/derivatives/tests/test_derivatives.cpp argues


def fd_jacobian(f, R, p, L):
    """d f / d xi, xi = (w, v) body twist, by Richardson-extrapolated central
    differences (v steps scaled by L). None if a perturbed solve fails."""
    cols = []
    for j in range(6):
        step = H * (L if j >= 3 else 1.0)

        def central(h):
            e = np.zeros(6)
            e[j] = h
            fp, fm = f(*perturb(R, p, e)), f(*perturb(R, p, -e))
            if fp is None or fm is None:
                return None
            return (fp - fm) / (2 * h)

        d1, d2 = central(step), central(step / 2)
        if d1 is None or d2 is None:
            return None
        cols.append((4 * d2 - d1) / 3)
    return np.stack(cols, axis=-1)


def close(ift, fd, L, scale_rows=None):
    """max |ift - fd| <= TOL max(1, max |fd|), on quantities made
    dimensionless by L (v columns times L, length rows divided by L)."""
    a, b = np.array(ift, float), np.array(fd, float)
    a[..., 3:] *= L
    b[..., 3:] *= L
    if scale_rows is not None:
        a, b = a / scale_rows, b / scale_rows
    return np.max(np.abs(a - b)) <= TOL * max(1.0, np.max(np.abs(b)))


def values(a, b):
    def f(R, p):
        res = idcol.solve(a, b, R, p, options=TIGHT)
        if not res.converged:
            return None
        kin = idcol.contact_kinematics(res)
        return np.concatenate([res.x, [res.alpha, res.lambda1, res.lambda2], kin.p1, kin.p2, kin.normal, [kin.gap]])
    return f


@pytest.mark.parametrize("n1, n2", [("SE", "Poly"), ("TC", "SEC"), ("Poly", "SE")])
def test_everything_against_finite_differences(n1, n2):
    shapes = paper_shapes()
    a, b = shapes[n1], shapes[n2]
    L = a.radii[1] + b.radii[1]
    rng = np.random.default_rng({"SE": 1, "TC": 2, "Poly": 3}[n1])
    R, p = random_poses(rng, 12, 0.3 * L, 2.0 * L)
    f = values(a, b)
    checked = 0
    for Rk, pk in zip(R, p):
        res = idcol.solve(a, b, Rk, pk, options=TIGHT)
        assert res.converged and res.has_derivatives
        fd = fd_jacobian(f, Rk, pk, L)
        assert fd is not None
        sens = idcol.solution_sensitivity(res)
        assert sens.valid and sens.dz_dxi.shape == (6, 6)
        kin = idcol.contact_kinematics(res, derivatives=True)
        Lrow = np.array([L, L, L, 1.0])
        # dz/dxi rows x (3), alpha.
        assert close(sens.dz_dxi[:4], fd[:4], L, Lrow[:, None])
        assert np.array_equal(sens.dx_dxi, sens.dz_dxi[:3]) and np.array_equal(sens.dalpha_dxi, sens.dz_dxi[3])
        # alpha_gradient, by its adjoint solve, is the same row.
        assert np.allclose(idcol.alpha_gradient(res), sens.dalpha_dxi, rtol=1e-9, atol=1e-12)
        assert close(idcol.alpha_gradient(res), fd[3], L)
        # Witness points, normal, gap (body-1 frame).
        assert close(kin.dp1_dxi, fd[6:9], L, L)
        assert close(kin.dp2_dxi, fd[9:12], L, L)
        assert close(kin.dnormal_dxi, fd[12:15], L)
        assert close(kin.dgap_dxi, fd[15], L, L)
        assert close(idcol.gap_gradient(res), fd[15], L, L)
        checked += 1
    assert checked == 12


def test_wrench_derivatives_when_penetrating():
    shapes = paper_shapes()
    a, b = shapes["SE"], shapes["TC"]
    L = a.radii[1] + b.radii[1]
    model = idcol.HertzModel(stiffness=3.0, exponent=1.5)

    def f(R, p):
        res = idcol.solve(a, b, R, p, options=TIGHT)
        if not res.converged:
            return None
        w = idcol.contact_wrench(res, model)
        return np.concatenate([[w.f_n], w.F1, w.F2])

    rng = np.random.default_rng(7)
    R, p = random_poses(rng, 40, 0.2 * L, 0.6 * L)
    checked = 0
    for Rk, pk in zip(R, p):
        res = idcol.solve(a, b, Rk, pk, options=TIGHT)
        w = idcol.contact_wrench(res, model, derivatives=True)
        if not w.active:
            continue
        assert w.representable and w.f_n > 0
        # Force on body 1 is -f_n along body 1's outward normal (moment, force).
        kin = idcol.contact_kinematics(res)
        assert kin.representable
        assert np.allclose(w.F1[3:], -w.f_n * kin.normal, rtol=1e-12)
        fd = fd_jacobian(f, Rk, pk, L)
        assert fd is not None
        got = np.vstack([w.df_n_dxi[None], w.dF1_dxi, w.dF2_dxi])
        assert close(got, fd, L)
        checked += 1
        if checked == 8:
            break
    assert checked == 8
    # Without derivatives the derivative fields are None.
    w = idcol.contact_wrench(res, model)
    assert w.dF1_dxi is None and not w.has_derivatives


def test_kinematics_beyond_the_double_range_say_so():
    # Spheres of 1e300 and the largest double, penetrating: the gap
    # |r| - (R1 + R2) is not a double, the witness points are.
    big = np.finfo(float).max
    res = idcol.solve(idcol.Sphere(1e300), idcol.Sphere(big), np.eye(3), np.array([-7.5e240, 0.0, 0.0]))
    assert res.converged
    kin = idcol.contact_kinematics(res)
    assert not kin.representable and np.isinf(kin.gap)
    assert np.all(np.isfinite(kin.p1)) and np.all(np.isfinite(kin.p2))
    assert kin.p2[0] == pytest.approx(big - 7.5e240, rel=1e-12)


def test_world_frame_gradient_through_relative_twist_jacobians():
    """Body 2 translated in the world: d alpha*/dq = dalpha/dxi2[3:] R_W2^T,
    checked by differences of world positions."""
    shapes = paper_shapes()
    a, b = shapes["SEC"], shapes["SE"]
    rng = np.random.default_rng(8)
    (R1, R2), (p1, p2) = random_poses(rng, 2, 1.0, 3.0)
    p2 = p1 + np.array([2.5, 0.5, -0.3])

    def alpha(q):
        R12, p12 = R1.T @ R2, R1.T @ (q - p1)
        return idcol.solve(a, b, R12, p12, options=TIGHT).alpha

    R12, p12 = R1.T @ R2, R1.T @ (p2 - p1)
    res = idcol.solve(a, b, R12, p12, options=TIGHT)
    _, dxi_dxi2 = idcol.relative_twist_jacobians(R12, p12)
    g = idcol.alpha_gradient(res) @ dxi_dxi2
    dq = g[3:] @ R2.T
    h = 1e-5
    fd = np.array([(alpha(p2 + h * e) - alpha(p2 - h * e)) / (2 * h) for e in np.eye(3)])
    assert np.allclose(dq, fd, rtol=1e-6, atol=1e-8)
    # idcol.se3_exp agrees with scipy's exponential.
    xi = np.array([0.3, -0.2, 0.5, 1.0, 2.0, -0.5])
    Re, pe = idcol.se3_exp(xi)
    Rs, ps = perturb(np.eye(3), np.zeros(3), xi)
    assert np.allclose(Re, Rs, atol=1e-13) and np.allclose(pe, ps, atol=1e-13)


def test_derivatives_need_the_option_and_a_converged_result():
    a = idcol.Sphere(R=1.0)
    res = idcol.solve(a, a, np.eye(3), [3.0, 0, 0])
    for f in (idcol.alpha_gradient, idcol.solution_sensitivity, idcol.gap_gradient):
        with pytest.raises(ValueError, match="derivatives"):
            f(res)
    with pytest.raises(ValueError, match="derivatives"):
        idcol.contact_kinematics(res, derivatives=True)
    # Values need no factorisation.
    kin = idcol.contact_kinematics(res)
    assert kin.gap == pytest.approx(1.0) and kin.dp1_dxi is None
    bad = idcol.solve(a, a, np.eye(3), [0, 0, 0], options=TIGHT)  # Concentric: no derivatives
    assert not bad.converged and not idcol.solution_sensitivity(bad).valid
    assert np.array_equal(idcol.alpha_gradient(bad), np.zeros(6))


def test_contact_wrench_rejects_a_wrong_model():
    a = idcol.Sphere(R=1.0)
    res = idcol.solve(a, a, np.eye(3), [1.5, 0, 0], options=TIGHT)
    with pytest.raises(TypeError, match="model must be an idcol.HertzModel"):
        idcol.contact_wrench(res, model=(1.0, 1.5))
    w = idcol.contact_wrench(res)   # default HertzModel(1, 1.5): delta = 0.5
    assert w.active and w.f_n == pytest.approx(0.5 ** 1.5, rel=1e-12)

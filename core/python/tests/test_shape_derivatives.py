"""Shape-parameter derivatives from Python against Richardson central
differences in the parameters: each perturbed shape is built here by its
family's own Python constructor (not by Shape.with_params) and re-solved.
Also the two closed forms (two spheres; two ellipsoids through the
Perram-Wertheim function differentiated in the axes, written in NumPy), the
chain to a polytope's vertices, and the errors."""
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import idcol
from _helpers import OCTA, OCTA_B, random_rotation

TIGHT = idcol.SolverOptions(tolerance=1e-13, derivatives=True)
PLAIN = idcol.SolverOptions(tolerance=1e-13)
H = 1e-5      # relative step: theta_j +- H max(|theta_j|, L^power_j)
TOL = 1e-5    # relative, on quantities made dimensionless by L
ALPHAS = (2.0, 1.3, 1.0, 0.95, 0.6)
MODEL = idcol.HertzModel(stiffness=3.0, exponent=1.5)


def catalogue():
    """One shape of every family (the paper's Table 1 shapes and a sphere)."""
    return {
        "Sph": idcol.Sphere(R=0.8),
        "Poly": idcol.SmoothPolytope(OCTA, OCTA_B, beta=20.0),
        "TC": idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20.0),
        "SE": idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8),
        "SEC": idcol.SuperellipticCylinder(R=1.0, h=2.0, n=8),
    }


def rebuild(like, theta):
    """The shape of like's family with parameters theta, by its constructor,
    in the documented order of Shape.params."""
    t = [float(v) for v in theta]
    if isinstance(like, idcol.Sphere):
        return idcol.Sphere(R=t[0])
    if isinstance(like, idcol.Superellipsoid):
        return idcol.Superellipsoid(a=t[0], b=t[1], c=t[2], n=t[3])
    if isinstance(like, idcol.SuperellipticCylinder):
        return idcol.SuperellipticCylinder(R=t[0], h=t[1], n=t[2])
    if isinstance(like, idcol.SmoothTruncatedCone):
        return idcol.SmoothTruncatedCone(Rb=t[0], Rt=t[1], a=t[2], b=t[3], beta=t[4])
    rows = np.array(t[:-1]).reshape(-1, 4)
    return idcol.SmoothPolytope(rows[:, :3], rows[:, 3], beta=t[-1], L=like.L)


def outputs(a, b, R, p):
    """Everything differentiated, as one vector: x (3), alpha, p1, p2,
    normal (3 each), gap, f_n, F1, F2 (6 each). None if the solve fails."""
    res = idcol.solve(a, b, R, p, options=PLAIN)
    if not res.converged:
        return None
    k = idcol.contact_kinematics(res)
    w = idcol.contact_wrench(res, MODEL)
    return np.concatenate([res.x, [res.alpha], k.p1, k.p2, k.normal, [k.gap], [w.f_n], w.F1, w.F2])


def fd_in_params(a, b, body, R, p, L):
    """d outputs / d theta of the given body by Richardson-extrapolated
    central differences (steps h and h/2)."""
    shape = a if body == 1 else b
    theta = shape.params
    powers = shape.param_length_powers
    cols = []
    for j in range(theta.size):
        step = H * max(abs(theta[j]), L ** powers[j])

        def central(h):
            tp, tm = theta.copy(), theta.copy()
            tp[j] += h
            tm[j] -= h
            sp, sm = rebuild(shape, tp), rebuild(shape, tm)
            fp = outputs(sp, b, R, p) if body == 1 else outputs(a, sp, R, p)
            fm = outputs(sm, b, R, p) if body == 1 else outputs(a, sm, R, p)
            assert fp is not None and fm is not None, "perturbed solve failed"
            return (fp - fm) / (2 * h)

        d1, d2 = central(step), central(step / 2)
        cols.append((4 * d2 - d1) / 3)
    return np.stack(cols, axis=-1)


def agree(ift, fd, col_scale, row_scale=1.0):
    """max |ift - fd| <= TOL max(1, max |fd|) after making both
    dimensionless: rows divided by row_scale, columns times col_scale."""
    A = np.atleast_2d(ift) * col_scale / row_scale
    B = np.atleast_2d(fd) * col_scale / row_scale
    err = np.max(np.abs(A - B)) / max(1.0, np.max(np.abs(B)))
    return err <= TOL, err


def pose_at_alpha(a, b, rng, target):
    """A random rotation and direction, at the distance where alpha* = target
    (alpha* is homogeneous of degree 1 in p)."""
    R = random_rotation(rng)
    d = rng.normal(size=3)
    p = 2.0 * d / np.linalg.norm(d)
    res = idcol.solve(a, b, R, p, options=PLAIN)
    assert res.converged
    return R, p * (target / res.alpha)


PAIRS = [("Sph", "SE"), ("Poly", "TC"), ("TC", "SEC"), ("SE", "Poly"), ("SEC", "Sph")]


@pytest.mark.parametrize("body", [1, 2])
@pytest.mark.parametrize("fam, partner", PAIRS)
def test_every_family_against_finite_differences_in_its_parameters(fam, partner, body):
    shapes = catalogue()
    a, b = (shapes[fam], shapes[partner]) if body == 1 else (shapes[partner], shapes[fam])
    shape = shapes[fam]
    L = a.radii[1] + b.radii[1]
    col_scale = L ** shape.param_length_powers
    rng = np.random.default_rng(100 * body + list(shapes).index(fam))
    checked, wrenches = 0, 0
    for target in ALPHAS:
        R, p = pose_at_alpha(a, b, rng, target)
        res = idcol.solve(a, b, R, p, options=TIGHT)
        assert res.converged and res.alpha == pytest.approx(target, rel=1e-9)
        sens = idcol.shape_sensitivity(res, a, b, body)
        assert sens.valid and sens.body == body and sens.conditioning.reliable
        assert sens.names == shape.param_names and len(sens.names) == shape.params.size
        p_count = shape.params.size
        assert sens.dz_dtheta.shape == (6, p_count) and sens.dx_dtheta.shape == (3, p_count)
        assert np.array_equal(sens.dalpha_dtheta, sens.dz_dtheta[3])
        kin = idcol.shape_kinematics_derivatives(res, sens)
        wr = idcol.shape_wrench_derivatives(res, sens, MODEL)
        assert kin.valid and wr.valid and kin.names == sens.names
        fd = fd_in_params(a, b, body, R, p, L)
        # x* and alpha*, then p1, p2, normal, gap.
        for name, ift, rows, row_scale in [("x", sens.dx_dtheta, slice(0, 3), L),
                                           ("alpha", sens.dalpha_dtheta, 3, 1.0),
                                           ("p1", kin.dp1_dtheta, slice(4, 7), L),
                                           ("p2", kin.dp2_dtheta, slice(7, 10), L),
                                           ("normal", kin.dnormal_dtheta, slice(10, 13), 1.0),
                                           ("gap", kin.dgap_dtheta, 13, L)]:
            ok, err = agree(ift, fd[rows], col_scale, row_scale)
            assert ok, f"{fam} body {body} alpha {target}: d {name}/d theta off by {err:.2e}"
        checked += 1
        if target < 1.0:
            # Penetrating: the wrench is active. (At alpha* = 1 the force
            # law's kink at zero depth leaves central differences O(sqrt h).)
            got = np.vstack([wr.df_n_dtheta[None], wr.dF1_dtheta, wr.dF2_dtheta])
            scale = max(1.0, np.max(np.abs(fd[14:])))
            ok, err = agree(got / scale, fd[14:] / scale, col_scale)
            assert ok, f"{fam} body {body} alpha {target}: wrench derivative off by {err:.2e}"
            wrenches += 1
    assert checked == len(ALPHAS) and wrenches == 2


def test_with_params_builds_the_same_shape_as_the_constructor():
    for s in catalogue().values():
        theta = s.params * 1.01
        if isinstance(s, idcol.SmoothPolytope):
            theta = s.params.copy()
            theta[3::4][:-1] *= 1.01  # offsets only; a scaled row is the same plane
        t = s.with_params(theta)
        assert type(t) is type(s)
        assert repr(t) == repr(rebuild(s, theta))
        assert np.allclose(t.params, rebuild(s, theta).params, rtol=1e-15)
        assert len(s.param_names) == s.params.size == s.param_length_powers.size
    assert idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8).param_names == ["a", "b", "c", "n"]
    assert idcol.SuperellipticCylinder(R=1.0, h=2.0, n=8).param_names == ["R", "h", "n"]
    assert idcol.SmoothTruncatedCone(Rb=1, Rt=1.5, a=1.5, b=1.5, beta=20).param_names == ["Rb", "Rt", "a", "b", "beta"]
    poly = catalogue()["Poly"]
    assert poly.param_names[:5] == ["A0.x", "A0.y", "A0.z", "b0", "A1.x"] and poly.param_names[-1] == "beta"
    assert poly.params.size == 4 * 8 + 1


def test_eval_params_against_differences_of_phi():
    y = np.array([0.31, -0.22, 0.4])
    checked = 0
    for s in catalogue().values():
        phi, grad, _, dphi, dgrad = s.eval_params(y)
        theta = s.params
        assert dphi.shape == (theta.size,) and dgrad.shape == (3, theta.size)
        for j in range(theta.size):
            h = 1e-6 * max(1.0, abs(theta[j]))
            tp, tm = theta.copy(), theta.copy()
            tp[j] += h
            tm[j] -= h
            (pp, gp, _), (pm, gm, _) = rebuild(s, tp).eval(y), rebuild(s, tm).eval(y)
            assert dphi[j] == pytest.approx((pp - pm) / (2 * h), rel=1e-6, abs=1e-8)
            assert np.allclose(dgrad[:, j], (gp - gm) / (2 * h), rtol=1e-6, atol=1e-7)
            checked += 1
        assert phi == pytest.approx(s.eval(y)[0], rel=1e-15) and np.allclose(grad, s.eval(y)[1], rtol=1e-15)
    assert checked == 1 + 33 + 5 + 4 + 3


def test_two_spheres_closed_form():
    """alpha* = |r| / (R1 + R2), x* = R1 r / (R1 + R2)."""
    R1, R2 = 0.7, 1.3
    a, b = idcol.Sphere(R=R1), idcol.Sphere(R=R2)
    rng = np.random.default_rng(5)
    for k in range(6):
        R = random_rotation(rng)
        r = rng.normal(size=3) * (0.5 + k)
        res = idcol.solve(a, b, R, r, options=TIGHT)
        s1, s2 = (idcol.shape_sensitivity(res, a, b, body) for body in (1, 2))
        nr, S = np.linalg.norm(r), R1 + R2
        assert s1.dalpha_dtheta[0] == pytest.approx(-nr / S ** 2, rel=1e-10)
        assert s2.dalpha_dtheta[0] == pytest.approx(-nr / S ** 2, rel=1e-10)
        assert np.allclose(s1.dx_dtheta[:, 0], r * R2 / S ** 2, rtol=1e-9, atol=1e-12)
        assert np.allclose(s2.dx_dtheta[:, 0], -r * R1 / S ** 2, rtol=1e-9, atol=1e-12)
        # gap = |r| - (R1 + R2): d gap / d R_i = -1.
        kin = idcol.shape_kinematics_derivatives(res, s1)
        assert kin.dgap_dtheta[0] == pytest.approx(-1.0, rel=1e-10)


def pw_alpha_and_axis_gradient(axes1, axes2, R, p):
    """alpha* of two ellipsoids and d alpha*/d(axes1, axes2) by the
    Perram-Wertheim function F(l) = l (1 - l) p^T C(l)^-1 p,
    C = (1 - l) A1 + l A2, A1 = diag(axes1^2), A2 = R diag(axes2^2) R^T;
    alpha*^2 = max_l F, and by the envelope theorem d alpha*^2 = dF/d axes at
    the maximiser: dF = -l (1 - l) w^T dC w with w = C^-1 p."""
    import scipy.optimize
    a1, a2 = np.asarray(axes1, float), np.asarray(axes2, float)

    def C(lam):
        return (1 - lam) * np.diag(a1 ** 2) + lam * R @ np.diag(a2 ** 2) @ R.T

    def neg_f(lam):
        return -lam * (1 - lam) * p @ np.linalg.solve(C(lam), p)

    lam = scipy.optimize.minimize_scalar(neg_f, bounds=(0, 1), method="bounded", options={"xatol": 1e-14}).x
    alpha = math.sqrt(-neg_f(lam))
    w = np.linalg.solve(C(lam), p)
    c = -lam * (1 - lam)
    d1 = c * (1 - lam) * 2 * a1 * w ** 2               # dC/da1_k = (1 - l) 2 a1_k e_k e_k^T
    u = R.T @ w
    d2 = c * lam * 2 * a2 * u ** 2                     # dC/da2_k = l 2 a2_k R e_k e_k^T R^T
    return alpha, d1 / (2 * alpha), d2 / (2 * alpha)


def test_two_ellipsoids_against_the_perram_wertheim_function():
    ax1, ax2 = (0.5, 1.0, 1.5), (1.2, 0.4, 0.8)
    a, b = idcol.Superellipsoid(*ax1, n=1), idcol.Superellipsoid(*ax2, n=1)
    rng = np.random.default_rng(9)
    for _ in range(8):
        R = random_rotation(rng)
        d = rng.normal(size=3)
        p = d / np.linalg.norm(d) * rng.uniform(0.5, 4.0)
        res = idcol.solve(a, b, R, p, options=TIGHT)
        alpha, g1, g2 = pw_alpha_and_axis_gradient(ax1, ax2, R, p)
        assert res.alpha == pytest.approx(alpha, rel=1e-9)
        s1, s2 = (idcol.shape_sensitivity(res, a, b, body) for body in (1, 2))
        assert np.allclose(s1.dalpha_dtheta[:3], g1, rtol=1e-7, atol=1e-9 * alpha)
        assert np.allclose(s2.dalpha_dtheta[:3], g2, rtol=1e-7, atol=1e-9 * alpha)


def test_vertex_derivatives_through_the_hull():
    rng = np.random.default_rng(3)
    V = rng.normal(size=(12, 3))
    V /= np.linalg.norm(V, axis=1)[:, None]
    beta = 20.0
    P = idcol.SmoothPolytope.from_vertices(V, beta=beta)
    other = idcol.Superellipsoid(a=0.6, b=0.9, c=1.1, n=4)
    J = idcol.polytope_vertex_jacobian(V, P)
    assert J.shape == (P.params.size, 3 * len(V) + 1)
    names = [f"v{i}.{c}" for i in range(len(V)) for c in "xyz"] + ["beta"]
    checked = 0
    for target in (1.3, 0.8):
        R, p = pose_at_alpha(P, other, rng, target)
        res = idcol.solve(P, other, R, p, options=TIGHT)
        c = idcol.chain_params(idcol.shape_sensitivity(res, P, other, 1), J, names=names)
        assert c.names == names and c.dz_dtheta.shape == (6, 3 * len(V) + 1)
        kin = idcol.shape_kinematics_derivatives(res, c)
        for j in range(3 * len(V) + 1):
            def at(h):
                Vp, bp = V.copy(), beta
                if j < 3 * len(V):
                    Vp[j // 3, j % 3] += h
                else:
                    bp += h
                r = idcol.solve(idcol.SmoothPolytope.from_vertices(Vp, beta=bp), other, R, p, options=PLAIN)
                assert r.converged
                return np.concatenate([[r.alpha], idcol.contact_kinematics(r).p1])
            h = 1e-5 * (beta if j == 3 * len(V) else 1.0)
            fd = (4 * (at(h / 2) - at(-h / 2)) / h - (at(h) - at(-h)) / (2 * h)) / 3
            assert c.dalpha_dtheta[j] == pytest.approx(fd[0], rel=TOL, abs=TOL)
            assert np.allclose(kin.dp1_dtheta[:, j], fd[1:], rtol=TOL, atol=TOL)
            checked += 1
    assert checked == 2 * (3 * len(V) + 1)


def test_bad_input_is_a_clear_error():
    a, b = idcol.Sphere(R=1.0), idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=2)
    res = idcol.solve(a, b, np.eye(3), [2.0, 0.3, 0.0], options=TIGHT)
    with pytest.raises(ValueError, match="'body' must be 1 or 2, got 3"):
        idcol.shape_sensitivity(res, a, b, 3)
    with pytest.raises(ValueError, match="not the shape the result was solved with"):
        idcol.shape_sensitivity(res, a, idcol.Superellipsoid(a=0.6, b=1.0, c=1.5, n=2), 2)
    with pytest.raises(TypeError, match="b must be an idcol shape"):
        idcol.shape_sensitivity(res, a, "ellipsoid", 2)
    with pytest.raises(ValueError, match="derivatives"):
        idcol.shape_sensitivity(idcol.solve(a, b, np.eye(3), [2.0, 0.3, 0.0]), a, b, 1)
    sens = idcol.shape_sensitivity(res, a, b, 2)
    other = idcol.solve(a, b, np.eye(3), [2.0, 0.3, 0.0], options=TIGHT)
    with pytest.raises(ValueError, match="another SolveResult"):
        idcol.shape_kinematics_derivatives(other, sens)
    with pytest.raises(ValueError, match="another SolveResult"):
        idcol.shape_wrench_derivatives(other, sens)
    with pytest.raises(TypeError, match="model must be an idcol.HertzModel"):
        idcol.shape_wrench_derivatives(res, sens, model=(1.0, 1.5))
    with pytest.raises(ValueError, match=r"dtheta_dq must have shape \(4, n\), got \(2, 2\)"):
        idcol.chain_params(sens, np.zeros((2, 2)))
    with pytest.raises(ValueError, match="names holds 1 names but dtheta_dq has 2 columns"):
        idcol.chain_params(sens, np.zeros((4, 2)), names=["q"])
    with pytest.raises(ValueError, match=r"theta must have shape \(4,\), got \(3,\)"):
        b.with_params([1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="'a'.*-1"):
        b.with_params([-1.0, 1.0, 1.0, 2.0])
    with pytest.raises(TypeError, match="polytope must be an idcol.SmoothPolytope"):
        idcol.polytope_vertex_jacobian(np.eye(3), b)
    cube = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    with pytest.raises(ValueError, match="face"):
        idcol.polytope_vertex_jacobian(cube, idcol.SmoothPolytope.from_vertices(cube, beta=20))
    # A result that did not converge gives an invalid sensitivity, no columns.
    bad = idcol.solve(a, b, np.eye(3), [0, 0, 0], options=TIGHT)  # Concentric
    s = idcol.shape_sensitivity(bad, a, b, 1)
    assert not s.valid and s.dz_dtheta.shape == (6, 0) and s.dalpha_dtheta.shape == (0,)
    assert not idcol.shape_kinematics_derivatives(bad, s).valid


def test_readme_shape_derivative_example_runs():
    """The example of core/README.md's "Shape-parameter derivatives" part of
    the Python section, run as written."""
    readme = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "README.md")
    text = open(readme).read()
    start = text.index("```python\n", text.index("**Shape-parameter derivatives from Python.**")) + len("```python\n")
    code = text[start:text.index("```", start)]
    assert "shape_sensitivity" in code
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "['a', 'b', 'c', 'n']" in r.stdout

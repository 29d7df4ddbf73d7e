"""One query and contact pairs: closed forms, the Perram-Wertheim oracle, the
KKT conditions checked with NumPy, swap symmetry, warm starts, and the C++
harness's own answers on the paper's sweep."""
import math
import os
import subprocess
import textwrap

import numpy as np
import pytest

import idcol
from _helpers import (ellipsoid_alpha, paper_poses, paper_shapes, radial_range, random_poses,
                      superellipsoid_phi)


def test_sphere_sphere_closed_form():
    rng = np.random.default_rng(2)
    a, b = idcol.Sphere(R=0.7), idcol.Sphere(R=1.3)
    R, p = random_poses(rng, 200, 0.05, 20.0)
    for Rk, pk in zip(R, p):
        res = idcol.solve(a, b, Rk, pk)
        assert res.status == idcol.SolveStatus.Converged and res.converged
        assert res.alpha == pytest.approx(np.linalg.norm(pk) / 2.0, rel=1e-12)
        # The contact point lies on the segment, at R1 alpha from body 1's centre.
        assert np.allclose(res.x, pk / np.linalg.norm(pk) * 0.7 * res.alpha, rtol=1e-10, atol=1e-12)


def test_alpha_max_early_exit_is_separated_with_a_lower_bound():
    rng = np.random.default_rng(9)
    a, b = idcol.Sphere(R=0.7), idcol.Sphere(R=1.3)
    opt = idcol.SolverOptions(alpha_max=1.0, derivatives=True)
    R, p = random_poses(rng, 200, 0.05, 20.0)
    separated = 0
    for Rk, pk in zip(R, p):
        exact = np.linalg.norm(pk) / 2.0
        res = idcol.solve(a, b, Rk, pk, options=opt)
        if exact > 1.0 + 1e-12:
            assert res.status == idcol.SolveStatus.Separated and not res.converged
            assert 1.0 < res.alpha <= exact and res.alpha == pytest.approx(exact, rel=1e-12)
            with pytest.raises(ValueError, match="Separated"):
                idcol.alpha_gradient(res)
            separated += 1
        elif exact < 1.0 - 1e-12:
            assert res.status == idcol.SolveStatus.Converged
    assert separated > 50


def test_ellipsoids_against_perram_wertheim():
    rng = np.random.default_rng(3)
    ax1, ax2 = (0.5, 1.0, 1.5), (1.2, 0.4, 0.8)
    a, b = idcol.Superellipsoid(*ax1, n=1), idcol.Superellipsoid(*ax2, n=1)
    R, p = random_poses(rng, 60, 0.2, 8.0)
    for Rk, pk in zip(R, p):
        res = idcol.solve(a, b, Rk, pk)
        assert res.converged
        assert res.alpha == pytest.approx(ellipsoid_alpha(ax1, ax2, Rk, pk), rel=1e-8)


def test_kkt_conditions_hold_for_every_paper_pair():
    """x/alpha on body 1, R^T (x - p)/alpha on body 2, opposite normals,
    positive multipliers; phi of the superellipsoid by the closed form."""
    rng = np.random.default_rng(4)
    shapes = paper_shapes()
    checked = 0
    for n1, n2 in [("SE", "Poly"), ("TC", "SEC"), ("SE", "SE"), ("Poly", "TC")]:
        a, b = shapes[n1], shapes[n2]
        R, p = random_poses(rng, 40, 0.3, 6.0)
        for Rk, pk in zip(R, p):
            res = idcol.solve(a, b, Rk, pk)
            assert res.converged, (n1, n2, Rk.tolist(), pk.tolist(), res)
            y1 = res.x / res.alpha
            y2 = Rk.T @ (res.x - pk) / res.alpha
            phi1, g1, _ = a.eval(y1)
            phi2, g2, _ = b.eval(y2)
            assert abs(phi1) < 1e-8 and abs(phi2) < 1e-8
            if n1 == "SE":
                assert abs(superellipsoid_phi([0.5, 1.0, 1.5], 8, y1)) < 1e-8
            n_1 = g1 / np.linalg.norm(g1)
            n_2 = Rk @ g2 / np.linalg.norm(g2)
            assert np.dot(n_1, n_2) == pytest.approx(-1.0, abs=1e-8)
            assert res.lambda1 > 0 and res.lambda2 > 0
            checked += 1
    assert checked == 160


def test_swap_symmetry():
    rng = np.random.default_rng(5)
    shapes = paper_shapes()
    a, b = shapes["SE"], shapes["TC"]
    R, p = random_poses(rng, 50, 0.3, 6.0)
    for Rk, pk in zip(R, p):
        r12 = idcol.solve(a, b, Rk, pk)
        r21 = idcol.solve(b, a, Rk.T, -Rk.T @ pk)
        assert r12.converged and r21.converged
        assert r21.alpha == pytest.approx(r12.alpha, rel=1e-9)
        # The contact point, seen from body 2.
        assert np.allclose(Rk.T @ (r12.x - pk), r21.x, rtol=1e-7, atol=1e-8)


def test_bad_poses_and_bad_arrays_are_errors():
    a = idcol.Sphere(R=1.0)
    res = idcol.solve(a, a, np.eye(3), [0, 0, 0])
    assert res.status == idcol.SolveStatus.Concentric and res.alpha == 0.0
    with pytest.raises(ValueError, match=r"R must have shape \(3, 3\), got \(9,\)"):
        idcol.solve(a, a, np.eye(3).ravel(), [1, 0, 0])
    with pytest.raises(ValueError, match=r"p must have shape \(3,\), got \(1, 3\)"):
        idcol.solve(a, a, np.eye(3), [[1, 0, 0]])
    with pytest.raises(TypeError, match="b must be an idcol shape"):
        idcol.solve(a, "sphere", np.eye(3), [1, 0, 0])
    with pytest.raises(TypeError, match="options must be an idcol.SolverOptions"):
        idcol.solve(a, a, np.eye(3), [1, 0, 0], options={"tolerance": 1e-8})
    # Integer and Fortran-ordered inputs are converted.
    r1 = idcol.solve(a, a, np.asfortranarray(np.eye(3)), np.array([3, 0, 0]))
    assert r1.converged and r1.alpha == pytest.approx(1.5, rel=1e-14)


def test_contact_pair_warm_starts_and_agrees_with_cold():
    shapes = paper_shapes()
    pair = idcol.ContactPair(shapes["SE"], shapes["SEC"], options=idcol.SolverOptions(tolerance=1e-12))
    assert pair.body1 is shapes["SE"] and pair.options.tolerance == 1e-12
    R, p = paper_poses(400, *radial_range(shapes["SE"], shapes["SEC"]))
    warm_its = cold_its = 0
    for k, (Rk, pk) in enumerate(zip(R, p)):
        rw = pair.solve(Rk, pk)
        rc = pair.solve_cold(Rk, pk)
        assert rw.converged and rc.converged
        assert rw.warm_started == (k > 0)
        assert rw.alpha == pytest.approx(rc.alpha, rel=1e-10)
        warm_its += rw.iterations
        cold_its += rc.iterations
    assert warm_its < cold_its
    pair.reset_warm_start()
    assert not pair.solve(R[0], p[0]).warm_started
    # Options cannot be made invalid (every assignment is validated), so a
    # pair's options are valid by construction.
    o = idcol.SolverOptions()
    with pytest.raises(ValueError, match=r"'max_restarts'.*got -1"):
        o.max_restarts = -1
    assert idcol.ContactPair(shapes["SE"], shapes["SEC"], options=o).options.max_restarts == 8


def _harness():
    build = os.environ.get("IDCOL_BUILD_DIR", "build")
    exe = os.path.join(build, "harness", "idcol_harness")
    return exe if os.access(exe, os.X_OK) else None


@pytest.mark.skipif(_harness() is None, reason="idcol_harness not built (IDCOL_BUILD_HARNESS=OFF)")
def test_same_answers_as_the_cpp_harness(tmp_path):
    """The harness (C++, its own pose generator) and this module (poses from
    NumPy) solve the paper's sweep; alpha* agrees to the solver tolerance."""
    shapes = paper_shapes()
    scene = tmp_path / "py.toml"
    scene.write_text(textwrap.dedent("""\
        name = "python-check"
        description = "cold sweep for the Python tests"
        [shapes]
        Poly = { family = "smooth_polytope", normals = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1], [-1, -1, -1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]], offsets = [1, 1, 1, 1, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667], beta = 20 }
        TC = { family = "smooth_truncated_cone", Rb = 1.0, Rt = 1.5, a = 1.5, b = 1.5, beta = 20 }
        SE = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 8 }
        SEC = { family = "superelliptic_cylinder", R = 1.0, h = 2.0, n = 8 }
        [sweep]
        generator = "paper"
        poses = 2000
        dt = 1e-4
        warm_chain = 1000
        warmup = 0
        [run]
        pairs = [["SE", "Poly"], ["TC", "SEC"]]
        passes = ["cold"]
        record = ["iterations", "per_pose"]
        """))
    out = tmp_path / "py.json"
    subprocess.run([_harness(), "run", str(scene), "-o", str(out), "--no-progress"], check=True,
                   stdout=subprocess.DEVNULL)
    rows = [line.split(",") for line in (tmp_path / "py.poses.csv").read_text().splitlines()[1:]]
    checked = 0
    for n1, n2 in [("SE", "Poly"), ("TC", "SEC")]:
        cpp = {int(r[3]): (r[4], float(r[6])) for r in rows if r[0] == n1 and r[1] == n2}
        assert len(cpp) == 2000
        a, b = shapes[n1], shapes[n2]
        R, p = paper_poses(2000, *radial_range(a, b))
        for k in range(0, 2000, 4):
            res = idcol.solve(a, b, R[k], p[k])
            status, alpha = cpp[k]
            assert status == "converged" and res.converged
            assert res.alpha == pytest.approx(alpha, rel=1e-9)
            checked += 1
    assert checked == 1000


BAD_POSES = [
    (np.eye(3), [np.nan, 0, 0], r"^p\[0\] = nan is not finite$"),
    (np.eye(3), [1, -np.inf, 0], r"^p\[1\] = -inf is not finite$"),
    (np.where(np.eye(3) == 1, 1.0, np.nan), [1, 0, 0], r"^R\[0, 1\] = nan is not finite$"),
    (2 * np.eye(3), [1, 0, 0], r"^R is not a rotation: \|\|R\^T R - I\|\|_F = 5\.2 > 1e-09"),
    (np.eye(3) + 1e-8, [1, 0, 0], r"^R is not a rotation: \|\|R\^T R - I\|\|_F = 6e-08 > 1e-09"),
    (np.diag([1.0, 1.0, -1.0]), [1, 0, 0], r"^R has determinant -1\.0: a reflection, not a rotation$"),
    (np.diag([1.0, 1.0, -1.0]).astype(np.float32), [1, 0, 0], r"^R has determinant -1\.0: a reflection"),
    (np.full((3, 3), np.nan, np.float32), [1, 0, 0], r"^R\[0, 0\] = nan is not finite$"),
]


@pytest.mark.parametrize("R, p, message", BAD_POSES)
def test_a_bad_pose_is_a_value_error_naming_the_argument_everywhere(R, p, message):
    """One query refuses a pose that is not rigid (a NaN or Inf entry, R not
    orthonormal to 1e-9, a reflection) with a ValueError naming the
    argument and the entry, in every dtype: solve, ContactPair, the twist
    Jacobians and time_of_impact (its four arguments by name). Only a
    batch row is a status (test_batch.py)."""
    a = idcol.Sphere(R=1.0)
    for call in (lambda: idcol.solve(a, a, R, p), lambda: idcol.solve(a, a, R, p, derivatives=True),
                 lambda: idcol.ContactPair(a, a).solve(R, p), lambda: idcol.ContactPair(a, a).solve_cold(R, p),
                 lambda: idcol.relative_twist_jacobians(R, p)):
        with pytest.raises(ValueError, match=message):
            call()
    R0, p0 = np.eye(3), [3.0, 0, 0]
    for end, args in ((0, (R, p, R0, p0)), (1, (R0, p0, R, p))):  # "R" -> "R0" or "R1", "p" -> "p0" or "p1"
        with pytest.raises(ValueError, match="^" + message[1] + str(end) + message[2:]):
            idcol.time_of_impact(a, a, *args)

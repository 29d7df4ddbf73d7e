"""The contact-physics layer from NumPy: solve_batch's per-row warm states and
wrenches against the loop of solve and contact_wrench (bit for bit), the
broad phase against a brute force, the scene's wrench pairs and Jacobians,
the rigid bodies' Jacobian against differences, and the library's
integrator against SciPy's BDF on the same equations."""
import pickle

import numpy as np
import pytest
import scipy.integrate
import scipy.spatial.transform

import idcol

from _helpers import paper_shapes


@pytest.fixture(scope="module")
def rows():
    """Mixed pairs near contact, and the poses of a second step 0.01 away."""
    s = list(paper_shapes().values())
    rng = np.random.default_rng(21)
    n = 90
    pairs = [(s[k % 4], s[(k // 4) % 4]) for k in range(n)]
    R = scipy.spatial.transform.Rotation.random(n, random_state=22).as_matrix()
    reach = np.array([a.radii[1] + b.radii[1] for a, b in pairs])
    d = rng.normal(size=(n, 3))
    p0 = (rng.uniform(0.5, 1.2, n) * reach)[:, None] * d / np.linalg.norm(d, axis=1)[:, None]
    return pairs, R, p0, p0 + 0.01 * rng.normal(size=(n, 3))


def test_per_row_warm_states_and_wrenches_equal_the_loop(rows):
    pairs, R, p0, p1 = rows
    model = idcol.HertzModel(1e4, 1.5)
    ws = idcol.WarmStarts(len(pairs))
    idcol.solve_batch(pairs, R, p0, warm=ws, threads=2)
    assert ws.valid.sum() >= len(pairs) - 2
    before = [ws[k] for k in range(len(pairs))]
    out = idcol.solve_batch(pairs, R, p1, warm=ws, contact=model, derivatives=True, threads=2)
    active = 0
    for k, (a, b) in enumerate(pairs):
        w = before[k]
        res = idcol.solve(a, b, R[k], p1[k], derivatives=True, warm_start=w)
        assert res.status == out.status[k] and res.iterations == out.iterations[k]
        assert pickle.dumps(w) == pickle.dumps(ws[k]), k  # the state left for the next step
        if not res.converged:
            assert np.isnan(out.f_n[k]) and np.isnan(out.F1[k]).all()
            continue
        assert res.alpha == out.alpha[k]
        cw = idcol.contact_wrench(res, model, derivatives=True)
        assert out.f_n[k] == (cw.f_n if cw.active else 0.0)
        assert np.array_equal(out.F1[k], cw.F1) and np.array_equal(out.F2[k], cw.F2)
        assert np.array_equal(out.dF1_dxi[k], cw.dF1_dxi) and np.array_equal(out.dF2_dxi[k], cw.dF2_dxi)
        assert np.array_equal(out.df_n_dxi[k], cw.df_n_dxi)
        active += cw.active
    assert active >= 20
    assert out.iterations.mean() < 4  # warm from the last step


def test_the_two_warm_modes_are_refused_together(rows):
    pairs, R, p0, _ = rows
    with pytest.raises(ValueError, match="two modes"):
        idcol.solve_batch(pairs, R, p0, warm=idcol.WarmStarts(len(pairs)), warm_start=True)
    with pytest.raises(ValueError, match="warm holds 3 states"):
        idcol.solve_batch(pairs, R, p0, warm=idcol.WarmStarts(3))
    with pytest.raises(TypeError, match="WarmStarts"):
        idcol.solve_batch(pairs, R, p0, warm=[idcol.WarmStart()] * len(pairs))
    ws = pickle.loads(pickle.dumps(idcol.WarmStarts(4)))
    assert len(ws) == 4 and not ws.valid.any()


def test_broad_phase_equals_brute_force():
    rng = np.random.default_rng(3)
    for n, box in ((0, 1.0), (5, 1.0), (200, 5.0), (800, 12.0)):
        c = rng.uniform(-box, box, (n, 3))
        r = rng.uniform(0.05, 1.0, n)
        i, j = np.triu_indices(n, 1)
        d2 = ((c[i] - c[j]) ** 2).sum(axis=1)
        want = np.stack([i, j], axis=1)[d2 <= (r[i] + r[j]) ** 2] if n else np.zeros((0, 2))
        for method in ("all_pairs", "sweep_and_prune", "tree", "auto"):
            got = idcol.broad_phase(c, r, method)
            assert np.array_equal(got, want), (method, n)
    with pytest.raises(ValueError, match="broad_phase must be"):
        idcol.Scene([idcol.Sphere(1.0)], broad_phase="octree")


def world(R, p, F):
    """A body-frame wrench (moment, force) in the world about the origin."""
    f = R @ F[3:]
    return np.concatenate([R @ F[:3] + np.cross(p, f), f])


@pytest.fixture(scope="module")
def crowd():
    return idcol.box_of_bodies(27, seed=3, scale=0.9, jitter=0.15)


def test_scene_wrench_pairs_are_equal_and_opposite(crowd):
    scene = idcol.Scene(crowd.shapes, contact=idcol.HertzModel(1e4))
    c = scene.update(crowd.R, crowd.p)
    assert c.ok.all() and c.active.sum() > 10
    for k in np.flatnonzero(c.active):
        i, j = c.body1[k], c.body2[k]
        s = world(crowd.R[i], crowd.p[i], c.F1[k]) + world(crowd.R[j], crowd.p[j], c.F2[k])
        assert np.linalg.norm(s) < 1e-12 * np.linalg.norm(c.F1[k])
    again = scene.update(crowd.R, crowd.p)
    assert again.warm_started[again.status == idcol.SolveStatus.Converged].all()
    total = sum(world(crowd.R[i], crowd.p[i], F) for i, F in enumerate(scene.body_wrenches()))
    assert np.linalg.norm(total) < 1e-11 * np.abs(scene.body_wrenches()).sum()


def test_scene_jacobians_against_differences(crowd):
    scene = idcol.Scene(crowd.shapes, contact=idcol.HertzModel(1e4), options=idcol.SolverOptions(tolerance=1e-13, alpha_max=1.0),
                        warm_start=False)
    c = scene.update(crowd.R, crowd.p, derivatives=True)
    k = int(np.flatnonzero(c.active & (c.f_n > 1.0))[0])
    i, j = c.body1[k], c.body2[k]
    h = 1e-6
    fd = np.zeros((6, 12))
    for col in range(12):
        body = i if col < 6 else j
        diffs = []
        for s in (1.0, -1.0):
            R, p = crowd.R.copy(), crowd.p.copy()
            dR, dp = idcol.se3_exp(s * h * np.eye(6)[col % 6])
            R[body], p[body] = R[body] @ dR, p[body] + R[body] @ dp
            cc = scene.update(R, p)
            diffs.append(cc.F1[(cc.body1 == i) & (cc.body2 == j)][0])
        fd[:, col] = (diffs[0] - diffs[1]) / (2 * h)
    assert np.abs(c.dF1[k] - fd).max() < 1e-5 * np.abs(fd).max()


def test_system_jacobian_against_differences(crowd):
    shapes, masses = crowd.shapes[:4], crowd.masses[:4]
    sys_ = idcol.MultibodySystem(shapes, masses, contact=idcol.HertzModel(1e3),
                                 options=idcol.SolverOptions(tolerance=1e-13, alpha_max=1.0))
    eta = np.random.default_rng(4).normal(size=(4, 6))
    y = sys_.state(crowd.R[:4], crowd.p[:4], eta)
    J = sys_.jacobian(y)
    h = 1e-6
    fd = np.stack([(sys_.rhs(y + h * e) - sys_.rhs(y - h * e)) / (2 * h) for e in np.eye(len(y))], axis=1)
    assert np.abs(J - fd).max() < 1e-6 * np.abs(fd).max()


def test_ten_bodies_in_a_few_lines_conserve_momentum():
    sc = idcol.paper_ten_bodies(seed=1)
    sys_ = idcol.MultibodySystem(sc.shapes, sc.masses, contact=idcol.HertzModel(1e4, 1.5))
    y0 = sys_.state(sc.R, sc.p, sc.eta)
    run = sys_.simulate(y0, 2.4, outputs=[1.0, 2.0, 2.4], max_step=0.01)
    assert run["status"] == "success" and run["y"].shape == (4, 120)
    assert run["active_contacts"] > 100
    drift = np.abs(sys_.momentum(run["y"][-1]) - sys_.momentum(y0))
    assert drift[3:].max() < 50 * 1e-6 * sum(m.mass for m in sc.masses) * 2.0


def test_the_integrator_agrees_with_scipys_bdf():
    """Four bodies thrown at each other, 0.6 s through their collisions: the
    library's NDF and SciPy's BDF, each with the system's rhs and Jacobian,
    reach the same state to the tolerance (SciPy shares no code with it)."""
    sc = idcol.paper_ten_bodies(seed=1)
    keep = [1, 3, 4, 8]  # cube, cylinder, ellipsoid, sphere
    corners = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]) / np.sqrt(3) * 1.7
    R = sc.R[keep]
    eta = np.zeros((4, 6))
    for b in range(4):
        eta[b, 3:] = R[b].T @ (-2.5 * corners[b] / 1.7)
        eta[b, :3] = [0.5, -1.0, 0.3]
    sys_ = idcol.MultibodySystem([sc.shapes[k] for k in keep], [sc.masses[k] for k in keep],
                                 contact=idcol.HertzModel(1e4, 1.5), options=idcol.SolverOptions(tolerance=1e-12, alpha_max=1.0))
    y0 = sys_.state(R, corners, eta)
    ours = sys_.simulate(y0, 0.6, outputs=[0.6], rtol=1e-8, atol=1e-10, max_step=0.01)
    assert ours["status"] == "success" and ours["active_contacts"] > 50
    ref = scipy.integrate.solve_ivp(lambda t, y: sys_.rhs(y), (0.0, 0.6), y0, method="BDF",
                                    jac=lambda t, y: sys_.jacobian(y), rtol=1e-8, atol=1e-10, max_step=0.01)
    assert ref.success
    # Compare the poses (rotation vectors may differ by a chart change: compare R and p).
    Ra, pa = sys_.poses(ours["y"][-1])
    Rb, pb = sys_.poses(ref.y[:, -1])
    # Measured: 8.9e-8 (positions), 1.5e-7 (rotations), 9.9e-7 (twists), after
    # collisions that changed the twists by up to 5.
    assert np.abs(pa - pb).max() < 1e-6 and np.abs(Ra - Rb).max() < 1e-6
    assert np.abs(ours["y"][-1][24:] - ref.y[24:, -1]).max() < 1e-5


def test_wrench_fields_pickle_and_old_states_read_them_as_none():
    a = idcol.Sphere(1.0)
    R = np.repeat(np.eye(3)[None], 3, 0)
    p = np.array([[1.5, 0, 0], [3.0, 0, 0], [1.9, 0, 0]])
    out = idcol.solve_batch(a, a, R, p, contact=idcol.HertzModel(1e3), derivatives=True)
    # Two unit spheres 1.5 apart: alpha* = 0.75, gap = -0.5, f_n = 1e3 0.5^1.5.
    assert out.f_n[0] == pytest.approx(1e3 * 0.5 ** 1.5, rel=1e-12) and out.f_n[1] == 0.0
    back = pickle.loads(pickle.dumps(out))
    assert np.array_equal(back.F1, out.F1) and np.array_equal(back.dF2_dxi, out.dF2_dxi)
    state = out.__reduce__()[1][0]
    old = {k: v for k, v in state.items() if k not in ("f_n", "F1", "F2", "df_n_dxi", "dF1_dxi", "dF2_dxi")}
    assert idcol._restore_batch_result(old).f_n is None
    with pytest.raises(ValueError, match="come together"):
        idcol._restore_batch_result(dict(state, dF1_dxi=None))

"""The batch returns what a planner needs: gap, normal and witness points
(body-1 and world frame) and their derivatives, each row equal to solve +
contact_kinematics on that row; and the keywords shared with solve."""
import numpy as np
import pytest
import scipy.spatial.transform

import idcol

from _helpers import paper_shapes


@pytest.fixture(scope="module")
def rows():
    s = paper_shapes()
    rng = np.random.default_rng(11)
    n = 120
    names = list(s)
    pairs = [(s[names[k % 4]], s[names[(k // 4) % 4]]) for k in range(n)]
    R = scipy.spatial.transform.Rotation.random(n, random_state=12).as_matrix()
    p = rng.uniform(-4.0, 4.0, (n, 3))
    return pairs, R, p


def test_kinematics_equal_solve_and_contact_kinematics_row_by_row(rows):
    pairs, R, p = rows
    out = idcol.solve_batch(pairs, R, p, derivatives=True, threads=2)
    assert out.converged.sum() >= len(pairs) - 2
    for k, (a, b) in enumerate(pairs):
        res = idcol.solve(a, b, R[k], p[k], derivatives=True)
        assert res.status == out.status[k]
        if not res.converged:
            assert np.isnan(out.gap[k]) and np.isnan(out.p1[k]).all()
            assert not out.dgap_dxi[k].any() and not out.dp1_dxi[k].any()
            continue
        kin = idcol.contact_kinematics(res, derivatives=True)
        assert out.gap[k] == kin.gap
        assert np.array_equal(out.normal[k], kin.normal)
        assert np.array_equal(out.p1[k], kin.p1) and np.array_equal(out.p2[k], kin.p2)
        assert np.array_equal(out.dgap_dxi[k], kin.dgap_dxi)
        assert np.array_equal(out.dnormal_dxi[k], kin.dnormal_dxi)
        assert np.array_equal(out.dp1_dxi[k], kin.dp1_dxi) and np.array_equal(out.dp2_dxi[k], kin.dp2_dxi)
        assert np.array_equal(out.dalpha_dxi[k], idcol.alpha_gradient(res))


def test_kinematics_relations_hold_without_the_solver(rows):
    """Independent of contact_kinematics: p1 = x/alpha, p2 - p1 = gap p/|p|,
    |normal| = 1, and the normal is opposite to body 2's at p2."""
    pairs, R, p = rows
    out = idcol.solve_batch(pairs, R, p)
    c = out.converged
    assert np.allclose(out.p1[c], out.x[c] / out.alpha[c, None], rtol=0, atol=1e-12)
    u = p[c] / np.linalg.norm(p[c], axis=1)[:, None]
    assert np.allclose(out.p2[c] - out.p1[c], out.gap[c, None] * u, atol=1e-10)
    assert np.allclose(np.linalg.norm(out.normal[c], axis=1), 1.0, atol=1e-12)
    for k in np.flatnonzero(c)[:30]:
        a, b = pairs[k]
        _, g1, _ = a.eval(out.p1[k])
        assert np.allclose(g1 / np.linalg.norm(g1), out.normal[k], atol=1e-9)
        _, g2, _ = b.eval(R[k].T @ (out.p2[k] - p[k]))
        n2 = R[k] @ g2
        assert np.allclose(n2 / np.linalg.norm(n2), -out.normal[k], atol=1e-6)


def test_world_frame_kinematics(rows):
    pairs, R, p = rows
    R_W1 = scipy.spatial.transform.Rotation.random(len(pairs), random_state=13).as_matrix()
    p_W1 = np.random.default_rng(14).normal(size=(len(pairs), 3))
    out = idcol.solve_batch(pairs, R, p, R_W1=R_W1, p_W1=p_W1)
    c = out.converged
    assert np.allclose(out.normal_W[c], np.einsum("kij,kj->ki", R_W1, out.normal)[c], atol=1e-14)
    assert np.allclose(out.p1_W[c], (np.einsum("kij,kj->ki", R_W1, out.p1) + p_W1)[c], atol=1e-13)
    assert np.allclose(out.p2_W[c], (np.einsum("kij,kj->ki", R_W1, out.p2) + p_W1)[c], atol=1e-13)
    # One world pose for every row.
    one = idcol.solve_batch(pairs, R, p, R_W1=R_W1[0], p_W1=p_W1[0])
    assert np.allclose(one.p1_W[c], (out.p1 @ R_W1[0].T + p_W1[0])[c], atol=1e-13)
    # The world-frame p2 - p1 has the length of the gap.
    assert np.allclose(np.linalg.norm(out.p2_W[c] - out.p1_W[c], axis=1), np.abs(out.gap[c]), atol=1e-10)
    with pytest.raises(ValueError, match="give both R_W1 and p_W1"):
        idcol.solve_batch(pairs, R, p, R_W1=R_W1)
    with pytest.raises(ValueError, match="need kinematics=True"):
        idcol.solve_batch(pairs, R, p, R_W1=R_W1, p_W1=p_W1, kinematics=False)


def _solved_beside(a, b, R, p, j, h, **kw):
    """The batch's answers at X_12 exp(+-h e_j^), e_j the j-th twist coordinate."""
    xi = np.zeros(6)
    xi[j] = h
    out = []
    for sign in (1.0, -1.0):
        Rd, pd = idcol.se3_exp(sign * xi)
        out.append(idcol.solve_batch(a, b, (R @ Rd)[None], (p + R @ pd)[None], **kw))
    return out


def test_kinematic_derivatives_match_finite_differences_in_the_tangent_space(rows):
    """d gap/d xi and d p1/d xi against central differences along
    X_12 exp(h xi^), h = 1e-6."""
    pairs, R, p = rows
    out = idcol.solve_batch(pairs[:20], R[:20], p[:20], derivatives=True)
    h = 1e-6
    for k in np.flatnonzero(out.converged)[:8]:
        a, b = pairs[k]
        for j in range(6):
            plus, minus = _solved_beside(a, b, R[k], p[k], j, h)
            fd_gap = (plus.gap[0] - minus.gap[0]) / (2 * h)
            fd_p1 = (plus.p1[0] - minus.p1[0]) / (2 * h)
            assert abs(fd_gap - out.dgap_dxi[k, j]) < 1e-5 * (1 + abs(fd_gap))
            assert np.allclose(fd_p1, out.dp1_dxi[k, :, j], atol=1e-5 * (1 + np.abs(fd_p1).max()))


def test_world_frame_derivatives_match_finite_differences(rows):
    """d normal_W, d p1_W, d p2_W / d xi against central differences of the
    world-frame outputs along X_12 exp(h xi^), body 1 held at (R_W1, p_W1)."""
    pairs, R, p = rows
    R_W1 = scipy.spatial.transform.Rotation.random(1, random_state=15).as_matrix()[0]
    p_W1 = np.array([0.3, -1.2, 2.0])
    world = dict(R_W1=R_W1, p_W1=p_W1)
    out = idcol.solve_batch(pairs[:20], R[:20], p[:20], derivatives=True, **world)
    plain = idcol.solve_batch(pairs[:20], R[:20], p[:20], derivatives=True)
    assert plain.dnormal_W_dxi is None and idcol.solve_batch(pairs[:20], R[:20], p[:20], **world).dp1_W_dxi is None
    h = 1e-6
    for k in np.flatnonzero(out.converged)[:6]:
        a, b = pairs[k]
        for j in range(6):
            plus, minus = _solved_beside(a, b, R[k], p[k], j, h, **world)
            for name in ("normal_W", "p1_W", "p2_W"):
                fd = (getattr(plus, name)[0] - getattr(minus, name)[0]) / (2 * h)
                got = getattr(out, "d" + name + "_dxi")[k, :, j]
                assert np.allclose(fd, got, atol=1e-5 * (1 + np.abs(fd).max())), (k, j, name, fd, got)


def test_repr_names_the_rows_and_the_arrays(rows):
    pairs, R, p = rows
    out = idcol.solve_batch(pairs, R, p)
    r = repr(out)
    assert r.startswith("BatchResult(N=120, converged=%d, alpha in [" % out.converged.sum())
    assert "arrays=[alpha, x, status, iterations, converged, gap, normal, p1, p2])" in r
    assert out.dalpha_dxi is None and out.dgap_dxi is None and out.p1_W is None
    bare = idcol.solve_batch(pairs, R, p, kinematics=False)
    assert bare.gap is None and "gap" not in repr(bare)


def test_one_set_of_keywords_for_solve_and_solve_batch(rows):
    pairs, R, p = rows
    a, b = pairs[5]
    # derivatives=True without building SolverOptions.
    res = idcol.solve(a, b, R[5], p[5], derivatives=True)
    assert res.has_derivatives
    out = idcol.solve_batch(a, b, R[5:6], p[5:6], derivatives=True)
    assert np.array_equal(out.dalpha_dxi[0], idcol.alpha_gradient(res))
    # derivatives from options, and the keyword overriding them.
    opt = idcol.SolverOptions(derivatives=True)
    assert idcol.solve_batch(a, b, R[5:6], p[5:6], options=opt).dalpha_dxi is not None
    assert idcol.solve_batch(a, b, R[5:6], p[5:6], options=opt, derivatives=False).dalpha_dxi is None
    assert not idcol.solve(a, b, R[5], p[5], options=opt, derivatives=False).has_derivatives
    # alpha_max: the early exit, the same in both.
    far = np.array([[30.0, 0.0, 0.0]])
    r1 = idcol.solve(a, b, np.eye(3), far[0], alpha_max=2.0)
    r2 = idcol.solve_batch(a, b, np.eye(3)[None], far, alpha_max=2.0)
    assert r1.status == idcol.SolveStatus.Separated and r2.status[0] == idcol.SolveStatus.Separated
    assert r1.alpha == r2.alpha[0]
    # warm_start: a WarmStart carried along rows equals the warm batch.
    ws = idcol.WarmStart()
    chain = [idcol.solve(a, b, R[k], p[k], warm_start=ws).alpha for k in range(10)]
    batch = idcol.solve_batch(a, b, R[:10], p[:10], warm_start=True)
    assert np.array_equal(batch.alpha, chain) and ws.valid
    with pytest.raises(TypeError, match="warm_start must be an idcol.WarmStart"):
        idcol.solve(a, b, R[0], p[0], warm_start=True)
    with pytest.raises(TypeError, match="derivatives must be a bool"):
        idcol.solve(a, b, R[0], p[0], derivatives=1)
    with pytest.raises(ValueError, match="alpha_max"):
        idcol.solve_batch(a, b, R[:2], p[:2], alpha_max=-1.0)

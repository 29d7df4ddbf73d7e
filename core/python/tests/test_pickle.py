"""Shapes, options, results and contact pairs pickle and deep-copy, so that
multiprocessing works; a ContactPair's warm start is dropped (documented)."""
import copy
import multiprocessing
import pickle

import numpy as np
import pytest

import idcol

from _helpers import OCTA, OCTA_B, paper_shapes


def all_shapes():
    s = paper_shapes()
    rng = np.random.default_rng(3)
    V = rng.normal(size=(14, 3))
    V -= V.mean(axis=0)
    return list(s.values()) + [idcol.Sphere(R=0.7), idcol.Superellipsoid(0.3, 0.7, 1.1),
                               idcol.SmoothPolytope.from_vertices(V, beta=15.0, L=1.3),
                               idcol.SmoothPolytope(OCTA, OCTA_B, beta=20.0, L=0.8),
                               idcol.SmoothPolytope.from_vertices(V, beta=15.0, L=1.3).with_params(
                                   idcol.SmoothPolytope.from_vertices(V, beta=15.0, L=1.3).params * 1.001)]


@pytest.mark.parametrize("shape", all_shapes(), ids=repr)
@pytest.mark.parametrize("clone", [lambda o: pickle.loads(pickle.dumps(o)), copy.deepcopy, copy.copy],
                         ids=["pickle", "deepcopy", "copy"])
def test_shapes_round_trip(shape, clone):
    c = clone(shape)
    assert type(c) is type(shape) and repr(c) == repr(shape)
    assert np.array_equal(c.params, shape.params)
    if shape.family == "smooth_polytope":
        assert np.array_equal(c.vertices, shape.vertices)
    other = idcol.Sphere(R=0.5)
    R, p = np.eye(3), np.array([2.5, 0.3, 0.1])
    assert idcol.solve(c, other, R, p).alpha == idcol.solve(shape, other, R, p).alpha


def test_random_polytopes_round_trip_bit_for_bit():
    """Polytopes are rebuilt from what built them (vertices, or A and b),
    not from their renormalised rows, which could move by an ulp."""
    rng = np.random.default_rng(8)
    done = 0
    for _ in range(100):
        V = rng.normal(size=(12, 3))
        V -= V.mean(axis=0)
        try:
            P = idcol.SmoothPolytope.from_vertices(V, beta=20.0, L=1.3)
        except ValueError:
            continue
        Q = pickle.loads(pickle.dumps(P))
        assert np.array_equal(P.params, Q.params) and np.array_equal(P.vertices, Q.vertices)
        A = idcol.SmoothPolytope(P.A * rng.uniform(0.5, 2.0, (len(P.b), 1)), P.b, beta=20.0, L=1.3)
        assert np.array_equal(pickle.loads(pickle.dumps(A)).params, A.params)
        done += 1
    assert done > 50


def test_options_round_trip_every_field():
    o = idcol.SolverOptions(tolerance=1e-11, max_iterations=77, derivatives=True, alpha_max=3.5, barrier=False)
    for c in (pickle.loads(pickle.dumps(o)), copy.deepcopy(o)):
        assert repr(c) == repr(o)
    h = idcol.HertzModel(stiffness=2.0, exponent=1.2)
    assert repr(pickle.loads(pickle.dumps(h))) == repr(h)


def test_solve_result_round_trips_with_its_derivatives():
    a, b = paper_shapes()["SE"], paper_shapes()["TC"]
    res = idcol.solve(a, b, np.eye(3), [3.0, 0.5, 0.0], derivatives=True)
    for c in (pickle.loads(pickle.dumps(res)), copy.deepcopy(res)):
        assert repr(c) == repr(res) and c.lambda1 == res.lambda1 and c.has_derivatives
        assert np.array_equal(idcol.alpha_gradient(c), idcol.alpha_gradient(res))
        assert np.array_equal(idcol.contact_kinematics(c).p2, idcol.contact_kinematics(res).p2)
    assert pickle.loads(pickle.dumps(idcol.SolveStatus.Converged)) == idcol.SolveStatus.Converged
    with pytest.raises(ValueError, match="another build of idcol"):
        idcol._restore_solve_result(b"\0" * 8, "idcol-0.0.0-8-8-8-little")


def test_batch_result_round_trips_read_only():
    a, b = paper_shapes()["SE"], paper_shapes()["TC"]
    p = np.random.default_rng(4).uniform(-3, 3, (20, 3))
    out = idcol.solve_batch(a, b, np.repeat(np.eye(3)[None], 20, 0), p, derivatives=True)
    c = pickle.loads(pickle.dumps(out))
    assert repr(c) == repr(out)
    for name in ("alpha", "x", "status", "dalpha_dxi", "dp1_dxi", "gap", "normal"):
        assert np.array_equal(getattr(c, name), getattr(out, name), equal_nan=True)
        assert not getattr(c, name).flags.writeable
    assert c.p1_W is None


def test_contact_pair_keeps_shapes_and_options_and_drops_the_warm_start():
    a, b = paper_shapes()["SE"], paper_shapes()["Poly"]
    pair = idcol.ContactPair(a, b, idcol.SolverOptions(tolerance=1e-11))
    pair.solve(np.eye(3), [3.0, 0.2, 0.0])
    c = pickle.loads(pickle.dumps(pair))
    assert repr(c) == repr(pair) and repr(c.options) == repr(pair.options)
    r = c.solve(np.eye(3), [3.0, 0.25, 0.0])
    assert not r.warm_started  # dropped: the copy's first solve is cold
    assert pair.solve(np.eye(3), [3.0, 0.25, 0.0]).warm_started


def test_warm_start_round_trips_with_its_state():
    a, b = paper_shapes()["SE"], paper_shapes()["TC"]
    ws = idcol.WarmStart()
    for k in range(4):
        idcol.solve(a, b, np.eye(3), [3.0, 0.1 * k, 0.0], warm_start=ws)
    c = pickle.loads(pickle.dumps(ws))
    r1 = idcol.solve(a, b, np.eye(3), [3.0, 0.45, 0.0], warm_start=ws)
    r2 = idcol.solve(a, b, np.eye(3), [3.0, 0.45, 0.0], warm_start=c)
    assert r2.warm_started and r1.alpha == r2.alpha and r1.iterations == r2.iterations


def _work(args):
    a, b, R, p = args
    out = idcol.solve_batch(a, b, R, p, threads=1)
    return idcol.solve(a, b, R[0], p[0]), out


def test_multiprocessing_pool_gives_the_serial_answers():
    s = paper_shapes()
    rng = np.random.default_rng(5)
    jobs = []
    for name in ("SE", "Poly", "TC"):
        R = np.repeat(np.eye(3)[None], 16, 0)
        jobs.append((s[name], s["SEC"], R, rng.uniform(-4, 4, (16, 3))))
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        got = pool.map(_work, jobs)
    for (a, b, R, p), (res, out) in zip(jobs, got):
        want = idcol.solve_batch(a, b, R, p, threads=1)
        assert np.array_equal(out.alpha, want.alpha) and np.array_equal(out.status, want.status)
        assert res.alpha == idcol.solve(a, b, R[0], p[0]).alpha

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
    # The raw-memory pickles of earlier builds are refused, never read.
    with pytest.raises(ValueError, match="pickled as raw memory by another"):
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


# --- Pickles hold the result's fields, validated when read back -------------

def _toi(impact=True):
    a, b = idcol.Sphere(0.25), idcol.Superellipsoid(0.8, 0.3, 0.2, 1.0)
    R0 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    p1 = [1.0, -0.1, 0.3] if impact else [-1.5, 3.0, 0.1]
    return idcol.time_of_impact(a, b, R0, [-1.5, 0.2, 0.1], np.eye(3), p1)


def _toi_batch():
    a = idcol.Sphere(0.3)
    R = np.repeat(np.eye(3)[None], 4, 0)
    p0 = np.array([[2.0, 0.0, 0.0], [2.0, np.nan, 0.0], [2.0, 0.1, 0.0], [2.0, 5.0, 0.0]])
    return idcol.time_of_impact_batch(a, a, R, p0, R, p0 - [4.0, 0.0, 0.0])


def _results():
    """Every result type, each computed twice from the same input."""
    s = paper_shapes()
    p = np.random.default_rng(4).uniform(-3, 3, (6, 3))
    R6 = np.repeat(np.eye(3)[None], 6, 0)
    return [
        ("solve", lambda: idcol.solve(s["SE"], s["TC"], np.eye(3), [3.0, 0.5, 0.0])),
        ("solve-derivatives", lambda: idcol.solve(s["SE"], s["TC"], np.eye(3), [3.0, 0.5, 0.0], derivatives=True)),
        ("concentric", lambda: idcol.solve(s["SE"], s["TC"], np.eye(3), [0.0, 0.0, 0.0])),
        ("separated", lambda: idcol.solve(s["SE"], s["TC"], np.eye(3), [30.0, 0.5, 0.0], alpha_max=2.0)),
        ("toi-impact", _toi),
        ("toi-no-impact", lambda: _toi(impact=False)),
        ("batch", lambda: idcol.solve_batch(s["SE"], s["TC"], R6, p, derivatives=True, R_W1=np.eye(3),
                                            p_W1=np.ones(3))),
        ("toi-batch", _toi_batch),
    ]


def _holds_bytes(obj):
    if isinstance(obj, (bytes, bytearray)):
        return True
    if isinstance(obj, dict):
        return any(_holds_bytes(v) for v in obj.values())
    if isinstance(obj, (tuple, list)):
        return any(_holds_bytes(v) for v in obj)
    return False


@pytest.mark.parametrize("name, make", _results(), ids=lambda x: x if isinstance(x, str) else "")
def test_a_pickle_is_the_result_alone(name, make):
    """The state is the result's fields (no raw memory, in which padding and
    an unused factorisation would be whatever the stack held): two
    computations of the same result pickle to the same bytes, at every
    protocol, and so does the copy read back."""
    r1, r2 = make(), make()
    assert not _holds_bytes(r1.__reduce__())
    for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
        b1 = pickle.dumps(r1, protocol=protocol)
        assert b1 == pickle.dumps(r2, protocol=protocol)
        assert b1 == pickle.dumps(pickle.loads(b1), protocol=protocol)


def test_toi_result_round_trips_every_field():
    for r in (_toi(), _toi(impact=False)):
        for c in [pickle.loads(pickle.dumps(r, protocol=k)) for k in range(pickle.HIGHEST_PROTOCOL + 1)] + \
                [copy.deepcopy(r), copy.copy(r)]:
            assert type(c) is idcol.ToiResult and repr(c) == repr(r)
            for f in ("status", "t", "t_free", "alpha_rate", "has_derivatives", "solves", "probes"):
                assert getattr(c, f) == getattr(r, f), f
            for f in ("R", "p", "dt_dX0", "dt_dX1"):
                assert np.array_equal(getattr(c, f), getattr(r, f)), f
            assert repr(c.contact) == repr(r.contact) and c.contact.has_derivatives == r.contact.has_derivatives
            if r.contact.has_derivatives:
                assert np.array_equal(idcol.alpha_gradient(c.contact), idcol.alpha_gradient(r.contact))
    assert _toi().status == idcol.ToiStatus.Impact and _toi().has_derivatives
    assert _toi(impact=False).status == idcol.ToiStatus.NoImpact


def test_toi_batch_result_round_trips_read_only_with_its_errors():
    out = _toi_batch()
    assert list(out.status) == [idcol.ToiStatus.Impact, idcol.ToiStatus.InvalidInput, idcol.ToiStatus.Impact,
                                idcol.ToiStatus.NoImpact]
    for c in (pickle.loads(pickle.dumps(out)), copy.deepcopy(out)):
        assert repr(c) == repr(out) and c.errors == out.errors and len(c) == 4
        for f in ("status", "t", "t_free", "alpha", "solves", "has_derivatives", "dt_dX0", "dt_dX1"):
            assert np.array_equal(getattr(c, f), getattr(out, f), equal_nan=True), f
            assert not getattr(c, f).flags.writeable, f


def _state(obj):
    fn, args = obj.__reduce__()
    return fn, copy.deepcopy(args)


def _solve_state():
    a, b = paper_shapes()["SE"], paper_shapes()["TC"]
    return _state(idcol.solve(a, b, np.eye(3), [3.0, 0.5, 0.0], derivatives=True))


DELETE = object()
SOLVE_RESULT_ATTACKS = [
    ({"lu_rows": (0, 1, 2, 3, 4, 2**31 - 1)}, r"'lu_rows' \[5\] must be an int in \[0, 5\], got 2147483647"),
    ({"lu_rows": (0, 0, 1, 2, 3, 4)}, r"'lu_rows' must be a permutation of 0\.\.5"),
    ({"lu_rows": (0, 1, 2, 3, 4)}, r"'lu_rows' must be a tuple of 6 ints"),
    ({"lu_factors": (1.0,) * 35}, r"'lu_factors' must be a tuple of 36 floats, got tuple of 35"),
    ({"lu_factors": None}, r"'lu_factors' must be a tuple of 36 floats, got NoneType"),
    ({"status": 99}, r"'status' must be an int in \[0, 7\], got 99"),
    ({"status": -1}, r"'status' must be an int in \[0, 7\], got -1"),
    ({"status": True}, r"'status' must be an int in \[0, 7\], got True"),
    ({"status": 2}, r"'factorised' is True but status is IterationLimit"),
    ({"iterations": -5}, r"'iterations' must be an int in \[0, 2147483647\], got -5"),
    ({"restarts": 2**40}, r"'restarts' must be an int in \[0, 2147483647\]"),
    ({"alpha": float("nan")}, r"'alpha' of a Converged result must be finite and > 0, got nan"),
    ({"alpha": -1.0}, r"'alpha' of a Converged result must be finite and > 0, got -1\.0"),
    ({"lambda2": 0.0}, r"'lambda2' of a Converged result must be finite and > 0, got 0\.0"),
    ({"x": (1.0, 2.0)}, r"'x' must be a tuple of 3 floats, got tuple of 2"),
    ({"x": (1.0, 2.0, float("inf"))}, r"'x' of a Converged result must be finite"),
    ({"alpha": "1.5"}, r"'alpha' must be a float, got '1\.5'"),
    ({"used_barrier": 1}, r"'used_barrier' must be True or False, got 1"),
    ({"R": np.eye(3)}, r"'R' must be a tuple of 9 floats, got ndarray"),
    ({"alpha": DELETE}, r" lacks 'alpha'"),
    ({"extra": 1.0}, r" has an unknown field 'extra'"),
]


@pytest.mark.parametrize("change, message", SOLVE_RESULT_ATTACKS, ids=lambda x: str(x)[:40])
def test_a_crafted_solve_result_state_is_refused_naming_the_field(change, message):
    """A pickle is code that runs: a state that no solve produces (a row
    order that indexes out of the factorisation, a status past the enum, a
    Converged result that is not an answer) is a ValueError naming the
    field, never a result whose derivatives read outside their arrays."""
    fn, (state,) = _solve_state()
    for k, v in change.items():
        if v is DELETE:
            del state[k]
        else:
            state[k] = v
    with pytest.raises(ValueError, match="^SolveResult state.*" + message):
        fn(state)


def test_a_restored_solve_result_answers_as_the_original():
    fn, (state,) = _solve_state()
    r = fn(state)
    a, b = paper_shapes()["SE"], paper_shapes()["TC"]
    res = idcol.solve(a, b, np.eye(3), [3.0, 0.5, 0.0], derivatives=True)
    assert np.array_equal(idcol.alpha_gradient(r), idcol.alpha_gradient(res))
    assert np.array_equal(idcol.solution_sensitivity(r).dz_dxi, idcol.solution_sensitivity(res).dz_dxi)
    assert idcol.conditioning(r).pivot_ratio == idcol.conditioning(res).pivot_ratio


TOI_RESULT_ATTACKS = [
    ({"status": 5}, r"'status' must be an int in \[0, 4\], got 5"),
    ({"t": 1.5}, r"'t' must be in \[0, 1\], got 1\.5"),
    ({"t_free": float("nan")}, r"'t_free' must be in \[0, 1\], got nan"),
    ({"probes": 10**6}, r"'probes' must be an int in \[0, \d+\], got 1000000"),
    ({"solves": -1}, r"'solves' must be an int in \[0, 2147483647\], got -1"),
    ({"status": 1}, r"'has_derivatives' is True but status is not Impact"),
    ({"dt_dX0": (0.0,) * 5}, r"'dt_dX0' must be a tuple of 6 floats"),
    ({"contact": {"status": 0}}, r": 'contact' lacks 'alpha'"),
    ({"contact": None}, r": 'contact' must be a dict, got NoneType"),
]


@pytest.mark.parametrize("change, message", TOI_RESULT_ATTACKS, ids=lambda x: str(x)[:40])
def test_a_crafted_toi_result_state_is_refused_naming_the_field(change, message):
    fn, (state,) = _state(_toi())
    state.update(change)
    with pytest.raises(ValueError, match="^ToiResult state.*" + message):
        fn(state)
    fn, (state,) = _state(_toi())
    state["contact"]["lu_rows"] = (5, 4, 3, 2, 1, 7)
    with pytest.raises(ValueError, match=r"^ToiResult state: 'contact': 'lu_rows' \[5\] must be an int in \[0, 5\]"):
        fn(state)


def _batch_state():
    s = paper_shapes()
    out = idcol.solve_batch(s["SE"], s["TC"], np.repeat(np.eye(3)[None], 2, 0), [[3.0, 0.5, 0.0], [0.0, 3.0, 0.5]],
                            derivatives=True)
    return _state(out)


BATCH_ATTACKS = [
    ({"converged": np.array([1, 1])}, r"'converged' must have dtype bool, got int64"),
    ({"alpha": np.array([1.0, 2.0], ">f8")}, r"'alpha' must have dtype float64, got >f8"),
    ({"x": np.zeros((2, 2))}, r"'x' must have shape \(2, 3\), got \(2, 2\)"),
    ({"dp1_dxi": np.zeros((2, 3, 5))}, r"'dp1_dxi' must have shape \(2, 3, 6\), got \(2, 3, 5\)"),
    ({"status": np.array([0, 42], np.int32)}, r"'status'\[1\] = 42 is not a SolveStatus code \(0\.\.7\)"),
    ({"status": np.array([0, 2], np.int32)}, r"'converged'\[1\] disagrees with 'status'\[1\]"),
    ({"iterations": np.array([3, -1], np.int32)}, r"'iterations'\[1\] = -1 is negative"),
    ({"alpha": None}, r"'alpha' must be an array, got None"),
    ({"alpha": [1.0, 2.0]}, r"'alpha' must be a NumPy array, got list"),
    ({"normal": None}, r"the fields of 'gap' come together"),
    ({"dgap_dxi": None, "dnormal_dxi": None, "dp1_dxi": None, "dp2_dxi": None},
     r"'dgap_dxi' must be given exactly when 'gap' and 'dalpha_dxi' are"),
    ({"normal_W": np.zeros((2, 3)), "p1_W": np.zeros((2, 3)), "p2_W": np.zeros((2, 3))},
     r"'dnormal_W_dxi' must be given exactly when 'normal_W' and 'dalpha_dxi' are"),
    ({"extra": np.zeros(2)}, r" has an unknown field 'extra'"),
    ({"p2": DELETE}, r" lacks 'p2'"),
]


@pytest.mark.parametrize("change, message", BATCH_ATTACKS, ids=lambda x: str(x)[:40])
def test_a_crafted_batch_result_state_is_refused_naming_the_field(change, message):
    fn, (state,) = _batch_state()
    for k, v in change.items():
        if v is DELETE:
            del state[k]
        else:
            state[k] = v
    with pytest.raises(ValueError, match="^BatchResult state.*" + message):
        fn(state)


TOI_BATCH_ATTACKS = [
    ({"status": np.array([0, 5, 9, 1], np.int32)}, r"'status'\[2\] = 9 is not a ToiStatus code \(0\.\.5\)"),
    ({"t": np.zeros(4, np.float32)}, r"'t' must have dtype float64, got float32"),
    ({"dt_dX1": np.zeros((4, 3))}, r"'dt_dX1' must have shape \(4, 6\), got \(4, 3\)"),
    ({"solves": np.array([1, 0, -3, 2], np.int32)}, r"'solves'\[2\] = -3 is negative"),
    ({"has_derivatives": np.array([True, False, True, True])},
     r"'has_derivatives'\[3\] is True on a row that is not an Impact"),
    ({"errors": {}}, r"'errors' holds 0 messages for 1 InvalidInput rows"),
    ({"errors": {1: "x", 2: "y"}}, r"'errors' must map each InvalidInput row to its message"),
    ({"errors": {1: b"x"}}, r"'errors' must map each InvalidInput row to its message"),
    ({"errors": {7: "x"}}, r"'errors' must map each InvalidInput row to its message"),
    ({"errors": [(1, "x")]}, r"'errors' must be a dict \{row: message\}, got list"),
]


@pytest.mark.parametrize("change, message", TOI_BATCH_ATTACKS, ids=lambda x: str(x)[:40])
def test_a_crafted_toi_batch_state_is_refused_naming_the_field(change, message):
    fn, (arrays, errors) = _state(_toi_batch())
    assert errors == {1: "p0[1][1] = nan is not finite"}
    for k, v in change.items():
        if k == "errors":
            errors = v
        else:
            arrays[k] = v
    with pytest.raises(ValueError, match="^ToiBatchResult state.*" + message):
        fn(arrays, errors)


@pytest.mark.parametrize("index, value, message", [
    (0, 1, r"'valid' must be True or False, got 1"),
    (5, 3, r"'history' must be 0, 1 or 2, got 3"),
    (2, 0.0, r"'length' must be finite and > 0 when valid, got 0\.0"),
    (1, np.full(6, np.nan), r"'z' must be finite when valid"),
    (3, np.full(6, np.inf), r"'z_prev\[0\]' must be finite \(history 2\)"),
    (1, np.zeros(5), r"'z' must have shape \(6,\)"),
])
def test_a_crafted_warm_start_state_is_refused_naming_the_field(index, value, message):
    a, b = paper_shapes()["SE"], paper_shapes()["TC"]
    ws = idcol.WarmStart()
    for k in range(4):
        idcol.solve(a, b, np.eye(3), [3.0, 0.1 * k, 0.0], warm_start=ws)
    state = list(ws.__getstate__())
    assert state[0] is True and state[5] == 2
    state[index] = value
    with pytest.raises(ValueError, match="WarmStart state.*" + message):
        idcol.WarmStart.__new__(idcol.WarmStart).__setstate__(tuple(state))
    state = list(idcol.WarmStart().__getstate__())
    state[5] = 1
    with pytest.raises(ValueError, match=r"'history' must be 0 when not valid, got 1"):
        idcol.WarmStart.__new__(idcol.WarmStart).__setstate__(tuple(state))


def test_every_protocol_pickles_or_refuses_every_object():
    """Protocols 0 and 1 too: the objects that pickle round-trip, those that
    do not (derived results: pickle what they came from) raise TypeError,
    never reach the copyreg fallback that aborted the interpreter."""
    s = paper_shapes()
    res = idcol.solve(s["SE"], s["TC"], np.eye(3), [3.0, 0.5, 0.0], derivatives=True)
    picklable = [s["SE"], s["Poly"], idcol.SolverOptions(tolerance=1e-11), idcol.HertzModel(2.0, 1.2),
                 idcol.WarmStart(), idcol.ContactPair(s["SE"], s["TC"]), res, _toi(),
                 idcol.ToiOptions(t_tolerance=1e-8, solver=idcol.SolverOptions(tolerance=1e-11)),
                 idcol.solve_batch(s["SE"], s["TC"], np.eye(3)[None], [[3.0, 0.5, 0.0]]), _toi_batch()]
    sens = idcol.shape_sensitivity(res, s["SE"], s["TC"], 1)
    derived = [idcol.conditioning(res), idcol.solution_sensitivity(res), idcol.contact_kinematics(res),
               idcol.contact_wrench(res), sens, idcol.shape_kinematics_derivatives(res, sens),
               idcol.shape_wrench_derivatives(res, sens)]
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        for obj in picklable:
            assert repr(pickle.loads(pickle.dumps(obj, protocol=protocol))) == repr(obj), (obj, protocol)
        for obj in derived:
            with pytest.raises(TypeError, match="cannot be pickled; pickle the SolveResult"):
                pickle.dumps(obj, protocol=protocol)

"""solve_batch against the loop of single solves, bit for bit; thread-count
independence; mixed shape pairs; array layouts and bad input."""
import numpy as np
import pytest

import idcol
from _helpers import paper_poses, paper_shapes, radial_range, random_poses

N = 3000


def loop(a, b, R, p, warm=False, chain=1024, options=None):
    """The serial loop solve_batch documents, with single solves."""
    alpha, x, status, its = np.empty(len(p)), np.empty((len(p), 3)), np.empty(len(p), np.int32), np.empty(len(p), np.int32)
    pair = None
    for k in range(len(p)):
        ak = a[k] if isinstance(a, list) else a
        bk = b[k] if isinstance(b, list) else b
        if warm:
            if k % chain == 0 or pair is None or pair.body1 is not ak or pair.body2 is not bk:
                pair = idcol.ContactPair(ak, bk, options=options)
            res = pair.solve(R[k], p[k])
        else:
            res = idcol.solve(ak, bk, R[k], p[k], options=options)
        alpha[k], x[k], status[k], its[k] = res.alpha, res.x, int(res.status), res.iterations
    return alpha, x, status, its


def same(out, ref):
    alpha, x, status, its = ref
    return (np.array_equal(out.alpha, alpha) and np.array_equal(out.x, x) and np.array_equal(out.status, status)
            and np.array_equal(out.iterations, its))


@pytest.fixture(scope="module")
def sweep():
    s = paper_shapes()
    a, b = s["SE"], s["Poly"]
    R, p = paper_poses(N, *radial_range(a, b))
    return a, b, R, p


def test_cold_batch_equals_loop_for_every_thread_count(sweep):
    a, b, R, p = sweep
    ref = loop(a, b, R, p)
    assert np.count_nonzero(ref[2] == idcol.SolveStatus.Converged) == N
    for threads in (1, 2, 3, 0):
        out = idcol.solve_batch(a, b, R, p, threads=threads)
        assert same(out, ref), threads
        assert out.alpha.shape == (N,) and out.x.shape == (N, 3) and out.status.dtype == np.int32
        assert out.converged.all() and out.dalpha_dxi is None and len(out) == N


def test_warm_batch_equals_contact_pair_loop_and_ignores_threads(sweep):
    a, b, R, p = sweep
    ref = loop(a, b, R, p, warm=True, chain=500)
    cold = loop(a, b, R, p)
    assert ref[3].sum() < cold[3].sum()   # the warm start is used
    for threads in (1, 2, 5):
        assert same(idcol.solve_batch(a, b, R, p, warm_start=True, threads=threads, warm_chain=500), ref), threads


def test_derivatives_equal_alpha_gradient(sweep):
    a, b, R, p = sweep
    opt = idcol.SolverOptions(derivatives=True)
    out = idcol.solve_batch(a, b, R, p, derivatives=True, threads=2)
    assert out.dalpha_dxi.shape == (N, 6)
    for k in range(0, N, 37):
        res = idcol.solve(a, b, R[k], p[k], options=opt)
        assert np.array_equal(out.dalpha_dxi[k], idcol.alpha_gradient(res))
    # And the same with tighter options passed through.
    tight = idcol.SolverOptions(tolerance=1e-13)
    o2 = idcol.solve_batch(a, b, R[:50], p[:50], options=tight)
    assert same(o2, loop(a, b, R[:50], p[:50], options=tight))


def test_mixed_pairs_as_lists_of_shapes_and_of_tuples():
    rng = np.random.default_rng(9)
    shapes = list(paper_shapes().values()) + [idcol.Sphere(R=0.7), idcol.Superellipsoid(0.5, 1.0, 1.5, 1)]
    n = 1200
    a = [shapes[i] for i in np.repeat(rng.integers(0, len(shapes), n // 40), 40)]
    b = [shapes[i] for i in rng.integers(0, len(shapes), n)]
    R, p = random_poses(rng, n, 0.3, 6.0)
    for warm in (False, True):
        ref = loop(a, b, R, p, warm=warm, chain=128)
        assert np.count_nonzero(ref[2] == idcol.SolveStatus.Converged) >= n - 5
        for threads in (1, 2):
            assert same(idcol.solve_batch(a, b, R, p, warm_start=warm, threads=threads, warm_chain=128), ref)
            assert same(idcol.solve_batch(list(zip(a, b)), R, p, warm_start=warm, threads=threads, warm_chain=128), ref)
    # A NumPy object array of shapes, and one shape against a list.
    arr = np.empty(n, dtype=object)
    arr[:] = a
    assert same(idcol.solve_batch(arr, b, R, p), loop(a, b, R, p))
    assert same(idcol.solve_batch(shapes[0], b, R, p), loop(shapes[0], b, R, p))


def test_layouts_are_converted(sweep):
    a, b, R, p = sweep
    ref = idcol.solve_batch(a, b, R[:200], p[:200])
    RF = np.asfortranarray(R[:200])
    pT = np.ascontiguousarray(p[:200].T).T          # a non-contiguous view
    assert not RF.flags.c_contiguous and not pT.flags.c_contiguous
    out = idcol.solve_batch(a, b, RF, pT)
    assert np.array_equal(out.alpha, ref.alpha)
    every_other = idcol.solve_batch(a, b, R[:400:2], p[:400:2])
    assert np.array_equal(every_other.alpha, idcol.solve_batch(a, b, R[:400:2].copy(), p[:400:2].copy()).alpha)
    ints = idcol.solve_batch(idcol.Sphere(1.0), idcol.Sphere(1.0), np.repeat(np.eye(3, dtype=int)[None], 3, 0),
                             np.array([[3, 0, 0], [0, 4, 0], [0, 0, 0]]))
    assert list(ints.alpha[:2]) == [1.5, 2.0] and ints.status[2] == idcol.SolveStatus.Concentric
    empty = idcol.solve_batch(a, b, np.zeros((0, 3, 3)), np.zeros((0, 3)), derivatives=True)
    assert empty.alpha.shape == (0,) and empty.dalpha_dxi.shape == (0, 6)


def test_bad_rows_are_statuses(sweep):
    a, b, R, p = sweep
    R, p = R[:10].copy(), p[:10].copy()
    p[3, 1] = np.nan
    R[6] *= 2.0
    out = idcol.solve_batch(a, b, R, p, derivatives=True)
    assert [idcol.SolveStatus(s) for s in out.status[[3, 6]]] == [idcol.SolveStatus.InvalidInput] * 2
    assert out.converged.sum() == 8
    assert not out.dalpha_dxi[[3, 6]].any()


@pytest.mark.parametrize("R_W1, p_W1, message", [
    (2 * np.eye(3), np.zeros(3), r"^R_W1 is not a rotation: \|\|R\^T R - I\|\|_F = 5\.2 > 1e-09"),
    (np.full((3, 3), np.nan), np.zeros(3), r"^R_W1\[0, 0\] = nan is not finite \(body 1's world pose\)$"),
    (np.diag([-1.0, 1.0, 1.0]), np.zeros(3), r"^R_W1 has determinant -1\.0: a reflection, not a rotation"),
    (np.eye(3), [0.0, np.inf, 0.0], r"^p_W1\[1\] = inf is not finite"),
    (np.stack([np.eye(3), np.eye(3) * 1.001, np.eye(3)]), np.zeros((3, 3)), r"^R_W1\[1\] is not a rotation"),
    (np.repeat(np.eye(3)[None], 3, 0), [[0, 0, 0], [0, 0, 0], [0, 0, np.nan]], r"^p_W1\[2\]\[2\] = nan is not"),
])
def test_a_bad_world_pose_is_a_value_error_naming_it(R_W1, p_W1, message):
    """R_W1, p_W1 turn every row's answer into the world frame: a scaled,
    reflected or NaN rotation would give Converged rows with normals that
    are not unit or not normals; it is refused, named, before any row runs."""
    s = idcol.Sphere(1.0)
    R, p = np.repeat(np.eye(3)[None], 3, 0), [[3.0, 0, 0], [0, 3.0, 0], [0, 0, 3.0]]
    with pytest.raises(ValueError, match=message):
        idcol.solve_batch(s, s, R, p, R_W1=R_W1, p_W1=p_W1)
    # A float32 rotation within its precision is re-orthonormalised, as R is.
    Rz = np.array([[0.6, -0.8, 0.0], [0.8, 0.6, 0.0], [0.0, 0.0, 1.0]], np.float32)
    out = idcol.solve_batch(s, s, R, p, R_W1=Rz, p_W1=np.zeros(3))
    assert out.converged.all() and np.allclose(np.linalg.norm(out.normal_W, axis=1), 1.0, atol=1e-15)


@pytest.mark.parametrize("call, error, pattern", [
    (lambda a, R, p: idcol.solve_batch(a, a, R[:, :2], p), ValueError, r"R must have shape \(N, 3, 3\), got \(5, 2, 3\)"),
    (lambda a, R, p: idcol.solve_batch(a, a, R, p[:4]), ValueError, r"R holds 5 poses but p holds 4"),
    (lambda a, R, p: idcol.solve_batch(a, a, R, p.ravel()), ValueError, r"p must have shape \(N, 3\), got \(15,\)"),
    (lambda a, R, p: idcol.solve_batch(a, a, R.astype(complex), p), TypeError, r"R must hold real numbers.*complex128"),
    (lambda a, R, p: idcol.solve_batch(a, a, R, [["x"] * 3] * 5), TypeError, r"p must hold real numbers"),
    (lambda a, R, p: idcol.solve_batch(a, a, R, p, threads=-1), ValueError, r"'threads' must be >= 0.*got -1"),
    (lambda a, R, p: idcol.solve_batch(a, a, R, p, warm_chain=0), ValueError, r"warm_chain must be >= 1, got 0"),
    (lambda a, R, p: idcol.solve_batch([a] * 4, a, R, p), ValueError, r"a holds 4 shapes but R and p hold 5 poses"),
    (lambda a, R, p: idcol.solve_batch(a, [a, a, 3, a, a], R, p), TypeError, r"b\[2\] must be an idcol shape"),
    (lambda a, R, p: idcol.solve_batch([(a, a)] * 4, R, p), ValueError, r"pairs holds 4 pairs but R and p hold 5"),
    (lambda a, R, p: idcol.solve_batch([(a, a)] * 4 + [a], R, p), TypeError, r"pairs\[4\] must be an \(a, b\) tuple"),
    (lambda a, R, p: idcol.solve_batch(a, a, R, p, options=idcol.HertzModel()), TypeError, r"options must be"),
])
def test_bad_input_is_a_clear_error(call, error, pattern):
    a = idcol.Sphere(R=1.0)
    R, p = np.repeat(np.eye(3)[None], 5, 0), np.ones((5, 3))
    with pytest.raises(error, match=pattern):
        call(a, R, p)


def test_concurrent_batches_from_python_threads(sweep):
    """The GIL is released during a batch: batches started from several
    Python threads at once run side by side and each gets the loop's answer."""
    import threading
    a, b, R, p = sweep
    ref = idcol.solve_batch(a, b, R, p, threads=1)
    got = [None] * 4

    def work(i):
        got[i] = idcol.solve_batch(a, b, R, p, threads=1 + i % 2)

    ts = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert all(g is not None and np.array_equal(g.alpha, ref.alpha) and np.array_equal(g.status, ref.status)
               for g in got)

"""Poses of any real dtype and any memory layout: float32 and float16
rotations are re-orthonormalised within their precision (and refused beyond
it, naming the row), integers are converted exactly, complex and object
arrays are refused; every layout gives the float64 C-contiguous answer."""
import numpy as np
import pytest
import scipy.spatial.transform

import idcol

from _helpers import paper_shapes


def random_poses(n, seed):
    rng = np.random.default_rng(seed)
    R = scipy.spatial.transform.Rotation.random(n, random_state=seed).as_matrix()
    p = rng.uniform(-4.0, 4.0, (n, 3))
    return R, p


@pytest.fixture(scope="module")
def pair():
    s = paper_shapes()
    return s["SE"], s["TC"]


@pytest.mark.parametrize("dtype, tol", [(np.float32, 1e-5), (np.float16, 3e-2)])
def test_narrow_float_poses_converge_and_match_the_rounded_float64_pose(pair, dtype, tol):
    """float32 poses (PyTorch, ROS) converge; the answer is that of the
    float64 pose the narrow one rounds, to the precision of the type."""
    a, b = pair
    R, p = random_poses(200, 1)
    out = idcol.solve_batch(a, b, R.astype(dtype), p.astype(dtype))
    ref = idcol.solve_batch(a, b, R, p.astype(dtype).astype(np.float64))
    assert out.converged.all()
    # The rotation moved by at most the rounding of the narrow type.
    assert np.max(np.abs(out.alpha - ref.alpha) / ref.alpha) < tol
    # The same row through solve: identical to the batch (same conversion).
    for k in (0, 57, 199):
        r = idcol.solve(a, b, R[k].astype(dtype), p[k].astype(dtype))
        assert r.converged and r.alpha == out.alpha[k]


def test_float32_rotation_is_orthonormalised_to_double_precision(pair):
    """After conversion the rotation is orthonormal to 1e-15, far inside
    the solver's check (1e-9), so the status is not InvalidInput."""
    a, b = pair
    R, p = random_poses(50, 2)
    R32 = R.astype(np.float32)
    dev = np.linalg.norm(np.einsum("kji,kjl->kil", R32.astype(np.float64), R32.astype(np.float64)) - np.eye(3),
                         axis=(1, 2))
    assert dev.max() > 1e-9  # without the projection the solver would refuse these
    out = idcol.solve_batch(a, b, R32, p)
    assert not np.any(out.status == idcol.SolveStatus.InvalidInput)


@pytest.mark.parametrize("dtype", [np.int8, np.int16, np.int32, np.int64])
def test_integer_poses_are_converted_exactly(pair, dtype):
    a, b = pair
    R = np.array([np.eye(3), [[0, -1, 0], [1, 0, 0], [0, 0, 1]], [[1, 0, 0], [0, 0, -1], [0, 1, 0]]])
    p = np.array([[3, 1, 0], [0, 4, 1], [2, 2, 2]])
    out = idcol.solve_batch(a, b, R.astype(dtype), p.astype(dtype))
    ref = idcol.solve_batch(a, b, R.astype(float), p.astype(float))
    assert np.array_equal(out.alpha, ref.alpha) and out.converged.all()
    assert idcol.solve(a, b, R[1].astype(dtype), p[1].astype(dtype)).alpha == ref.alpha[1]
    assert np.array_equal(idcol.solve_batch(a, b, R, p.astype(np.uint8)).alpha, ref.alpha)


def test_longdouble_poses_are_converted(pair):
    a, b = pair
    R, p = random_poses(20, 3)
    out = idcol.solve_batch(a, b, R.astype(np.longdouble), p.astype(np.longdouble))
    assert np.array_equal(out.alpha, idcol.solve_batch(a, b, R, p).alpha)


@pytest.mark.parametrize("dtype, row", [(np.float32, 7), (np.float16, 0)])
def test_narrow_rotation_beyond_its_precision_is_a_value_error_naming_the_row(pair, dtype, row):
    a, b = pair
    R, p = random_poses(10, 4)
    R[row] = R[row] @ np.diag([1.0, 1.0, 1.1])  # 10% stretch: not a rotation at any precision
    with pytest.raises(ValueError, match=r"R\[%d\] is not a rotation to %s precision: \|\|R\^T R - I\|\|_F = 0\.2"
                       % (row, np.dtype(dtype).name)):
        idcol.solve_batch(a, b, R.astype(dtype), p)
    with pytest.raises(ValueError, match=r"R is not a rotation to %s precision" % np.dtype(dtype).name):
        idcol.solve(a, b, R[row].astype(dtype), p[row])


def test_narrow_rotation_just_past_the_tolerance_is_refused(pair):
    """The tolerance is 16 float32 epsilons (1.9e-6): 1e-5 off is refused,
    1e-7 off is accepted."""
    a, b = pair
    R = np.eye(3)
    ok = (R @ np.diag([1.0, 1.0, 1.0 + 1e-7])).astype(np.float32)
    bad = (R @ np.diag([1.0, 1.0, 1.0 + 1e-5])).astype(np.float32)
    assert idcol.solve(a, b, ok, [3.0, 0.5, 0.0]).converged
    with pytest.raises(ValueError, match=r"> 1\.9\d*e-06"):
        idcol.solve(a, b, bad, [3.0, 0.5, 0.0])


def test_float64_bad_rotation_is_an_error_for_one_query_and_a_status_in_a_batch(pair):
    a, b = pair
    R = np.diag([1.0, 1.0, 1.1])
    with pytest.raises(ValueError, match=r"R is not a rotation: \|\|R\^T R - I\|\|_F = 0\.21 > 1e-09"):
        idcol.solve(a, b, R, [3.0, 0.5, 0.0])
    out = idcol.solve_batch(a, b, np.stack([np.eye(3), R]), [[3.0, 0.5, 0.0]] * 2)
    assert list(out.status) == [idcol.SolveStatus.Converged, idcol.SolveStatus.InvalidInput]


@pytest.mark.parametrize("bad, what", [
    (lambda R: R.astype(np.complex64), "complex64"),
    (lambda R: R.astype(object), "object"),
    (lambda R: R.astype(bool), "bool"),
])
def test_complex_object_and_bool_arrays_are_a_type_error(pair, bad, what):
    a, b = pair
    R, p = random_poses(4, 5)
    with pytest.raises(TypeError, match=r"R must hold real numbers.*%s" % what):
        idcol.solve_batch(a, b, bad(R), p)
    with pytest.raises(TypeError, match=r"R must hold real numbers.*%s" % what):
        idcol.solve(a, b, bad(R[0]), p[0])
    with pytest.raises(TypeError, match=r"p must hold real numbers.*%s" % what):
        idcol.solve(a, b, R[0], bad(p[0]))


def test_non_contiguous_and_fortran_layouts_give_the_c_contiguous_answer(pair):
    a, b = pair
    R, p = random_poses(64, 6)
    ref = idcol.solve_batch(a, b, R, p)
    # Every other row of a larger array, and column-major copies.
    R2 = np.repeat(R, 2, axis=0)[::2]
    p2 = np.repeat(p, 2, axis=0)[::2]
    assert not R2.flags.c_contiguous and not p2.flags.c_contiguous
    assert np.array_equal(idcol.solve_batch(a, b, R2, p2).alpha, ref.alpha)
    Rf, pf = np.asfortranarray(R), np.asfortranarray(p)
    assert Rf.flags.f_contiguous and not Rf.flags.c_contiguous
    assert np.array_equal(idcol.solve_batch(a, b, Rf, pf).alpha, ref.alpha)
    # Transposed views (R^T of R^T) and a float32 Fortran array.
    Rt = np.transpose(np.transpose(R, (0, 2, 1)).copy(), (0, 2, 1))
    assert np.array_equal(idcol.solve_batch(a, b, Rt, p).alpha, ref.alpha)
    out32 = idcol.solve_batch(a, b, np.asfortranarray(R.astype(np.float32)), p)
    assert out32.converged.all()
    # solve: a Fortran-ordered rotation and a strided translation.
    for k in (0, 33):
        r = idcol.solve(a, b, np.asfortranarray(R[k]), p2[k])
        assert r.alpha == ref.alpha[k]
    # The caller's arrays are never written.
    R32 = R.astype(np.float32)
    keep = R32.copy()
    idcol.solve_batch(a, b, R32, p)
    assert np.array_equal(R32, keep)

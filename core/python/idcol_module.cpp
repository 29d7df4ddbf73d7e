// The Python module `idcol`: shapes, one query, contact pairs, derivatives and
// batched queries, as NumPy arrays. Everything is a thin layer over the C++
// library; the batch releases the GIL and runs core's solve_batch. One file
// per topic (bindings.def lists them); this one holds the module body.
#include "bindings.hpp"

namespace {

const char* kModuleDoc = R"doc(iDCOL: implicit differentiable collision detection.

For two strictly convex bodies (phi(y) <= 0 in each body's own frame), with
body 2 at the relative pose X_12 = (R, p) in body 1's frame (a point y_2 of
body 2 is R @ y_2 + p in body 1), iDCOL finds the smallest common scaling
alpha* of both bodies (each about its own frame origin) at which they touch,
and the touching point x* (body-1 frame). alpha* < 1: penetration;
alpha* > 1: separation. Derivatives come from the implicit function theorem
at the solution.

Conventions used by every function here
  * Poses: R is a (3, 3) rotation, p a (3,) translation; body 2 in body 1.
  * Vectors (x, witness points, normals) are in body 1's frame.
  * Derivatives d(.)/dxi are taken w.r.t. the body twist xi = (w, v) of
    X_12, angular part FIRST: X_12(eps) = X_12 @ exp(eps xi^), so
    R -> R (I + [w]x) and p -> p + R v to first order. Columns 0-2 are w,
    columns 3-5 are v. If body 2 moves by a world translation dq with body 1
    fixed at the identity, d(.)/dq = d(.)/dxi[:, 3:] @ R.T.
  * Wrenches are ordered (moment, force), like twists.

Example
  >>> import numpy as np, idcol
  >>> a = idcol.Superellipsoid(a=0.5, b=1.0, c=1.5, n=8)
  >>> b = idcol.SmoothTruncatedCone(Rb=1.0, Rt=1.5, a=1.5, b=1.5, beta=20)
  >>> res = idcol.solve(a, b, np.eye(3), [3.0, 0.5, 0.0], derivatives=True)
  >>> res.converged, res.alpha > 1                 # separated
  (True, True)
  >>> g = idcol.alpha_gradient(res)                # (6,) d alpha*/d(w, v)
  >>> R = np.repeat(np.eye(3)[None], 1000, axis=0); p = np.random.rand(1000, 3) * 4
  >>> out = idcol.solve_batch(a, b, R, p, derivatives=True, threads=0)
  >>> out.alpha.shape, out.dalpha_dxi.shape, out.p1.shape, out.dgap_dxi.shape
  ((1000,), (1000, 6), (1000, 3), (1000, 6))

Errors: bad shape parameters, options and array shapes raise ValueError (or
TypeError for a wrong type: complex, bool or object arrays) naming the field
and the value; an array that does not fit in memory raises MemoryError. A bad
pose (a NaN or Inf entry, R not orthonormal to 1e-9 in ||R^T R - I||_F, or
det R = -1) given to solve, ContactPair, time_of_impact or as R_W1, p_W1
raises ValueError naming the argument and the entry; in the poses of a batch
it marks that row instead (SolveStatus.InvalidInput, ToiStatus.InvalidInput).
Rotations given as float32 or float16 are re-orthonormalised within 16
epsilons of their type, and refused (ValueError naming the row) beyond.

solve and solve_batch share the keywords options, derivatives, alpha_max and
warm_start. Shapes, options and results pickle (multiprocessing works), field
by field: a state that is not one raises ValueError naming the field.
)doc";

}  // namespace

PYBIND11_MODULE(_idcol, m) {
  m.doc() = kModuleDoc;
#ifdef IDCOL_VERSION
  m.attr("__version__") = IDCOL_VERSION;
#endif
#define IDCOL_BINDING(topic) idcol::python::bind_##topic(m);
#include "bindings.def"
#undef IDCOL_BINDING
}

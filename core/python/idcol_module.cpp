// The Python module `idcol`: shapes, one query, contact pairs, derivatives and
// batched queries, as NumPy arrays. Everything is a thin layer over the C++
// library; the batch releases the GIL and runs core's solve_batch.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "idcol/batch.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/shape_derivatives.hpp"
#include "idcol/solver.hpp"

namespace py = pybind11;
using namespace idcol;

namespace {

// ---------------------------------------------------------------------------
// Arrays in and out.

using CArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string shape_str(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// Any array-like of real numbers as a C-contiguous float64 array (a copy
/// only when the layout or dtype differs); anything else is a ValueError
/// naming the argument.
CArray float_array(py::handle obj, const std::string& name) {
  if (py::isinstance<py::array_t<double, py::array::c_style>>(obj)) return py::reinterpret_borrow<CArray>(obj);
  py::array a;
  try {
    a = py::module_::import("numpy").attr("asarray")(obj);
  } catch (py::error_already_set& e) {
    throw py::value_error(name + " cannot be read as an array of numbers: " + std::string(e.what()));
  }
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::value_error(name + " must hold real numbers (float64), got dtype " + std::string(py::str(a.dtype())));
  return CArray::ensure(a);
}

CArray float_array(py::handle obj, const std::string& name, std::initializer_list<py::ssize_t> want) {
  CArray a = float_array(obj, name);
  bool ok = a.ndim() == static_cast<py::ssize_t>(want.size());
  py::ssize_t i = 0;
  for (py::ssize_t w : want) ok = ok && a.shape(i++) == w;
  if (!ok) {
    std::string s = "(";
    i = 0;
    for (py::ssize_t w : want) s += (i++ ? ", " : "") + std::to_string(w);
    throw py::value_error(name + " must have shape " + s + (want.size() == 1 ? ",)" : ")") + ", got " + shape_str(a));
  }
  return a;
}

Vec3 to_vec3(py::handle obj, const std::string& name) {
  const CArray a = float_array(obj, name, {3});
  return Vec3(a.data()[0], a.data()[1], a.data()[2]);
}

Mat3 to_mat3(py::handle obj, const std::string& name) {
  const CArray a = float_array(obj, name, {3, 3});
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(a.data());
}

std::vector<Vec3> to_points(py::handle obj, const std::string& name) {
  const CArray a = float_array(obj, name);
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(name + " must have shape (m, 3), got " + shape_str(a));
  std::vector<Vec3> v(static_cast<std::size_t>(a.shape(0)));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = Vec3(a.data()[3 * i], a.data()[3 * i + 1], a.data()[3 * i + 2]);
  return v;
}

/// A fixed-size Eigen object as a fresh NumPy array: vectors (and 1 x n
/// rows) as 1-D, matrices as 2-D, row-major.
template <class M>
py::array_t<double> to_numpy(const Eigen::MatrixBase<M>& m) {
  if (m.rows() == 1 || m.cols() == 1) {
    py::array_t<double> a(m.size());
    for (Eigen::Index i = 0; i < m.size(); ++i) a.mutable_data()[i] = m(i);
    return a;
  }
  py::array_t<double> a({m.rows(), m.cols()});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(a.mutable_data(), m.rows(), m.cols()) = m;
  return a;
}

std::string num(double v) { return py::repr(py::float_(v)).cast<std::string>(); }

// ---------------------------------------------------------------------------
// Shapes. One Python class per family; all derive from idcol.Shape, which
// holds the (immutable) C++ shape.

struct PyShape {
  std::shared_ptr<const Shape> shape;
};
struct PySphere : PyShape {};
struct PySuperellipsoid : PyShape {};
struct PySuperellipticCylinder : PyShape {};
struct PySmoothPolytope : PyShape {};
struct PySmoothTruncatedCone : PyShape {};

template <class Py, class S>
Py make_shape(S s) {
  Py p;
  p.shape = std::make_shared<const Shape>(std::move(s));
  return p;
}

template <class S>
const S& family(const PyShape& p) {
  return std::get<S>(*p.shape);
}

std::string shape_repr(const Shape& s) {
  std::ostringstream os;
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, Sphere>) {
          os << "Sphere(R=" << num(x.R()) << ")";
        } else if constexpr (std::is_same_v<T, Superellipsoid>) {
          os << "Superellipsoid(a=" << num(x.a()) << ", b=" << num(x.b()) << ", c=" << num(x.c()) << ", n=" << num(x.n())
             << ")";
        } else if constexpr (std::is_same_v<T, SuperellipticCylinder>) {
          os << "SuperellipticCylinder(R=" << num(x.R()) << ", h=" << num(x.h()) << ", n=" << num(x.n()) << ")";
        } else if constexpr (std::is_same_v<T, SmoothPolytope>) {
          os << "SmoothPolytope(A=[";
          for (int i = 0; i < x.num_halfspaces(); ++i) {
            const Vec3 a = x.normal(i);
            os << (i ? ", " : "") << "[" << num(a.x()) << ", " << num(a.y()) << ", " << num(a.z()) << "]";
          }
          os << "], b=[";
          for (int i = 0; i < x.num_halfspaces(); ++i) os << (i ? ", " : "") << num(x.offset(i));
          os << "], beta=" << num(x.beta()) << ", L=" << num(x.L()) << ")";
        } else {
          os << "SmoothTruncatedCone(Rb=" << num(x.Rb()) << ", Rt=" << num(x.Rt()) << ", a=" << num(x.a())
             << ", b=" << num(x.b()) << ", beta=" << num(x.beta()) << ")";
        }
      },
      s);
  return os.str();
}

const PyShape& as_shape(py::handle obj, const std::string& name) {
  if (!py::isinstance<PyShape>(obj))
    throw py::type_error(name + " must be an idcol shape (Sphere, Superellipsoid, ...), got " +
                         std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
  return obj.cast<const PyShape&>();
}

// ---------------------------------------------------------------------------
// SolverOptions: every field, type-checked and validated on construction and
// on every assignment.

#define IDCOL_OPTION_FIELDS(X)                 \
  X(double, tolerance)                         \
  X(int, max_iterations)                       \
  X(int, max_iterations_extended)              \
  X(double, extension_residual)                \
  X(int, max_restarts)                         \
  X(double, surrogate_factor)                  \
  X(double, armijo_c)                          \
  X(double, backtrack_factor)                  \
  X(int, max_backtracks)                       \
  X(double, max_step_s)                        \
  X(double, max_step_x)                        \
  X(double, lambda_fraction_to_boundary)       \
  X(double, lambda_fraction_to_boundary_restart) \
  X(double, min_pivot_ratio)                   \
  X(double, lm_initial_damping)                \
  X(int, lm_max_trials)                        \
  X(int, lm_stall_limit)                       \
  X(double, lm_min_progress)                   \
  X(double, bound_margin)                      \
  X(bool, continuation)                        \
  X(double, continuation_ratio)                \
  X(bool, rounding_continuation)               \
  X(bool, support_guess)                       \
  X(bool, barrier)                           \
  X(double, barrier_growth)                  \
  X(int, barrier_max_stages)                 \
  X(int, barrier_max_newton)                 \
  X(double, barrier_max_step_x)              \
  X(double, barrier_handover)                \
  X(bool, warm_fallback_to_cold)               \
  X(int, warm_predictor_order)                 \
  X(bool, derivatives)                         \
  X(double, alpha_max)

template <class T>
T checked(py::handle v, const char* field) {
  const bool is_bool = py::isinstance<py::bool_>(v);
  bool ok;
  if constexpr (std::is_same_v<T, bool>) {
    ok = is_bool;
  } else if constexpr (std::is_same_v<T, int>) {
    ok = !is_bool && py::isinstance<py::int_>(v);
  } else {
    ok = !is_bool && (py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v));
  }
  if (!ok) {
    const char* want = std::is_same_v<T, bool> ? "a bool" : std::is_same_v<T, int> ? "an int" : "a float";
    throw py::type_error(std::string("SolverOptions: field '") + field + "' must be " + want + ", got " +
                         std::string(py::repr(v)));
  }
  if constexpr (std::is_same_v<T, int>) {
    const long long x = v.cast<long long>();
    if (x < -2147483647LL || x > 2147483647LL)
      throw py::value_error(std::string("SolverOptions: field '") + field + "' is out of range, got " + std::to_string(x));
    return static_cast<int>(x);
  } else {
    return v.cast<T>();
  }
}

/// Sets one field by name; false if there is no such field.
bool set_option(SolverOptions& o, const std::string& name, py::handle v) {
#define IDCOL_SET(T, f)                 \
  if (name == #f) {                     \
    o.f = checked<T>(v, #f);            \
    return true;                        \
  }
  IDCOL_OPTION_FIELDS(IDCOL_SET)
#undef IDCOL_SET
  return false;
}

std::string options_repr(const SolverOptions& o) {
  std::ostringstream os;
  os << "SolverOptions(";
  bool first = true;
#define IDCOL_REPR(T, f)                                                             \
  os << (first ? "" : ", ") << #f << "=";                                           \
  if constexpr (std::is_same_v<T, bool>) os << (o.f ? "True" : "False");           \
  else if constexpr (std::is_same_v<T, int>) os << o.f;                            \
  else os << num(static_cast<double>(o.f));                                        \
  first = false;
  IDCOL_OPTION_FIELDS(IDCOL_REPR)
#undef IDCOL_REPR
  os << ")";
  return os.str();
}

SolverOptions options_or_default(const py::object& options) {
  if (options.is_none()) return SolverOptions{};
  if (!py::isinstance<SolverOptions>(options))
    throw py::type_error("options must be an idcol.SolverOptions or None, got " +
                         std::string(py::str(py::type::handle_of(options).attr("__name__"))));
  SolverOptions o = options.cast<SolverOptions>();
  o.validate();
  return o;
}

// ---------------------------------------------------------------------------
// Contact pair, derivatives.

struct PyContactPair {
  py::object body1, body2;  // the Python shapes, returned as given
  ContactPair pair;
};

Pose to_pose(py::handle R, py::handle p) { return Pose{to_mat3(R, "R"), to_vec3(p, "p")}; }

/// Contact kinematics and (optionally) their derivatives, as one object.
struct PyKinematics {
  ContactKinematics c;
  bool has_derivatives = false;
  ContactKinematicsDerivatives d;
};

struct PyWrench {
  ContactWrench w;
  bool has_derivatives = false;
  ContactWrenchDerivatives d;
};

/// The model argument of the wrench functions: HertzModel() for None,
/// validated.
HertzModel hertz_model(const py::object& model) {
  HertzModel h;
  if (!model.is_none()) {
    if (!py::isinstance<HertzModel>(model))
      throw py::type_error("model must be an idcol.HertzModel or None, got " +
                           std::string(py::str(py::type::handle_of(model).attr("__name__"))));
    h = model.cast<HertzModel>();
  }
  h.validate();
  return h;
}

// ---------------------------------------------------------------------------
// Shape-parameter derivatives.

/// Any Eigen matrix as a 2-D NumPy array (rows, cols), even with one column
/// (a sphere's single parameter) or none (a result that did not converge).
template <class M>
py::array_t<double> to_numpy_2d(const Eigen::MatrixBase<M>& m) {
  py::array_t<double> a({m.rows(), m.cols()});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(a.mutable_data(), m.rows(), m.cols()) = m;
  return a;
}

/// Any Eigen vector or row as a 1-D NumPy array (p,), even with p = 1.
template <class M>
py::array_t<double> to_numpy_1d(const Eigen::MatrixBase<M>& m) {
  py::array_t<double> a(m.size());
  for (Eigen::Index i = 0; i < m.size(); ++i) a.mutable_data()[i] = m(i);
  return a;
}

/// A C++ shape as an instance of its Python class.
py::object wrap_shape(Shape s) {
  return std::visit(
      [](auto&& x) -> py::object {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, Sphere>)
          return py::cast(make_shape<PySphere>(std::move(x)));
        else if constexpr (std::is_same_v<T, Superellipsoid>)
          return py::cast(make_shape<PySuperellipsoid>(std::move(x)));
        else if constexpr (std::is_same_v<T, SuperellipticCylinder>)
          return py::cast(make_shape<PySuperellipticCylinder>(std::move(x)));
        else if constexpr (std::is_same_v<T, SmoothPolytope>)
          return py::cast(make_shape<PySmoothPolytope>(std::move(x)));
        else
          return py::cast(make_shape<PySmoothTruncatedCone>(std::move(x)));
      },
      std::move(s));
}

py::list name_list(const std::vector<std::string>& names) {
  py::list l;
  for (const std::string& n : names) l.append(n);
  return l;
}

/// dz*/dtheta with the result it was taken from (kept alive and compared by
/// identity, so that kinematics and wrench derivatives cannot silently mix
/// one result with another's sensitivity) and the names of its columns.
struct PyShapeSensitivity {
  ShapeSensitivity s;
  py::object res;
  std::vector<std::string> names;
};

const PyShapeSensitivity& sensitivity_of(const py::object& res, const py::handle& sens, const char* function) {
  if (!py::isinstance<PyShapeSensitivity>(sens))
    throw py::type_error(std::string(function) + ": sens must be an idcol.ShapeSensitivity, got " +
                         std::string(py::str(py::type::handle_of(sens).attr("__name__"))));
  const auto& s = sens.cast<const PyShapeSensitivity&>();
  if (!s.res.is(res))
    throw py::value_error(std::string(function) +
                          ": sens was computed from another SolveResult than res; pass the result given to "
                          "shape_sensitivity");
  return s;
}

struct PyShapeKinematics {
  ShapeKinematicsDerivatives d;
  std::vector<std::string> names;
};

struct PyShapeWrench {
  ShapeWrenchDerivatives d;
  std::vector<std::string> names;
};

// ---------------------------------------------------------------------------
// Batch.

struct PyBatchResult {
  py::array_t<double> alpha, x;
  py::array_t<std::int32_t> status, iterations;
  py::array_t<bool> converged;
  py::object dalpha_dxi = py::none();
};

/// One shape for every row, or a sequence (list, tuple, NumPy object array)
/// of N shapes.
/// `keep` holds a reference to every shape used, so that no shape can be
/// freed while the GIL is released (another thread emptying the list).
void gather(py::handle obj, const char* name, std::size_t n, std::vector<const Shape*>& out,
            std::vector<std::shared_ptr<const Shape>>& keep) {
  if (py::isinstance<PyShape>(obj)) {
    keep.push_back(obj.cast<const PyShape&>().shape);
    out.assign(1, keep.back().get());
    return;
  }
  if (!py::isinstance<py::sequence>(obj) || py::isinstance<py::str>(obj))
    throw py::type_error(std::string(name) + " must be an idcol shape or a sequence of one shape per pose, got " +
                         std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(obj);
  if (seq.size() != n)
    throw py::value_error(std::string(name) + " holds " + std::to_string(seq.size()) + " shapes but R and p hold " +
                          std::to_string(n) + " poses");
  out.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::shared_ptr<const Shape>& s = as_shape(seq[k], std::string(name) + "[" + std::to_string(k) + "]").shape;
    if (keep.empty() || keep.back() != s) keep.push_back(s);
    out[k] = s.get();
  }
}

std::pair<CArray, CArray> batch_poses(py::handle R, py::handle p) {
  CArray Ra = float_array(R, "R"), pa = float_array(p, "p");
  if (Ra.ndim() != 3 || Ra.shape(1) != 3 || Ra.shape(2) != 3)
    throw py::value_error("R must have shape (N, 3, 3), got " + shape_str(Ra));
  if (pa.ndim() != 2 || pa.shape(1) != 3) throw py::value_error("p must have shape (N, 3), got " + shape_str(pa));
  if (Ra.shape(0) != pa.shape(0))
    throw py::value_error("R holds " + std::to_string(Ra.shape(0)) + " poses but p holds " + std::to_string(pa.shape(0)));
  return {Ra, pa};
}

PyBatchResult run_batch(const std::vector<const Shape*>& b1, const std::vector<const Shape*>& b2, const CArray& R,
                        const CArray& p, bool warm_start, bool derivatives, int threads, const py::object& options,
                        long long warm_chain) {
  BatchOptions o;
  o.solver = options_or_default(options);
  o.warm_start = warm_start;
  o.derivatives = derivatives;
  o.threads = threads;
  if (warm_chain < 1) throw py::value_error("warm_chain must be >= 1, got " + std::to_string(warm_chain));
  o.warm_chain = static_cast<std::size_t>(warm_chain);
  o.validate();
  const auto n = static_cast<py::ssize_t>(p.shape(0));
  PyBatchResult r;
  r.alpha = py::array_t<double>(n);
  r.x = py::array_t<double>({n, py::ssize_t(3)});
  r.status = py::array_t<std::int32_t>(n);
  r.iterations = py::array_t<std::int32_t>(n);
  py::array_t<double> d;
  if (derivatives) d = py::array_t<double>({n, py::ssize_t(6)});
  const std::size_t N = static_cast<std::size_t>(n);
  BatchOutput out{{r.alpha.mutable_data(), N},
                  {r.x.mutable_data(), 3 * N},
                  {r.status.mutable_data(), N},
                  {r.iterations.mutable_data(), N},
                  {derivatives ? d.mutable_data() : nullptr, derivatives ? 6 * N : 0}};
  const Span<const Shape* const> s1(b1.data(), b1.size()), s2(b2.data(), b2.size());
  const Span<const double> Rs(R.data(), 9 * N), ps(p.data(), 3 * N);
  {
    py::gil_scoped_release release;
    solve_batch(s1, s2, Rs, ps, o, out);
  }
  r.converged = py::array_t<bool>(n);
  for (std::size_t k = 0; k < N; ++k)
    r.converged.mutable_data()[k] = r.status.data()[k] == static_cast<std::int32_t>(SolveStatus::Converged);
  if (derivatives) r.dalpha_dxi = d;
  return r;
}

std::string camel(const std::string& snake) {
  std::string s;
  bool up = true;
  for (char ch : snake) {
    if (ch == '_') {
      up = true;
      continue;
    }
    s += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(ch))) : ch;
    up = false;
  }
  return s;
}

const char* status_doc(const std::string& name) {
  if (name == "converged") return "The KKT conditions of the target shapes hold to SolverOptions.tolerance, lambda1, lambda2 > 0.";
  if (name == "concentric") return "r = 0 exactly: alpha* = 0, x* = 0; no normal, multipliers or derivatives.";
  if (name == "iteration_limit") return "Every run used max_iterations Newton steps without meeting the tolerance.";
  if (name == "line_search_failed") return "Backtracking and Levenberg-Marquardt made no progress (a stationary point of ||F||).";
  if (name == "numerical_failure") return "Non-finite residual or Jacobian, or an answer beyond the double range.";
  if (name == "spurious_root") return "Only KKT roots with a multiplier <= 0 or alpha outside the certified bounds were found.";
  if (name == "invalid_input") return "The pose has a NaN/Inf entry, a non-orthonormal rotation or det R = -1.";
  if (name == "separated")
    return "SolverOptions.alpha_max is finite and a certified lower bound on alpha* exceeds it; alpha holds that bound "
           "(alpha_max < alpha <= alpha*); no x, multipliers or derivatives (the derivative functions raise).";
  return "See SolveStatus in idcol/result.hpp.";
}

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
  >>> res = idcol.solve(a, b, np.eye(3), [3.0, 0.5, 0.0],
  ...                   options=idcol.SolverOptions(derivatives=True))
  >>> res.converged, res.alpha > 1                 # separated
  (True, True)
  >>> g = idcol.alpha_gradient(res)                # (6,) d alpha*/d(w, v)
  >>> R = np.repeat(np.eye(3)[None], 1000, axis=0); p = np.random.rand(1000, 3) * 4
  >>> out = idcol.solve_batch(a, b, R, p, derivatives=True, threads=0)
  >>> out.alpha.shape, out.dalpha_dxi.shape
  ((1000,), (1000, 6))

Errors: bad shape parameters, options and array shapes raise ValueError (or
TypeError for a wrong type) naming the field and the value. A bad pose (NaN,
non-orthonormal R, det R = -1) is not an exception: the result's status is
SolveStatus.InvalidInput, as for every row of a batch.
)doc";

}  // namespace

void bind_toi(py::module_& m);  // toi_bindings.cpp

PYBIND11_MODULE(idcol, m) {
  m.doc() = kModuleDoc;
#ifdef IDCOL_VERSION
  m.attr("__version__") = IDCOL_VERSION;
#endif

  // --- Status ---------------------------------------------------------------
  // Values are enumerated through to_string(), so a status added to the C++
  // enum appears here without a change to this file.
  py::enum_<SolveStatus> status(m, "SolveStatus", py::arithmetic(),
                                "Why a solve stopped (C++ idcol::SolveStatus). Only Converged and Concentric carry a "
                                "genuine answer. Batch results hold these as int32 codes: idcol.SolveStatus(code).");
  for (int i = 0; i < 256; ++i) {
    const auto s = static_cast<SolveStatus>(i);
    const std::string name = to_string(s);
    if (name == "unknown") break;
    status.value(camel(name).c_str(), s, status_doc(name));
  }
  // pybind11 compares an `enum class` only with its own type; compare with
  // any integer too, so that `batch.status == SolveStatus.Converged` works
  // element-wise on the int32 codes of a batch.
  auto same_code = [](const py::object& a, const py::object& b) -> py::object {
    if (b.is_none()) return py::bool_(false);
    PyObject* idx = PyNumber_Index(b.ptr());
    if (idx == nullptr) {
      PyErr_Clear();
      return py::reinterpret_borrow<py::object>(Py_NotImplemented);
    }
    return py::bool_(py::int_(a).equal(py::reinterpret_steal<py::object>(idx)));
  };
  // (Assigned, not def'd: def would chain after pybind11's own __eq__.)
  status.attr("__eq__") = py::cpp_function(same_code, py::is_method(status), py::name("__eq__"));
  status.attr("__ne__") = py::cpp_function(
      [same_code](const py::object& a, const py::object& b) -> py::object {
        py::object r = same_code(a, b);
        if (r.is(py::reinterpret_borrow<py::object>(Py_NotImplemented))) return r;
        return py::bool_(!r.cast<bool>());
      },
      py::is_method(status), py::name("__ne__"));

  // --- Shapes ---------------------------------------------------------------
  py::class_<PyShape>(m, "Shape",
                      "Base class of the shape families: an immutable strictly convex body phi(y) <= 0 in its own "
                      "frame. Not constructed directly.")
      .def_property_readonly("family", [](const PyShape& s) { return std::string(family_name(*s.shape)); },
                             "Family name, e.g. 'superellipsoid'.")
      .def_property_readonly(
          "radii", [](const PyShape& s) { const Radii r = radii(*s.shape); return py::make_tuple(r.inner, r.outer); },
          "(inner, outer): certified radii of balls about the frame origin inside and around the body (closed form).")
      .def(
          "eval",
          [](const PyShape& s, py::handle y) {
            ShapeEval e;
            eval(*s.shape, to_vec3(y, "y"), e);
            return py::make_tuple(e.phi, to_numpy(e.grad), to_numpy(e.hess));
          },
          py::arg("y"), "(phi, grad (3,), hess (3, 3)) at the point y (3,) of the shape's frame.")
      .def("describe", [](const PyShape& s) { return describe(*s.shape); },
           "The parameters in the scene-file form (idcol::describe), at 17 significant digits.")
      .def_property_readonly("params", [](const PyShape& s) { return to_numpy_1d(shape_params(*s.shape)); },
                             "(p,) the shape parameters theta, in the order of param_names: Sphere (R); "
                             "Superellipsoid (a, b, c, n); SuperellipticCylinder (R, h, n); SmoothTruncatedCone (Rb, "
                             "Rt, a, b, beta); SmoothPolytope (A0.x, A0.y, A0.z, b0, ..., beta) at the stored unit "
                             "rows, L held fixed.")
      .def_property_readonly("param_names", [](const PyShape& s) { return name_list(param_names(*s.shape)); },
                             "Names of params, e.g. ['a', 'b', 'c', 'n'] or ['A0.x', ..., 'b7', 'beta'].")
      .def_property_readonly(
          "param_length_powers", [](const PyShape& s) { return to_numpy_1d(param_length_powers(*s.shape)); },
          "(p,) the power of length each parameter carries (1 for lengths and offsets, 0 for n, beta, unit rows).")
      .def(
          "with_params",
          [](const PyShape& s, py::handle theta) {
            const CArray t = float_array(theta, "theta");
            const int p = num_params(*s.shape);
            if (t.ndim() != 1 || t.shape(0) != p)
              throw py::value_error("theta must have shape (" + std::to_string(p) + ",), got " + shape_str(t));
            return wrap_shape(shape_with_params(*s.shape, Eigen::Map<const VecX>(t.data(), p)));
          },
          py::arg("theta"),
          "A shape of the same family (and the same L for a polytope) with parameters theta, built and validated by "
          "its constructor (ValueError naming the field and value).")
      .def(
          "eval_params",
          [](const PyShape& s, py::handle y) {
            ShapeEval e;
            ShapeParamEval d;
            eval_params(*s.shape, to_vec3(y, "y"), e, d);
            return py::make_tuple(e.phi, to_numpy(e.grad), to_numpy(e.hess), to_numpy_1d(d.dphi),
                                  to_numpy_2d(d.dgrad));
          },
          py::arg("y"),
          "(phi, grad (3,), hess (3, 3), dphi_dtheta (p,), dgrad_dtheta (3, p)) at the point y of the shape's frame.")
      .def("__repr__", [](const PyShape& s) { return shape_repr(*s.shape); });

  py::class_<PySphere, PyShape>(m, "Sphere", "Sphere of radius R: phi(y) = |y|/R - 1.")
      .def(py::init([](double R) { return make_shape<PySphere>(Sphere(R)); }), py::arg("R"))
      .def_property_readonly("R", [](const PyShape& s) { return family<Sphere>(s).R(); });

  py::class_<PySuperellipsoid, PyShape>(
      m, "Superellipsoid",
      "Superellipsoid: phi(y) = ((y1/a)^2n + (y2/b)^2n + (y3/c)^2n)^(1/2n) - 1, n >= 1 (n = 1: an exact ellipsoid).")
      .def(py::init([](double a, double b, double c, double n) {
             return make_shape<PySuperellipsoid>(Superellipsoid(a, b, c, n));
           }),
           py::arg("a"), py::arg("b"), py::arg("c"), py::arg("n") = 1.0)
      .def_property_readonly("a", [](const PyShape& s) { return family<Superellipsoid>(s).a(); })
      .def_property_readonly("b", [](const PyShape& s) { return family<Superellipsoid>(s).b(); })
      .def_property_readonly("c", [](const PyShape& s) { return family<Superellipsoid>(s).c(); })
      .def_property_readonly("n", [](const PyShape& s) { return family<Superellipsoid>(s).n(); });

  py::class_<PySuperellipticCylinder, PyShape>(
      m, "SuperellipticCylinder",
      "Superelliptic cylinder, axis y1: phi(y) = ((y1/h)^2n + ((y2^2 + y3^2)/R^2)^n)^(1/2n) - 1, n >= 1.")
      .def(py::init([](double R, double h, double n) {
             return make_shape<PySuperellipticCylinder>(SuperellipticCylinder(R, h, n));
           }),
           py::arg("R"), py::arg("h"), py::arg("n") = 1.0)
      .def_property_readonly("R", [](const PyShape& s) { return family<SuperellipticCylinder>(s).R(); })
      .def_property_readonly("h", [](const PyShape& s) { return family<SuperellipticCylinder>(s).h(); })
      .def_property_readonly("n", [](const PyShape& s) { return family<SuperellipticCylinder>(s).n(); });

  py::class_<PySmoothPolytope, PyShape>(
      m, "SmoothPolytope",
      "Smooth polytope: phi(y) = smax_beta((A y - b) / L), the LogSumExp smooth maximum over the half-spaces "
      "A y <= b (A: (m, 3), b: (m,), m >= 4; rows normalised at construction, b scaled with them). The polytope "
      "must hold its frame origin strictly inside. The smooth body lies inside the exact polytope.")
      .def(py::init([](py::handle A, py::handle b, double beta, double L) {
             const std::vector<Vec3> rows = to_points(A, "A");
             const CArray ba = float_array(b, "b");
             if (ba.ndim() != 1 || ba.shape(0) != static_cast<py::ssize_t>(rows.size()))
               throw py::value_error("b must have shape (" + std::to_string(rows.size()) + ",) to match A, got " +
                                     shape_str(ba));
             const std::vector<double> bv(ba.data(), ba.data() + ba.shape(0));
             return make_shape<PySmoothPolytope>(SmoothPolytope(rows, bv, beta, L));
           }),
           py::arg("A"), py::arg("b"), py::arg("beta"), py::arg("L") = 1.0)
      .def_static(
          "from_vertices",
          [](py::handle V, double beta, double L) {
            return make_shape<PySmoothPolytope>(SmoothPolytope::from_vertices(to_points(V, "V"), beta, L));
          },
          py::arg("V"), py::arg("beta"), py::arg("L") = 1.0,
          "The convex hull of the vertices V (k, 3) (coplanar facets merged), smoothed with beta.")
      .def_property_readonly("A",
                             [](const PyShape& s) {
                               const auto& P = family<SmoothPolytope>(s);
                               py::array_t<double> a({py::ssize_t(P.num_halfspaces()), py::ssize_t(3)});
                               for (int i = 0; i < P.num_halfspaces(); ++i)
                                 for (int j = 0; j < 3; ++j) a.mutable_data()[3 * i + j] = P.normal(i)[j];
                               return a;
                             },
                             "(m, 3) unit normals of the half-spaces.")
      .def_property_readonly("b",
                             [](const PyShape& s) {
                               const auto& P = family<SmoothPolytope>(s);
                               py::array_t<double> a(P.num_halfspaces());
                               for (int i = 0; i < P.num_halfspaces(); ++i) a.mutable_data()[i] = P.offset(i);
                               return a;
                             },
                             "(m,) offsets of the normalised half-spaces.")
      .def_property_readonly("beta", [](const PyShape& s) { return family<SmoothPolytope>(s).beta(); })
      .def_property_readonly("L", [](const PyShape& s) { return family<SmoothPolytope>(s).L(); })
      .def_property_readonly("vertices",
                             [](const PyShape& s) {
                               const auto& V = family<SmoothPolytope>(s).vertices();
                               py::array_t<double> a({py::ssize_t(V.size()), py::ssize_t(3)});
                               for (std::size_t i = 0; i < V.size(); ++i)
                                 for (int j = 0; j < 3; ++j) a.mutable_data()[3 * i + j] = V[i][j];
                               return a;
                             },
                             "(k, 3) vertices of the exact polytope.");

  py::class_<PySmoothTruncatedCone, PyShape>(
      m, "SmoothTruncatedCone",
      "Smooth truncated cone, axis y1, base radius Rb at y1 = -a, top radius Rt at y1 = b: "
      "phi = smax_beta(r^2/R(y1)^2 - 1, -y1/a - 1, y1/b - 1), beta > log 3.")
      .def(py::init([](double Rb, double Rt, double a, double b, double beta) {
             return make_shape<PySmoothTruncatedCone>(SmoothTruncatedCone(Rb, Rt, a, b, beta));
           }),
           py::arg("Rb"), py::arg("Rt"), py::arg("a"), py::arg("b"), py::arg("beta"))
      .def_property_readonly("Rb", [](const PyShape& s) { return family<SmoothTruncatedCone>(s).Rb(); })
      .def_property_readonly("Rt", [](const PyShape& s) { return family<SmoothTruncatedCone>(s).Rt(); })
      .def_property_readonly("a", [](const PyShape& s) { return family<SmoothTruncatedCone>(s).a(); })
      .def_property_readonly("b", [](const PyShape& s) { return family<SmoothTruncatedCone>(s).b(); })
      .def_property_readonly("beta", [](const PyShape& s) { return family<SmoothTruncatedCone>(s).beta(); });

  // --- Options --------------------------------------------------------------
  {
    std::string doc =
        "Every tunable of the solver (C++ idcol::SolverOptions; the reason for each default is in "
        "idcol/options.hpp). Construct with keyword arguments, e.g. SolverOptions(tolerance=1e-12, "
        "derivatives=True). Each value is type-checked and the whole set validated at construction and on every "
        "assignment: a bad value raises ValueError (TypeError for a wrong type) naming the field and the value.\n\n"
        "derivatives=True keeps the KKT factorisation at the solution, which alpha_gradient, gap_gradient, "
        "solution_sensitivity and the derivative parts of contact_kinematics and contact_wrench read.\n\n"
        "Fields and defaults: ";
    doc += options_repr(SolverOptions{});
    py::class_<SolverOptions> opt(m, "SolverOptions", doc.c_str());
    opt.def(py::init([](const py::kwargs& kw) {
      SolverOptions o;
      for (auto item : kw) {
        const std::string name = py::str(item.first);
        if (!set_option(o, name, item.second)) throw py::type_error("SolverOptions has no field '" + name + "'");
      }
      o.validate();
      return o;
    }));
#define IDCOL_PROP(T, f)                                               \
  opt.def_property(                                                    \
      #f, [](const SolverOptions& o) { return o.f; },                  \
      [](SolverOptions& o, py::handle v) {                             \
        SolverOptions c = o;                                           \
        c.f = checked<T>(v, #f);                                       \
        c.validate();                                                  \
        o = c;                                                         \
      });
    IDCOL_OPTION_FIELDS(IDCOL_PROP)
#undef IDCOL_PROP
    opt.def("validate", &SolverOptions::validate, "Raise ValueError naming the field if any option is out of range.")
        .def("__repr__", &options_repr);
  }

  // --- Results --------------------------------------------------------------
  py::class_<SolveResult>(
      m, "SolveResult",
      "Result of one query. When status == Converged (vectors in body 1's frame): alpha > 0; x/alpha lies on body "
      "1's surface and R.T @ (x - p)/alpha on body 2's; lambda1 grad phi1 + lambda2 grad phi2 = 0 with lambda1, "
      "lambda2 > 0; the gap (1 - 1/alpha)|p| is > 0 iff alpha > 1. Other statuses: the fields hold the last "
      "iterate and must not be used as an answer.")
      .def_property_readonly("status", [](const SolveResult& r) { return r.status; })
      .def_property_readonly("converged", &SolveResult::converged, "status == SolveStatus.Converged.")
      .def_readonly("alpha", &SolveResult::alpha, "alpha*, the minimal common scaling.")
      .def_property_readonly("x", [](const SolveResult& r) { return to_numpy(r.x_1); },
                             "(3,) x*, the contact point of the scaled bodies, body-1 frame.")
      .def_readonly("lambda1", &SolveResult::lambda1)
      .def_readonly("lambda2", &SolveResult::lambda2)
      .def_readonly("iterations", &SolveResult::iterations, "Newton steps over every run (restarts, continuation).")
      .def_readonly("restarts", &SolveResult::restarts)
      .def_readonly("used_continuation", &SolveResult::used_continuation)
      .def_readonly("used_barrier", &SolveResult::used_barrier)
      .def_readonly("warm_started", &SolveResult::warm_started)
      .def_readonly("warm_start_fell_back", &SolveResult::warm_start_fell_back)
      .def_readonly("residual_norm", &SolveResult::residual_norm, "Relative KKT residual at the returned point.")
      .def_property_readonly("has_derivatives", [](const SolveResult& r) { return r.internal.factorised; },
                             "The factorisation for derivatives is kept (SolverOptions.derivatives and converged).")
      .def("__repr__", [](const SolveResult& r) {
        std::ostringstream os;
        os << "SolveResult(status=" << camel(to_string(r.status)) << ", alpha=" << num(r.alpha) << ", x=["
           << num(r.x_1[0]) << ", " << num(r.x_1[1]) << ", " << num(r.x_1[2]) << "], iterations=" << r.iterations
           << ")";
        return os.str();
      });

  // --- One query ------------------------------------------------------------
  m.def(
      "solve",
      [](py::handle a, py::handle b, py::handle R, py::handle p, const py::object& options) {
        const PyShape& s1 = as_shape(a, "a");
        const PyShape& s2 = as_shape(b, "b");
        const SolverOptions o = options_or_default(options);
        const Pose X = to_pose(R, p);
        return solve(*s1.shape, *s2.shape, X, o);
      },
      py::arg("a"), py::arg("b"), py::arg("R"), py::arg("p"), py::arg("options") = py::none(),
      "Solve body a (at the identity) against body b at the relative pose X_12 = (R (3, 3), p (3,)), cold. "
      "Returns a SolveResult. Set options=SolverOptions(derivatives=True) to take derivatives of the result.");

  py::class_<PyContactPair>(m, "ContactPair",
                            "Two shapes and options, fixed (and validated) at construction, with the warm-start state "
                            "of the pair: each solve() starts from the previous successful one.")
      .def(py::init([](py::object a, py::object b, const py::object& options) {
             const PyShape& s1 = as_shape(a, "a");
             const PyShape& s2 = as_shape(b, "b");
             return PyContactPair{a, b, ContactPair(*s1.shape, *s2.shape, options_or_default(options))};
           }),
           py::arg("a"), py::arg("b"), py::arg("options") = py::none())
      .def(
          "solve", [](PyContactPair& c, py::handle R, py::handle p) { return c.pair.solve(to_pose(R, p)); },
          py::arg("R"), py::arg("p"), "Solve at X_12 = (R, p), warm-started from the previous successful query.")
      .def(
          "solve_cold", [](const PyContactPair& c, py::handle R, py::handle p) { return c.pair.solve_cold(to_pose(R, p)); },
          py::arg("R"), py::arg("p"), "Solve cold; the warm-start state is neither used nor changed.")
      .def("reset_warm_start", [](PyContactPair& c) { c.pair.reset_warm_start(); })
      .def_readonly("body1", &PyContactPair::body1)
      .def_readonly("body2", &PyContactPair::body2)
      .def_property_readonly("options", [](const PyContactPair& c) { return c.pair.options(); },
                             "A copy of the pair's options.")
      .def("__repr__", [](const PyContactPair& c) {
        return "ContactPair(" + shape_repr(c.pair.body1()) + ", " + shape_repr(c.pair.body2()) + ")";
      });

  // --- Derivatives ----------------------------------------------------------
  py::class_<Conditioning>(m, "Conditioning",
                           "How far derivatives can be trusted: pivot_ratio = min|U_ii|/max|U_ii| of the KKT LU "
                           "factor; sensitivity = max |dz/dxi| made dimensionless (-1 if not computed); reliable.")
      .def_readonly("pivot_ratio", &Conditioning::pivot_ratio)
      .def_readonly("sensitivity", &Conditioning::sensitivity)
      .def_readonly("reliable", &Conditioning::reliable);

  m.def("conditioning", &conditioning, py::arg("res"),
        "Conditioning of the KKT Jacobian at a converged result (needs SolverOptions.derivatives).");

  m.def(
      "alpha_gradient", [](const SolveResult& r) { return to_numpy(alpha_gradient(r)); }, py::arg("res"),
      "(6,) d alpha*/d xi, xi = (w, v) the body twist of X_12 (eq:dz_dq, one adjoint solve). Zeros unless "
      "converged. Raises ValueError if res was solved without SolverOptions(derivatives=True).");
  m.def(
      "gap_gradient", [](const SolveResult& r) { return to_numpy(gap_gradient(r)); }, py::arg("res"),
      "(6,) d gap/d xi, gap = (1 - 1/alpha*)|p| (eq:ddD_dq). Zeros unless converged.");

  py::class_<SolutionSensitivity>(m, "SolutionSensitivity",
                                  "dz*/dxi = T_c (eq:dz_dq): rows z = (x (3, body-1 frame), alpha, lambda1, lambda2), "
                                  "columns the twist xi = (w, v) of X_12.")
      .def_readonly("valid", &SolutionSensitivity::valid)
      .def_property_readonly("dz_dxi", [](const SolutionSensitivity& s) { return to_numpy(s.dz_dxi); }, "(6, 6)")
      .def_property_readonly("dx_dxi", [](const SolutionSensitivity& s) { return to_numpy(s.dx_dxi()); }, "(3, 6)")
      .def_property_readonly("dalpha_dxi", [](const SolutionSensitivity& s) { return to_numpy(s.dalpha_dxi()); },
                             "(6,)")
      .def_readonly("conditioning", &SolutionSensitivity::cond);

  m.def("solution_sensitivity", &solution_sensitivity, py::arg("res"),
        "The full sensitivity dz*/dxi (SolutionSensitivity). Needs SolverOptions(derivatives=True).");

  py::class_<PyKinematics>(
      m, "ContactKinematics",
      "Contact kinematics, body-1 frame (eq:witness, eq:gap, eq:unit_normal). With r = p: p1 = x/alpha lies on "
      "body 1; p2 = (1 - 1/alpha) r + x/alpha on body 2; p2 - p1 = gap r/|r|, gap = (1 - 1/alpha)|r| (> 0 "
      "separated); normal = body 1's outward unit normal at p1 (body 2's is -normal). Derivatives (3, 6) or (6,) "
      "w.r.t. xi = (w, v) of X_12 when asked for, else None.")
      .def_property_readonly("valid", [](const PyKinematics& k) { return k.c.valid; })
      .def_property_readonly("alpha", [](const PyKinematics& k) { return k.c.alpha; })
      .def_property_readonly("x", [](const PyKinematics& k) { return to_numpy(k.c.x_1); })
      .def_property_readonly("p1", [](const PyKinematics& k) { return to_numpy(k.c.p1_1); })
      .def_property_readonly("p2", [](const PyKinematics& k) { return to_numpy(k.c.p2_1); })
      .def_property_readonly("normal", [](const PyKinematics& k) { return to_numpy(k.c.nhat_1); })
      .def_property_readonly("gap", [](const PyKinematics& k) { return k.c.gap; })
      .def_readonly("has_derivatives", &PyKinematics::has_derivatives)
#define IDCOL_KD(name, expr)                                                                                 \
  .def_property_readonly(name, [](const PyKinematics& k) -> py::object {                                   \
    if (!k.has_derivatives) return py::none();                                                             \
    return to_numpy(k.d.expr);                                                                             \
  })
          IDCOL_KD("dp1_dxi", dp1_1_dxi) IDCOL_KD("dp2_dxi", dp2_1_dxi) IDCOL_KD("dnormal_dxi", dnhat_1_dxi)
              IDCOL_KD("dgap_dxi", dgap_dxi)
#undef IDCOL_KD
      .def_property_readonly("conditioning", [](const PyKinematics& k) -> py::object {
        if (!k.has_derivatives) return py::none();
        return py::cast(k.d.cond);
      });

  m.def(
      "contact_kinematics",
      [](const SolveResult& r, bool derivatives) {
        PyKinematics k;
        k.c = contact_kinematics(r);
        if (derivatives) {
          k.d = contact_kinematics_derivatives(r, solution_sensitivity(r));
          k.has_derivatives = true;
        }
        return k;
      },
      py::arg("res"), py::arg("derivatives") = false,
      "Witness points, gap and normal (body-1 frame) of a result, and with derivatives=True their derivatives "
      "w.r.t. xi = (w, v) of X_12 (needs SolverOptions(derivatives=True)).");

  py::class_<HertzModel>(m, "HertzModel", "Hertz penalty law f_n = stiffness * delta^exponent, delta = -gap > 0.")
      .def(py::init([](double stiffness, double exponent) {
             HertzModel h{stiffness, exponent};
             h.validate();
             return h;
           }),
           py::arg("stiffness") = 1.0, py::arg("exponent") = 1.5)
      .def_readonly("stiffness", &HertzModel::stiffness)
      .def_readonly("exponent", &HertzModel::exponent)
      .def("__repr__", [](const HertzModel& h) {
        return "HertzModel(stiffness=" + num(h.stiffness) + ", exponent=" + num(h.exponent) + ")";
      });

  py::class_<PyWrench>(
      m, "ContactWrench",
      "Contact wrench (eq:contact_wrench), ordered (moment, force). F1: on body 1, body-1 frame, moment about "
      "body 1's origin, force -f_n normal at x. F2: the reaction on body 2, body-2 frame, moment about body 2's "
      "origin (F2 = -Ad_X12^T F1). active: penetrating (delta > 0). representable: within the double range. "
      "Derivatives w.r.t. xi = (w, v) of X_12 when asked for, else None.")
      .def_property_readonly("valid", [](const PyWrench& w) { return w.w.valid; })
      .def_property_readonly("active", [](const PyWrench& w) { return w.w.active; })
      .def_property_readonly("representable", [](const PyWrench& w) { return w.w.representable; })
      .def_property_readonly("f_n", [](const PyWrench& w) { return w.w.f_n; })
      .def_property_readonly("F1", [](const PyWrench& w) { return to_numpy(w.w.F1_1); })
      .def_property_readonly("F2", [](const PyWrench& w) { return to_numpy(w.w.F2_2); })
      .def_readonly("has_derivatives", &PyWrench::has_derivatives)
#define IDCOL_WD(name, expr)                                                                                 \
  .def_property_readonly(name, [](const PyWrench& w) -> py::object {                                       \
    if (!w.has_derivatives) return py::none();                                                             \
    return to_numpy(w.d.expr);                                                                             \
  })
          IDCOL_WD("df_n_dxi", df_n_dxi) IDCOL_WD("dF1_dxi", dF1_1_dxi) IDCOL_WD("dF2_dxi", dF2_2_dxi)
#undef IDCOL_WD
      ;

  m.def(
      "contact_wrench",
      [](const SolveResult& r, const py::object& model, bool derivatives) {
        const HertzModel h = hertz_model(model);
        PyWrench w;
        w.w = contact_wrench(r, h);
        if (derivatives) {
          w.d = contact_wrench_derivatives(r, solution_sensitivity(r), h);
          w.has_derivatives = true;
        }
        return w;
      },
      py::arg("res"), py::arg("model") = py::none(), py::arg("derivatives") = false,
      "The Hertz contact wrench of a result (default HertzModel()), and with derivatives=True its derivatives "
      "w.r.t. xi = (w, v) of X_12 (needs SolverOptions(derivatives=True)).");

  m.def(
      "se3_exp",
      [](py::handle xi) {
        const CArray a = float_array(xi, "xi", {6});
        const Pose X = se3_exp(Eigen::Map<const Vec6>(a.data()));
        return py::make_tuple(to_numpy(X.R), to_numpy(X.p));
      },
      py::arg("xi"), "(R, p) = exp(xi^) for a twist xi = (w, v).");

  m.def(
      "relative_twist_jacobians",
      [](py::handle R, py::handle p) {
        Mat6 d1, d2;
        relative_twist_jacobians(to_pose(R, p), d1, d2);
        return py::make_tuple(to_numpy(d1), to_numpy(d2));
      },
      py::arg("R"), py::arg("p"),
      "(dxi/dxi1, dxi/dxi2), each (6, 6): how body twists xi1 of X_W1 and xi2 of X_W2 move the twist xi of "
      "X_12 = X_W1^-1 X_W2. So d alpha*/dxi1 = alpha_gradient(res) @ dxi_dxi1.");

  // --- Shape-parameter derivatives ------------------------------------------
  m.def(
      "polytope_vertex_jacobian",
      [](py::handle V, py::handle polytope) {
        const PyShape& p = as_shape(polytope, "polytope");
        if (!std::holds_alternative<SmoothPolytope>(*p.shape))
          throw py::type_error("polytope must be an idcol.SmoothPolytope, got " + shape_repr(*p.shape));
        return to_numpy_2d(polytope_vertex_jacobian(to_points(V, "V"), std::get<SmoothPolytope>(*p.shape)));
      },
      py::arg("V"), py::arg("polytope"),
      "d theta / d(vertices, beta) of a polytope built by SmoothPolytope.from_vertices(V, beta, L): a (4m + 1, "
      "3k + 1) array, columns (v0.x, v0.y, v0.z, ..., v{k-1}.z, beta), rows the polytope's params. Valid while the "
      "hull's combinatorics do not change; raises ValueError naming the face if a hull face has more than three "
      "vertices (a perturbation would split it) or if polytope was not built from V. Use with chain_params.");

  py::class_<PyShapeSensitivity>(
      m, "ShapeSensitivity",
      "dz*/dtheta for the shape parameters theta of one body (eq:IFT with theta in place of the pose), pose "
      "fixed: rows z = (x (3, body-1 frame), alpha, lambda1, lambda2), columns the parameters `names` in the "
      "order of that body's Shape.params. Returned by shape_sensitivity and chain_params; valid is False (and the "
      "arrays have no columns) unless the result converged.")
      .def_property_readonly("valid", [](const PyShapeSensitivity& s) { return s.s.valid; })
      .def_property_readonly("body", [](const PyShapeSensitivity& s) { return s.s.body; }, "1 or 2.")
      .def_property_readonly("names", [](const PyShapeSensitivity& s) { return name_list(s.names); },
                             "The parameter of each column.")
      .def_property_readonly("dz_dtheta", [](const PyShapeSensitivity& s) { return to_numpy_2d(s.s.dz_dtheta); },
                             "(6, p)")
      .def_property_readonly("dx_dtheta", [](const PyShapeSensitivity& s) { return to_numpy_2d(s.s.dx_dtheta()); },
                             "(3, p) d x*/d theta, body-1 frame.")
      .def_property_readonly("dalpha_dtheta",
                             [](const PyShapeSensitivity& s) {
                               py::array_t<double> a(s.s.dz_dtheta.cols());
                               for (Eigen::Index j = 0; j < s.s.dz_dtheta.cols(); ++j)
                                 a.mutable_data()[j] = s.s.dz_dtheta(3, j);
                               return a;
                             },
                             "(p,) d alpha*/d theta.")
      .def_property_readonly("conditioning", [](const PyShapeSensitivity& s) { return s.s.cond; },
                             "As for the pose derivatives; sensitivity = max |dz/dtheta| over the rows x/L and "
                             "alpha, each column times L for a length parameter.")
      .def("__repr__", [](const PyShapeSensitivity& s) {
        return "ShapeSensitivity(body=" + std::to_string(s.s.body) + ", valid=" + (s.s.valid ? "True" : "False") +
               ", params=" + std::to_string(s.names.size()) + ")";
      });

  m.def(
      "shape_sensitivity",
      [](const py::object& res, py::handle a, py::handle b, int body) {
        if (!py::isinstance<SolveResult>(res))
          throw py::type_error("res must be an idcol.SolveResult, got " +
                               std::string(py::str(py::type::handle_of(res).attr("__name__"))));
        const PyShape& s1 = as_shape(a, "a");
        const PyShape& s2 = as_shape(b, "b");
        PyShapeSensitivity out;
        out.s = shape_sensitivity(res.cast<const SolveResult&>(), *s1.shape, *s2.shape, body);
        out.res = res;
        out.names = param_names(body == 1 ? *s1.shape : *s2.shape);
        return out;
      },
      py::arg("res"), py::arg("a"), py::arg("b"), py::arg("body"),
      "dz*/dtheta (ShapeSensitivity) for the parameters of body 1 (a) or body 2 (b): a and b must be the shapes "
      "res was solved with (ValueError otherwise), body is 1 or 2. One 6x6 triangular solve per parameter through "
      "the factorisation the solve kept: needs SolverOptions(derivatives=True).");

  m.def(
      "chain_params",
      [](const PyShapeSensitivity& s, py::handle M, const py::object& names) {
        const CArray a = float_array(M, "dtheta_dq");
        if (a.ndim() != 2 || a.shape(0) != static_cast<py::ssize_t>(s.names.size()))
          throw py::value_error("dtheta_dq must have shape (" + std::to_string(s.names.size()) + ", n), got " +
                                shape_str(a));
        const Eigen::MatrixXd D = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            a.data(), a.shape(0), a.shape(1));
        PyShapeSensitivity c;
        c.s = chain_params(s.s, D);
        c.res = s.res;
        if (names.is_none()) {
          for (py::ssize_t j = 0; j < a.shape(1); ++j) c.names.push_back("q" + std::to_string(j));
        } else {
          if (!py::isinstance<py::sequence>(names) || py::isinstance<py::str>(names))
            throw py::type_error("names must be a sequence of strings or None");
          for (py::handle n : names) {
            if (!py::isinstance<py::str>(n)) throw py::type_error("names must hold strings, got " + std::string(py::repr(n)));
            c.names.push_back(n.cast<std::string>());
          }
          if (c.names.size() != static_cast<std::size_t>(a.shape(1)))
            throw py::value_error("names holds " + std::to_string(c.names.size()) + " names but dtheta_dq has " +
                                  std::to_string(a.shape(1)) + " columns");
        }
        return c;
      },
      py::arg("sens"), py::arg("dtheta_dq"), py::arg("names") = py::none(),
      "The sensitivity w.r.t. parameters q with theta = theta(q): every derivative times dtheta_dq (p, n) on the "
      "right, e.g. polytope_vertex_jacobian(V, P) for a polytope's vertices. Columns named `names` (default q0, "
      "q1, ...).");

  py::class_<PyShapeKinematics>(
      m, "ShapeKinematicsDerivatives",
      "Derivatives of contact_kinematics (p1, p2, normal, gap; body-1 frame) w.r.t. theta, pose fixed: dp1_dtheta, "
      "dp2_dtheta, dnormal_dtheta (3, p), dgap_dtheta (p,); columns `names`.")
      .def_property_readonly("valid", [](const PyShapeKinematics& k) { return k.d.valid; })
      .def_property_readonly("names", [](const PyShapeKinematics& k) { return name_list(k.names); })
      .def_property_readonly("dp1_dtheta", [](const PyShapeKinematics& k) { return to_numpy_2d(k.d.dp1_1); })
      .def_property_readonly("dp2_dtheta", [](const PyShapeKinematics& k) { return to_numpy_2d(k.d.dp2_1); })
      .def_property_readonly("dnormal_dtheta", [](const PyShapeKinematics& k) { return to_numpy_2d(k.d.dnhat_1); })
      .def_property_readonly("dgap_dtheta",
                             [](const PyShapeKinematics& k) { return to_numpy_1d(k.d.dgap); })
      .def_property_readonly("conditioning", [](const PyShapeKinematics& k) { return k.d.cond; });

  m.def(
      "shape_kinematics_derivatives",
      [](const py::object& res, py::handle sens) {
        const PyShapeSensitivity& s = sensitivity_of(res, sens, "shape_kinematics_derivatives");
        return PyShapeKinematics{shape_kinematics_derivatives(res.cast<const SolveResult&>(), s.s), s.names};
      },
      py::arg("res"), py::arg("sens"),
      "Witness points, normal and gap differentiated w.r.t. the parameters of sens (ShapeKinematicsDerivatives); "
      "res must be the result sens was computed from.");

  py::class_<PyShapeWrench>(
      m, "ShapeWrenchDerivatives",
      "Derivatives of contact_wrench w.r.t. theta, pose fixed: df_n_dtheta (p,), dF1_dtheta, dF2_dtheta (6, p), "
      "rows (moment, force). Zero (and valid) when the contact is not active; conditioning.reliable is False when "
      "the wrench is beyond the double range.")
      .def_property_readonly("valid", [](const PyShapeWrench& w) { return w.d.valid; })
      .def_property_readonly("names", [](const PyShapeWrench& w) { return name_list(w.names); })
      .def_property_readonly("df_n_dtheta",
                             [](const PyShapeWrench& w) { return to_numpy_1d(w.d.df_n); })
      .def_property_readonly("dF1_dtheta", [](const PyShapeWrench& w) { return to_numpy_2d(w.d.dF1_1); })
      .def_property_readonly("dF2_dtheta", [](const PyShapeWrench& w) { return to_numpy_2d(w.d.dF2_2); })
      .def_property_readonly("conditioning", [](const PyShapeWrench& w) { return w.d.cond; });

  m.def(
      "shape_wrench_derivatives",
      [](const py::object& res, py::handle sens, const py::object& model) {
        const PyShapeSensitivity& s = sensitivity_of(res, sens, "shape_wrench_derivatives");
        const HertzModel h = hertz_model(model);
        return PyShapeWrench{shape_wrench_derivatives(res.cast<const SolveResult&>(), s.s, h), s.names};
      },
      py::arg("res"), py::arg("sens"), py::arg("model") = py::none(),
      "The Hertz wrench (default HertzModel()) differentiated w.r.t. the parameters of sens "
      "(ShapeWrenchDerivatives); res must be the result sens was computed from.");

  // --- Batch ----------------------------------------------------------------
  py::class_<PyBatchResult>(
      m, "BatchResult",
      "Arrays of a batch, one row per pose: alpha (N,), x (N, 3) body-1 frame, status (N,) int32 codes of "
      "SolveStatus, iterations (N,) int32, converged (N,) bool, and dalpha_dxi (N, 6) (w, v) with "
      "derivatives=True (None otherwise; zero rows where not converged).")
      .def_readonly("alpha", &PyBatchResult::alpha)
      .def_readonly("x", &PyBatchResult::x)
      .def_readonly("status", &PyBatchResult::status)
      .def_readonly("iterations", &PyBatchResult::iterations)
      .def_readonly("converged", &PyBatchResult::converged)
      .def_readonly("dalpha_dxi", &PyBatchResult::dalpha_dxi)
      .def("__len__", [](const PyBatchResult& r) { return r.alpha.shape(0); });

  const char* batch_doc =
      "Solve N queries in one call, with the GIL released, over `threads` worker threads (0 = every CPU this "
      "process may use) in contiguous chunks (C++ idcol::solve_batch). R: (N, 3, 3), p: (N, 3), C-contiguous "
      "float64 (other layouts and integer dtypes are converted; anything else is a ValueError). Bodies: `a` and "
      "`b` are each one shape for every row or a sequence of N shapes (mixed families are fine); or give "
      "`pairs`, a sequence of N (a, b) tuples.\n\n"
      "warm_start=True warm-starts each row from the previous one inside chains of `warm_chain` rows (reset at "
      "each chain start and where the pair changes), so results never depend on `threads`: they equal the serial "
      "loop of idcol.solve (cold) or of ContactPair.solve restarted every warm_chain rows (warm), bit for bit. "
      "derivatives=True also returns dalpha_dxi (N, 6). Returns a BatchResult.";
  m.def(
      "solve_batch",
      [](py::handle pairs, py::handle R, py::handle p, bool warm_start, bool derivatives, int threads,
         const py::object& options, long long warm_chain) {
        const auto [Ra, pa] = batch_poses(R, p);
        const std::size_t n = static_cast<std::size_t>(pa.shape(0));
        if (!py::isinstance<py::sequence>(pairs))
          throw py::type_error("pairs must be a sequence of (a, b) shape tuples");
        const py::sequence seq = py::reinterpret_borrow<py::sequence>(pairs);
        if (seq.size() != n)
          throw py::value_error("pairs holds " + std::to_string(seq.size()) + " pairs but R and p hold " +
                                std::to_string(n) + " poses");
        std::vector<const Shape*> b1(n), b2(n);
        std::vector<std::shared_ptr<const Shape>> keep;  // alive while the GIL is released
        for (std::size_t k = 0; k < n; ++k) {
          const py::object item = seq[k];
          const std::string at = "pairs[" + std::to_string(k) + "]";
          if (!py::isinstance<py::sequence>(item) || py::len(item) != 2)
            throw py::type_error(at + " must be an (a, b) tuple of shapes");
          const auto& s1 = as_shape(item[py::int_(0)], at + "[0]").shape;
          const auto& s2 = as_shape(item[py::int_(1)], at + "[1]").shape;
          if (keep.size() < 2 || keep[keep.size() - 2] != s1 || keep.back() != s2) keep.push_back(s1), keep.push_back(s2);
          b1[k] = s1.get();
          b2[k] = s2.get();
        }
        return run_batch(b1, b2, Ra, pa, warm_start, derivatives, threads, options, warm_chain);
      },
      py::arg("pairs"), py::arg("R"), py::arg("p"), py::arg("warm_start") = false, py::arg("derivatives") = false,
      py::arg("threads") = 0, py::arg("options") = py::none(), py::arg("warm_chain") = 1024, batch_doc);
  m.def(
      "solve_batch",
      [](py::handle a, py::handle b, py::handle R, py::handle p, bool warm_start, bool derivatives, int threads,
         const py::object& options, long long warm_chain) {
        const auto [Ra, pa] = batch_poses(R, p);
        const std::size_t n = static_cast<std::size_t>(pa.shape(0));
        std::vector<const Shape*> b1, b2;
        std::vector<std::shared_ptr<const Shape>> keep;  // alive while the GIL is released
        gather(a, "a", n, b1, keep);
        gather(b, "b", n, b2, keep);
        return run_batch(b1, b2, Ra, pa, warm_start, derivatives, threads, options, warm_chain);
      },
      py::arg("a"), py::arg("b"), py::arg("R"), py::arg("p"), py::arg("warm_start") = false,
      py::arg("derivatives") = false, py::arg("threads") = 0, py::arg("options") = py::none(),
      py::arg("warm_chain") = 1024, batch_doc);

  bind_toi(m);
}

/// The C++ shape behind a Python shape, for the bindings in other files.
const Shape& idcol_python_shape(py::handle obj, const std::string& name) { return *as_shape(obj, name).shape; }

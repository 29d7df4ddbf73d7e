// What the binding files of the Python module share: array conversion, the
// Python-side holders of shapes and results, and the option helpers.
//
// The module is split by topic, one `bind_<topic>(py::module_&)` per file
// `<topic>_bindings.cpp`; bindings.def lists them in registration order, so a
// new topic is its file plus one line there.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "idcol/derivatives.hpp"
#include "idcol/families.hpp"
#include "idcol/shape_derivatives.hpp"
#include "idcol/solver.hpp"
#include "idcol/toi.hpp"

#ifndef IDCOL_VERSION
#define IDCOL_VERSION "unknown"
#endif

namespace idcol::python {

namespace py = pybind11;

#define IDCOL_BINDING(topic) void bind_##topic(py::module_& m);
#include "bindings.def"
#undef IDCOL_BINDING

// ---------------------------------------------------------------------------
// Objects made with __new__ and no __init__.
//
// pybind11 allocates the C++ value of an instance lazily and does not
// construct it when Python calls `Cls.__new__(Cls)` without `__init__`. Every
// holder below derives from Guarded: its storage is zeroed when allocated, so
// such a value reads `ready == false`, and the argument caster (IDCOL_GUARD)
// raises TypeError instead of handing the uninitialised value to C++. Any
// value built by C++ has ready == true.

struct Guarded {
  bool ready = true;
  static void* operator new(std::size_t n) {
    void* p = ::operator new(n);
    std::memset(p, 0, n);
    return p;
  }
  static void operator delete(void* p) { ::operator delete(p); }
};

template <class T>
class GuardedCaster : public py::detail::type_caster_base<T> {
 public:
  bool load(py::handle src, bool convert) {
    if (!py::detail::type_caster_base<T>::load(src, convert)) return false;
    const T* v = static_cast<const T*>(this->value);
    if (v != nullptr && !v->ready)
      throw py::type_error("this idcol." + std::string(py::str(py::type::handle_of(src).attr("__name__"))) +
                           " was made by __new__ without __init__ and holds nothing; build it through its "
                           "constructor or the function that returns it");
    return true;
  }
};

/// The C++ classes of the library bound as they are (SolveResult,
/// ToiResult, ToiOptions, Conditioning, SolutionSensitivity) have no ready
/// flag: their argument caster asks pybind11 instead whether the instance's
/// value was ever built. An instance made by the base class's __new__
/// (`pybind11_object.__new__(Cls)`, which forbid_new cannot replace) has none
/// until its first use would allocate it uninitialised; that use raises
/// TypeError instead.
template <class T>
class BuiltCaster : public py::detail::type_caster_base<T> {
 public:
  bool load(py::handle src, bool convert) {
    if (src && py::isinstance<T>(src)) {
      auto* inst = reinterpret_cast<py::detail::instance*>(src.ptr());
      const py::detail::value_and_holder vh = inst->get_value_and_holder(py::detail::get_type_info(typeid(T)), false);
      if (vh.inst != nullptr && vh.value_ptr() == nullptr)
        throw py::type_error("this idcol." + std::string(py::str(py::type::handle_of(src).attr("__name__"))) +
                             " was made by __new__ without __init__ and holds nothing; build it through its "
                             "constructor or the function that returns it");
    }
    return py::detail::type_caster_base<T>::load(src, convert);
  }
};

/// pybind11 compares an `enum class` only with its own type; a status enum
/// (SolveStatus, ToiStatus) compares with any integer too, so that
/// `batch.status == SolveStatus.Converged` works element-wise on the int32
/// codes of a batch.
void compare_with_ints(py::handle status_enum);

/// A class with no Python constructor: `Cls.__new__` raises TypeError (the
/// module builds every instance from C++, which does not call __new__).
void forbid_new(py::handle cls);

/// A class that does not pickle: __reduce__ raises TypeError saying what to
/// pickle instead. (Without it, pickle protocols 0 and 1 reach copyreg's
/// fallback, which calls pybind11's base class and aborts the interpreter.)
void forbid_pickle(py::handle cls, const std::string& instead);

/// For a class pickled by py::pickle (__getstate__, __setstate__): the same
/// state at pickle protocols 0 and 1 too, which otherwise reach that
/// fallback and abort.
void pickle_at_every_protocol(py::handle cls);

/// A plain-data C++ class with a Python constructor (SolverOptions,
/// HertzModel, WarmStart): the storage pybind11 allocates for it is zeroed,
/// so an instance made by __new__ without __init__ holds zeros (which the
/// options' and model's validation refuses, and which is an empty warm
/// start) instead of uninitialised memory.
template <class T>
void zero_new() {
  static_assert(std::is_trivially_destructible<T>::value, "zero_new: the value is never destroyed if never built");
  py::detail::get_type_info(typeid(T))->operator_new = [](std::size_t n) -> void* {
    void* p = ::operator new(n);
    std::memset(p, 0, n);
    return p;
  };
}

// ---------------------------------------------------------------------------
// Arrays in and out.

using CArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string shape_str(const py::array& a);

/// Any array-like of real numbers (float of any width, int, uint) as a
/// C-contiguous float64 array, copied only when the layout or dtype differs.
/// Complex, object, string and bool arrays are a TypeError naming the
/// argument; NumPy's MemoryError propagates.
CArray float_array(py::handle obj, const std::string& name);
/// The same with a required shape (ValueError naming the argument).
CArray float_array(py::handle obj, const std::string& name, std::initializer_list<py::ssize_t> want);

/// Rotations as float64 row-major 3x3 blocks. Given a float type narrower
/// than float64 (float32, float16), each rotation is re-orthonormalised when
/// ||R^T R - I||_F is within what that precision rounds a rotation to (16
/// machine epsilons: 1.9e-6 for float32), and refused beyond it with a
/// ValueError naming the row and the deviation. float64 and integer input is
/// passed as given (to_pose refuses a non-rotation; a batch marks its row).
/// `batch`: R is (N, 3, 3), else (3, 3).
CArray rotations(py::handle obj, const std::string& name, bool batch);

Vec3 to_vec3(py::handle obj, const std::string& name);
Mat3 to_mat3(py::handle obj, const std::string& name);
std::vector<Vec3> to_points(py::handle obj, const std::string& name);

/// What is wrong with (R, p) as a relative pose, naming the arguments
/// `Rname`, `pname` and the entry; empty if nothing. The test is core's
/// check_pose: finite entries, ||R^T R - I||_F <= kPoseTolerance (1e-9) and
/// det R > 0. Needs the GIL (numbers are written as Python's repr).
std::string pose_problem(const Mat3& R, const Vec3& p, const std::string& Rname, const std::string& pname);

/// A pose for one query, any real dtype (rotations as rotations() reads
/// them): a ValueError naming the argument and what is wrong for a NaN or
/// Inf entry, a rotation not orthonormal to 1e-9 or a reflection.
Pose to_pose(py::handle R, py::handle p, const std::string& Rname = "R", const std::string& pname = "p");

/// Marks an array read-only, so that results cannot be edited in place by
/// mistake (np.array(a) gives a writable copy).
template <class A>
A frozen(A a) {
  a.attr("flags").attr("writeable") = false;
  return a;
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

std::string num(double v);
std::string type_name(py::handle obj);
py::list name_list(const std::vector<std::string>& names);
std::string camel(const std::string& snake);

// ---------------------------------------------------------------------------
// Pickled state of the results: a dict of plain Python values (ints, floats,
// bools, tuples of floats), one entry per field, so that the bytes are
// determined by the result alone and every field is validated on reading.

/// Reads a state dict, raising ValueError "<what>: '<field>' ..." for a
/// missing, mistyped or out-of-range field and, at done(), for a field it
/// does not know.
class StateReader {
 public:
  StateReader(py::handle state, std::string what);
  double real(const char* key);
  /// n reals (a tuple or list of floats) into out.
  void reals(const char* key, double* out, int n);
  long long integer(const char* key, long long lo, long long hi);
  bool flag(const char* key);
  py::object get(const char* key);
  [[noreturn]] void fail(const char* key, const std::string& why) const;
  void done() const;

 private:
  py::dict d_;
  std::string what_;
  std::vector<std::string> read_;
};

py::tuple reals_tuple(const double* v, int n);

/// Whether v is a Python int (not a bool) in [lo, hi], then in out.
bool int_in(py::handle v, long long lo, long long hi, long long& out);

/// A SolveResult's pickled state (every field, the factorisation when it
/// was kept) and the result rebuilt from one, validated field by field
/// (status and counts in range, the factorisation's row order a permutation
/// of 0..5, a Converged result's alpha, x and multipliers finite, alpha and
/// the multipliers > 0).
py::dict solve_result_state(const SolveResult& r);
SolveResult solve_result_from_state(py::handle state, const std::string& what);

// ---------------------------------------------------------------------------
// Shapes. One Python class per family; all derive from idcol.Shape, which
// holds the (immutable) C++ shape.

struct PyShape : Guarded {
  std::shared_ptr<const Shape> shape;
  /// How a polytope was built, for pickling bit for bit (its constructor
  /// renormalises rows, so rebuilding from the stored rows may move them by
  /// an ulp): a tuple (name of a reconstructor in idcol/__init__.py, args),
  /// or None (rebuilt from the parameters, exact for the other families).
  py::object origin = py::none();
};
/// The Python class of the family T (named as families.hpp declares it).
template <class T>
struct PyFamily : PyShape {};
using PySphere = PyFamily<Sphere>;
using PySuperellipsoid = PyFamily<Superellipsoid>;
using PySuperellipticCylinder = PyFamily<SuperellipticCylinder>;
using PySmoothPolytope = PyFamily<SmoothPolytope>;
using PySmoothTruncatedCone = PyFamily<SmoothTruncatedCone>;

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

std::string shape_repr(const Shape& s);
const PyShape& as_shape(py::handle obj, const std::string& name);
/// A C++ shape as an instance of its Python class.
py::object wrap_shape(Shape s);

// ---------------------------------------------------------------------------
// Options, solve keywords.

SolverOptions options_or_default(const py::object& options);

/// The keywords that solve, ContactPair.solve and solve_batch share:
/// `options` (None: defaults) with `derivatives` and `alpha_max` applied on
/// top when given (None leaves the options' value).
SolverOptions solve_options(const py::object& options, const py::object& derivatives, const py::object& alpha_max);

// ---------------------------------------------------------------------------
// Contact pair, derivatives.

struct PyContactPair : Guarded {
  py::object body1, body2;  // the Python shapes, returned as given
  ContactPair pair;
  PyContactPair(py::object a, py::object b, ContactPair c) : body1(std::move(a)), body2(std::move(b)), pair(std::move(c)) {}
};

/// Contact kinematics and (optionally) their derivatives, as one object.
struct PyKinematics : Guarded {
  ContactKinematics c;
  bool has_derivatives = false;
  ContactKinematicsDerivatives d;
};

struct PyWrench : Guarded {
  ContactWrench w;
  bool has_derivatives = false;
  ContactWrenchDerivatives d;
};

/// One warm state per row of solve_batch (idcol.WarmStarts; BatchOutput::warm).
struct PyWarmStarts : Guarded {
  std::vector<WarmStart> states;
};

/// The model argument of the wrench functions: HertzModel() for None,
/// validated.
HertzModel hertz_model(const py::object& model);

// ---------------------------------------------------------------------------
// Shape-parameter derivatives.

/// dz*/dtheta with the result it was taken from (kept alive and compared by
/// identity, so that kinematics and wrench derivatives cannot silently mix
/// one result with another's sensitivity) and the names of its columns.
struct PyShapeSensitivity : Guarded {
  ShapeSensitivity s;
  py::object res;
  std::vector<std::string> names;
};

struct PyShapeKinematics : Guarded {
  ShapeKinematicsDerivatives d;
  std::vector<std::string> names;
};

struct PyShapeWrench : Guarded {
  ShapeWrenchDerivatives d;
  std::vector<std::string> names;
};

// ---------------------------------------------------------------------------
// Batch: every array read-only; the optional ones None when not asked for.

struct PyBatchResult : Guarded {
  /// Field name -> NumPy array (read-only) or None; the names are those of
  /// kBatchFields (batch_bindings.cpp).
  py::dict arrays;
};

/// The arrays of a time_of_impact_batch (names in toi_bindings.cpp), all
/// read-only, and the message of each row marked InvalidInput.
struct PyToiBatch : Guarded {
  py::dict arrays;
  py::dict errors;  // row (int) -> message (str)
};

/// A read-only copy of `v` as it was pickled: a NumPy array of exactly the
/// dtype T (native byte order) with `tail` after its first dimension, whose
/// length must be n (n < 0: any, returned in n). ValueError naming `what`
/// and the field otherwise.
template <class T>
py::array_t<T> state_array(py::handle v, const std::string& what, const char* field, py::ssize_t& n,
                           const std::vector<py::ssize_t>& tail) {
  const std::string at = what + ": '" + field + "'";
  if (!py::isinstance<py::array>(v)) throw py::value_error(at + " must be a NumPy array, got " + type_name(v));
  const py::array a = py::reinterpret_borrow<py::array>(v);
  const py::object want = py::dtype::of<T>();
  if (!a.dtype().equal(py::dtype::of<T>()) || !a.dtype().attr("isnative").cast<bool>())
    throw py::value_error(at + " must have dtype " + std::string(py::str(want)) + ", got " +
                          std::string(py::str(py::object(a.dtype()))));
  bool ok = a.ndim() == 1 + static_cast<py::ssize_t>(tail.size()) && (n < 0 || a.shape(0) == n);
  py::ssize_t i = 1;
  for (py::ssize_t t : tail) ok = ok && a.shape(i++) == t;
  if (!ok) {
    std::string s = "(" + (n < 0 ? std::string("N") : std::to_string(n));
    for (py::ssize_t t : tail) s += ", " + std::to_string(t);
    throw py::value_error(at + " must have shape " + s + (tail.size() == 0 ? ",)" : ")") + ", got " + shape_str(a));
  }
  n = a.shape(0);
  // A C-contiguous copy of our own (the caster may read it as raw memory).
  return frozen(py::array_t<T>(py::module_::import("numpy").attr("array")(a, py::arg("order") = "C")));
}

}  // namespace idcol::python

#define IDCOL_GUARD(T)                                                                   \
  namespace pybind11::detail {                                                           \
  template <>                                                                            \
  class type_caster<idcol::python::T> : public idcol::python::GuardedCaster<idcol::python::T> {}; \
  }
IDCOL_GUARD(PyShape)
IDCOL_GUARD(PyContactPair)
IDCOL_GUARD(PyKinematics)
IDCOL_GUARD(PyWrench)
IDCOL_GUARD(PyShapeSensitivity)
IDCOL_GUARD(PyShapeKinematics)
IDCOL_GUARD(PyShapeWrench)
IDCOL_GUARD(PyBatchResult)
IDCOL_GUARD(PyToiBatch)
IDCOL_GUARD(PyWarmStarts)
#undef IDCOL_GUARD

#define IDCOL_BUILT(T)                                                                   \
  namespace pybind11::detail {                                                           \
  template <>                                                                            \
  class type_caster<T> : public idcol::python::BuiltCaster<T> {};                        \
  }
IDCOL_BUILT(idcol::SolveResult)
IDCOL_BUILT(idcol::ToiResult)
IDCOL_BUILT(idcol::ToiOptions)
IDCOL_BUILT(idcol::Conditioning)
IDCOL_BUILT(idcol::SolutionSensitivity)
#undef IDCOL_BUILT

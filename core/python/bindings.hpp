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
#include "idcol/shape_derivatives.hpp"
#include "idcol/solver.hpp"

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

/// A class with no Python constructor: `Cls.__new__` raises TypeError (the
/// module builds every instance from C++, which does not call __new__).
void forbid_new(py::handle cls);

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
/// passed as given (the solver reports a non-rotation as InvalidInput).
/// `batch`: R is (N, 3, 3), else (3, 3).
CArray rotations(py::handle obj, const std::string& name, bool batch);

Vec3 to_vec3(py::handle obj, const std::string& name);
Mat3 to_mat3(py::handle obj, const std::string& name);
std::vector<Vec3> to_points(py::handle obj, const std::string& name);
Pose to_pose(py::handle R, py::handle p);

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
#undef IDCOL_GUARD

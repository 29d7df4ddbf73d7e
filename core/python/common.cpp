// Array conversion, shape holders and option helpers shared by the binding
// files (declared in bindings.hpp).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "bindings.hpp"

namespace idcol::python {

void forbid_new(py::handle cls) {
  const std::string name = py::str(cls.attr("__name__"));
  cls.attr("__new__") = py::staticmethod(py::cpp_function([name](const py::args&, const py::kwargs&) -> py::object {
    throw py::type_error("idcol." + name + " cannot be created from Python; it is returned by the module's functions");
  }));
}

void compare_with_ints(py::handle status_enum) {
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
  status_enum.attr("__eq__") = py::cpp_function(same_code, py::is_method(status_enum), py::name("__eq__"));
  status_enum.attr("__ne__") = py::cpp_function(
      [same_code](const py::object& a, const py::object& b) -> py::object {
        py::object r = same_code(a, b);
        if (r.is(py::reinterpret_borrow<py::object>(Py_NotImplemented))) return r;
        return py::bool_(!r.cast<bool>());
      },
      py::is_method(status_enum), py::name("__ne__"));
}

void forbid_pickle(py::handle cls, const std::string& instead) {
  const std::string name = py::str(cls.attr("__name__"));
  cls.attr("__reduce__") = py::cpp_function(
      [name, instead](py::handle) -> py::object {
        throw py::type_error("idcol." + name + " cannot be pickled; " + instead);
      },
      py::is_method(cls), py::name("__reduce__"));
}

void pickle_at_every_protocol(py::handle cls) {
  cls.attr("__reduce__") = py::cpp_function(
      [](const py::object& self) {
        return py::make_tuple(py::module_::import("copyreg").attr("__newobj__"),
                              py::make_tuple(py::type::handle_of(self)), self.attr("__getstate__")());
      },
      py::is_method(cls), py::name("__reduce__"));
}

std::string shape_str(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string type_name(py::handle obj) { return py::str(py::type::handle_of(obj).attr("__name__")); }

namespace {

/// obj as a NumPy array of real numbers, in its own dtype.
py::array real_array(py::handle obj, const std::string& name) {
  py::array a;
  if (py::isinstance<py::array>(obj)) {
    a = py::reinterpret_borrow<py::array>(obj);
  } else {
    try {
      a = py::module_::import("numpy").attr("asarray")(obj);
    } catch (py::error_already_set& e) {
      if (e.matches(PyExc_MemoryError)) throw;
      throw py::value_error(name + " cannot be read as an array of numbers: " + std::string(e.what()));
    }
  }
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(name + " must hold real numbers (float or int), got dtype " + std::string(py::str(a.dtype())));
  return a;
}

CArray as_float64(const py::array& a) {
  if (py::isinstance<py::array_t<double, py::array::c_style>>(a)) return py::reinterpret_borrow<CArray>(a);
  // numpy raises MemoryError when the copy does not fit (array_t::ensure
  // would hand back a null array instead).
  py::object c = py::module_::import("numpy").attr("ascontiguousarray")(a, py::arg("dtype") = "float64");
  return py::reinterpret_borrow<CArray>(c);
}

}  // namespace

CArray float_array(py::handle obj, const std::string& name) { return as_float64(real_array(obj, name)); }

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

CArray rotations(py::handle obj, const std::string& name, bool batch) {
  const py::array src = real_array(obj, name);
  const bool narrow = src.dtype().kind() == 'f' && src.dtype().itemsize() < 8;
  CArray a = as_float64(src);
  if (batch ? (a.ndim() != 3 || a.shape(1) != 3 || a.shape(2) != 3) : (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3))
    throw py::value_error(name + " must have shape " + (batch ? "(N, 3, 3)" : "(3, 3)") + ", got " + shape_str(a));
  if (!narrow) return a;
  // Narrow floats: a copy was made above (the dtype differed), so it may be
  // written. Tolerance: 16 epsilons of the input's type.
  const py::object finfo = py::module_::import("numpy").attr("finfo")(src.dtype());
  const double tol = 16.0 * finfo.attr("eps").cast<double>();
  const std::string dtype = py::str(src.dtype());
  const py::ssize_t n = batch ? a.shape(0) : 1;
  double* d = a.mutable_data();
  using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  for (py::ssize_t k = 0; k < n; ++k) {
    Eigen::Map<RowMat3> R(d + 9 * k);
    if (!R.allFinite()) continue;  // the solver reports InvalidInput
    const double dev = (R.transpose() * R - Mat3::Identity()).norm();
    if (!(dev <= tol)) {
      std::ostringstream os;
      os << name << (batch ? "[" + std::to_string(k) + "]" : std::string()) << " is not a rotation to " << dtype
         << " precision: ||R^T R - I||_F = " << std::setprecision(3) << dev << " > " << tol
         << " (16 epsilons of " << dtype << "); re-orthonormalise it or pass float64";
      throw py::value_error(os.str());
    }
    // Newton's iteration for the orthogonal polar factor, R <- R (3I - R^T R)/2:
    // quadratic, so from 1e-2 four steps reach the double rounding level.
    for (int it = 0; it < 8 && (R.transpose() * R - Mat3::Identity()).norm() > 1e-15; ++it) {
      const RowMat3 next = 0.5 * R * (3.0 * Mat3::Identity() - R.transpose() * R);
      R = next;
    }
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

std::string pose_problem(const Mat3& R, const Vec3& p, const std::string& Rname, const std::string& pname) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!std::isfinite(R(i, j)))
        return Rname + "[" + std::to_string(i) + ", " + std::to_string(j) + "] = " + num(R(i, j)) + " is not finite";
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(p[i])) return pname + "[" + std::to_string(i) + "] = " + num(p[i]) + " is not finite";
  switch (check_pose(Pose{R, p})) {
    case PoseCheck::Ok: return "";
    case PoseCheck::NotOrthonormal: {
      std::ostringstream os;
      os << Rname << " is not a rotation: ||R^T R - I||_F = " << std::setprecision(3)
         << (R.transpose() * R - Mat3::Identity()).norm() << " > " << kPoseTolerance
         << " (a float64 rotation must be orthonormal to 1e-9; re-orthonormalise it)";
      return os.str();
    }
    case PoseCheck::Reflection:
      return Rname + " has determinant " + num(R.determinant()) + ": a reflection, not a rotation";
    case PoseCheck::NonFinite: break;  // found above
  }
  return Rname + ", " + pname + ": " + to_string(check_pose(Pose{R, p}));
}

Pose to_pose(py::handle R, py::handle p, const std::string& Rname, const std::string& pname) {
  const CArray Ra = rotations(R, Rname, false);
  const Pose X{Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(Ra.data()), to_vec3(p, pname)};
  const std::string bad = pose_problem(X.R, X.p, Rname, pname);
  if (!bad.empty()) throw py::value_error(bad);
  return X;
}

StateReader::StateReader(py::handle state, std::string what) : what_(std::move(what)) {
  if (!py::isinstance<py::dict>(state)) throw py::value_error(what_ + " must be a dict, got " + type_name(state));
  d_ = py::reinterpret_borrow<py::dict>(state);
}

void StateReader::fail(const char* key, const std::string& why) const {
  throw py::value_error(what_ + ": '" + key + "' " + why);
}

py::object StateReader::get(const char* key) {
  if (!d_.contains(key)) throw py::value_error(what_ + " lacks '" + key + "'");
  read_.emplace_back(key);
  return d_[key];
}

double StateReader::real(const char* key) {
  const py::object v = get(key);
  if (!py::isinstance<py::float_>(v)) fail(key, "must be a float, got " + std::string(py::repr(v)));
  return v.cast<double>();
}

void StateReader::reals(const char* key, double* out, int n) {
  const py::object v = get(key);
  if (!py::isinstance<py::tuple>(v) || py::len(v) != static_cast<std::size_t>(n))
    fail(key, "must be a tuple of " + std::to_string(n) + " floats, got " + type_name(v) +
                  (py::isinstance<py::tuple>(v) ? " of " + std::to_string(py::len(v)) : std::string()));
  const py::tuple t = py::reinterpret_borrow<py::tuple>(v);
  for (int i = 0; i < n; ++i) {
    if (!py::isinstance<py::float_>(t[i]))
      fail(key, "[" + std::to_string(i) + "] must be a float, got " + std::string(py::repr(t[i])));
    out[i] = t[i].cast<double>();
  }
}

bool int_in(py::handle v, long long lo, long long hi, long long& out) {
  if (!py::isinstance<py::int_>(v) || py::isinstance<py::bool_>(v)) return false;
  int overflow = 0;
  out = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
  return overflow == 0 && out >= lo && out <= hi;
}

long long StateReader::integer(const char* key, long long lo, long long hi) {
  const py::object v = get(key);
  long long x = 0;
  if (!int_in(v, lo, hi, x))
    fail(key, "must be an int in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                  std::string(py::repr(v)));
  return x;
}

bool StateReader::flag(const char* key) {
  const py::object v = get(key);
  if (!py::isinstance<py::bool_>(v)) fail(key, "must be True or False, got " + std::string(py::repr(v)));
  return v.cast<bool>();
}

void StateReader::done() const {
  for (auto item : d_) {
    const std::string k = py::str(item.first);
    if (std::find(read_.begin(), read_.end(), k) == read_.end())
      throw py::value_error(what_ + " has an unknown field " + std::string(py::repr(item.first)));
  }
}

py::tuple reals_tuple(const double* v, int n) {
  py::tuple t(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) t[static_cast<std::size_t>(i)] = py::float_(v[i]);
  return t;
}

std::string num(double v) { return py::repr(py::float_(v)).cast<std::string>(); }

py::list name_list(const std::vector<std::string>& names) {
  py::list l;
  for (const std::string& n : names) l.append(n);
  return l;
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

std::string shape_repr(const Shape& s) {
  std::ostringstream os;
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (kScalarFamily<T>) {
          const auto v = FamilyParams<T>::get(x);
          os << family_info<T>().type << "(";
          std::size_t i = 0;
          for (const FamilyParam* p : family_info<T>().scalars()) {
            os << (i ? ", " : "") << p->key << "=" << num(v[i]);
            ++i;
          }
          os << ")";
        } else {
          os << "SmoothPolytope(A=[";
          for (int i = 0; i < x.num_halfspaces(); ++i) {
            const Vec3 a = x.normal(i);
            os << (i ? ", " : "") << "[" << num(a.x()) << ", " << num(a.y()) << ", " << num(a.z()) << "]";
          }
          os << "], b=[";
          for (int i = 0; i < x.num_halfspaces(); ++i) os << (i ? ", " : "") << num(x.offset(i));
          os << "], beta=" << num(x.beta()) << ", L=" << num(x.L()) << ")";
        }
      },
      s);
  return os.str();
}

const PyShape& as_shape(py::handle obj, const std::string& name) {
  if (!py::isinstance<PyShape>(obj))
    throw py::type_error(name + " must be an idcol shape (Sphere, Superellipsoid, ...), got " + type_name(obj));
  return obj.cast<const PyShape&>();
}

/// A C++ shape as an instance of its Python class.
py::object wrap_shape(Shape s) {
  return std::visit(
      [](auto&& x) -> py::object {
        using T = std::decay_t<decltype(x)>;
        return py::cast(make_shape<PyFamily<T>>(std::move(x)));
      },
      std::move(s));
}

SolverOptions options_or_default(const py::object& options) {
  if (options.is_none()) return SolverOptions{};
  if (!py::isinstance<SolverOptions>(options))
    throw py::type_error("options must be an idcol.SolverOptions or None, got " + type_name(options));
  SolverOptions o = options.cast<SolverOptions>();
  o.validate();
  return o;
}

SolverOptions solve_options(const py::object& options, const py::object& derivatives, const py::object& alpha_max) {
  SolverOptions o = options_or_default(options);
  if (!derivatives.is_none()) {
    if (!py::isinstance<py::bool_>(derivatives))
      throw py::type_error("derivatives must be a bool or None, got " + std::string(py::repr(derivatives)));
    o.derivatives = derivatives.cast<bool>();
  }
  if (!alpha_max.is_none()) {
    if (py::isinstance<py::bool_>(alpha_max) || !(py::isinstance<py::float_>(alpha_max) || py::isinstance<py::int_>(alpha_max)))
      throw py::type_error("alpha_max must be a float or None, got " + std::string(py::repr(alpha_max)));
    o.alpha_max = alpha_max.cast<double>();
  }
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  return o;
}

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

}  // namespace idcol::python

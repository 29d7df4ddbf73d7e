// Python bindings: SolverOptions, every field type-checked and validated.
#include <sstream>
#include <string>

#include "bindings.hpp"
#include "idcol/options_fields.hpp"

namespace idcol::python {

namespace {

// ---------------------------------------------------------------------------
// SolverOptions: every field of idcol/options_fields.hpp, type-checked and
// validated on construction and on every assignment.

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
#define IDCOL_SET(T, f, range)                \
  if (name == #f) {                     \
    o.f = checked<T>(v, #f);            \
    return true;                        \
  }
  IDCOL_SOLVER_OPTION_FIELDS(IDCOL_SET)
#undef IDCOL_SET
  return false;
}

std::string options_repr(const SolverOptions& o) {
  std::ostringstream os;
  os << "SolverOptions(";
  bool first = true;
#define IDCOL_REPR(T, f, range)                                                            \
  os << (first ? "" : ", ") << #f << "=";                                           \
  if constexpr (std::is_same_v<T, bool>) os << (o.f ? "True" : "False");           \
  else if constexpr (std::is_same_v<T, int>) os << o.f;                            \
  else os << num(static_cast<double>(o.f));                                        \
  first = false;
  IDCOL_SOLVER_OPTION_FIELDS(IDCOL_REPR)
#undef IDCOL_REPR
  os << ")";
  return os.str();
}

}  // namespace

void bind_options(py::module_& m) {
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
    zero_new<SolverOptions>();
    opt.def(py::init([](const py::kwargs& kw) {
      SolverOptions o;
      for (auto item : kw) {
        const std::string name = py::str(item.first);
        if (!set_option(o, name, item.second)) throw py::type_error("SolverOptions has no field '" + name + "'");
      }
      o.validate();
      return o;
    }));
    // Each property's docstring: its type and the values validate() accepts.
    auto field_doc = [](const char* type, const char* name) {
      for (const SolverOptionField& f : solver_option_fields())
        if (std::string(f.name) == name) return std::string(type) + ": " + f.expected() + ".";
      return std::string(type);
    };
#define IDCOL_PROP(T, f, range)                                                                             \
  opt.def_property(                                                                                         \
      #f, [](const SolverOptions& o) { return o.f; },                                                       \
      [](SolverOptions& o, py::handle v) {                                                                  \
        SolverOptions c = o;                                                                                \
        c.f = checked<T>(v, #f);                                                                            \
        c.validate();                                                                                       \
        o = c;                                                                                              \
      },                                                                                                    \
      field_doc(std::is_same_v<T, bool> ? "bool" : std::is_same_v<T, int> ? "int" : "float", #f).c_str());
    IDCOL_SOLVER_OPTION_FIELDS(IDCOL_PROP)
#undef IDCOL_PROP
    opt.def("validate", &SolverOptions::validate, "Raise ValueError naming the field if any option is out of range.")
        .def("__repr__", &options_repr)
        .def(py::pickle(
            [](const SolverOptions& o) {
              py::dict d;
#define IDCOL_GET(T, f, range) d[#f] = o.f;
              IDCOL_SOLVER_OPTION_FIELDS(IDCOL_GET)
#undef IDCOL_GET
              return d;
            },
            [](const py::dict& d) {
              SolverOptions o;
              for (auto item : d) {
                const std::string name = py::str(item.first);
                if (!set_option(o, name, item.second)) throw py::type_error("SolverOptions has no field '" + name + "'");
              }
              o.validate();
              return o;
            }));
    pickle_at_every_protocol(opt);
  }
}

}  // namespace idcol::python

// Python bindings: the shape families (idcol.Shape and its subclasses).
#include <cmath>
#include <sstream>
#include <type_traits>
#include <variant>
#include <string>

#include "bindings.hpp"

namespace idcol::python {

namespace {
/// A family's declaration (families.hpp) as Python reads it.
py::dict family_dict(const FamilyInfo& f) {
  py::list params;
  for (const FamilyParam& p : f.params) {
    py::dict d;
    d["key"] = p.key;
    d["meaning"] = p.meaning;
    d["array"] = p.array;
    if (!p.array) {
      d["lower"] = p.lower;
      d["lower_open"] = p.lower_open;
      d["default"] = std::isnan(p.fallback) ? py::object(py::none()) : py::object(py::float_(p.fallback));
      d["length_power"] = p.length_power;
      d["example"] = p.example;
    }
    params.append(d);
  }
  py::dict d;
  d["name"] = f.name;
  d["type"] = f.type;
  d["summary"] = f.summary;
  d["smooth_form_of"] = f.smooth_form_of;
  d["axes"] = f.axes;
  d["params"] = params;
  return d;
}

/// The class of family T, with its docstring and a read-only property for
/// each scalar parameter, from its declaration.
template <class T>
py::class_<PyFamily<T>, PyShape> family_class(py::module_& m) {
  const FamilyInfo& f = family_info<T>();
  std::string doc = std::string(f.summary) + ". Frame: " + f.axes + ".";
  if (*f.smooth_form_of) doc += " The smooth form of " + std::string(f.smooth_form_of) + ".";
  doc += " Parameters:";
  for (const FamilyParam& p : f.params) doc += std::string(" ") + p.key + ": " + p.meaning + ";";
  doc.back() = '.';
  py::class_<PyFamily<T>, PyShape> c(m, f.type, doc.c_str());
  if constexpr (kScalarFamily<T>) {
    std::size_t i = 0;
    for (const FamilyParam* p : f.scalars()) {
      c.def_property_readonly(
          p->key, [i](const PyShape& s) { return FamilyParams<T>::get(family<T>(s))[i]; }, p->meaning);
      ++i;
    }
  }
  return c;
}
}  // namespace

// Long: the module's declarations for shapes.hpp, one statement a binding.
void bind_shapes(py::module_& m) {
  m.def(
      "shape_families",
      [] {
        py::list out;
        for (const FamilyInfo& f : shape_families()) out.append(family_dict(f));
        return out;
      },
      "Each shape family's declaration, as core holds it (idcol/families.hpp): name, type (the class), summary, "
      "smooth_form_of, axes, and params (key, meaning, and for a scalar: lower, lower_open, default (None: "
      "required), length_power, example).");
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
          py::arg("y"),
          "(phi (dimensionless), grad (3,) (1/length), hess (3, 3) (1/length^2)) at the point y (3,), length units, "
          "in the shape's own frame; phi <= 0 inside.")
      .def("describe", [](const PyShape& s) { return describe(*s.shape); },
           "The parameters in the scene-file form (idcol::describe), at 17 significant digits.")
      .def_property_readonly("params", [](const PyShape& s) { return to_numpy_1d(shape_params(*s.shape)); },
                             "(p,) the shape parameters theta, in the order of param_names: a family's constructor "
                             "arguments (shape_families()); SmoothPolytope (A0.x, A0.y, A0.z, b0, ..., beta) at the "
                             "stored unit rows, L held fixed.")
      .def_property_readonly("param_names", [](const PyShape& s) { return name_list(param_names(*s.shape)); },
                             "Names of params, e.g. ['a', 'b', 'c', 'n'] or ['A0.x', ..., 'b7', 'beta'].")
      .def_property_readonly(
          "param_length_powers", [](const PyShape& s) { return to_numpy_1d(param_length_powers(*s.shape)); },
          "(p,) the power of length each parameter carries (1 for lengths and offsets, 0 for n, beta, unit rows).")
      .def(
          "with_params",
          [](const py::object& self, py::handle theta) {
            const PyShape& s = self.cast<const PyShape&>();
            const CArray t = float_array(theta, "theta");
            const int p = num_params(*s.shape);
            if (t.ndim() != 1 || t.shape(0) != p)
              throw py::value_error("theta must have shape (" + std::to_string(p) + ",), got " + shape_str(t));
            py::object out = wrap_shape(shape_with_params(*s.shape, Eigen::Map<const VecX>(t.data(), p)));
            if (std::holds_alternative<SmoothPolytope>(*s.shape))
              out.cast<PyShape&>().origin =
                  py::make_tuple("_shape_with_params", py::make_tuple(self, t.attr("copy")()));
            return out;
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
          "(phi, grad (3,), hess (3, 3), dphi_dtheta (p,), dgrad_dtheta (3, p)) at the point y (3,), length units, "
          "in the shape's own frame; theta = params.")
      .def("__repr__", [](const PyShape& s) { return shape_repr(*s.shape); })
      .def("__reduce__", [](const py::object& self) {
        // (class, constructor arguments): pickle and deepcopy rebuild the
        // shape through its validating constructor, bit for bit.
        const PyShape& s = self.cast<const PyShape&>();
        if (!s.origin.is_none()) {
          const py::tuple o = s.origin;
          return py::make_tuple(py::module_::import("idcol").attr(o[0]), o[1]);
        }
        const py::object cls = py::reinterpret_borrow<py::object>(py::type::handle_of(self));
        return std::visit(
            [&](const auto& x) -> py::tuple {
              using T = std::decay_t<decltype(x)>;
              if constexpr (kScalarFamily<T>) {
                py::tuple args(FamilyParams<T>::kCount);
                const auto v = FamilyParams<T>::get(x);
                for (int i = 0; i < FamilyParams<T>::kCount; ++i) args[static_cast<std::size_t>(i)] = py::float_(v[static_cast<std::size_t>(i)]);
                return py::make_tuple(cls, args);
              } else {
                return py::make_tuple(cls, py::make_tuple(self.attr("A"), self.attr("b"), x.beta(), x.L()));
              }
            },
            *s.shape);
      });

  // Each family's class: its name, docstring and parameters' properties from
  // its declaration (idcol/families.hpp); its constructor below.
  family_class<Sphere>(m).def(py::init([](double R) { return make_shape<PySphere>(Sphere(R)); }), py::arg("R"));
  family_class<Superellipsoid>(m).def(
      py::init([](double a, double b, double c, double n) { return make_shape<PySuperellipsoid>(Superellipsoid(a, b, c, n)); }),
      py::arg("a"), py::arg("b"), py::arg("c"), py::arg("n") = 1.0);
  family_class<SuperellipticCylinder>(m).def(
      py::init([](double R, double h, double n) { return make_shape<PySuperellipticCylinder>(SuperellipticCylinder(R, h, n)); }),
      py::arg("R"), py::arg("h"), py::arg("n") = 1.0);
  family_class<SmoothTruncatedCone>(m).def(
      py::init([](double Rb, double Rt, double a, double b, double beta) {
        return make_shape<PySmoothTruncatedCone>(SmoothTruncatedCone(Rb, Rt, a, b, beta));
      }),
      py::arg("Rb"), py::arg("Rt"), py::arg("a"), py::arg("b"), py::arg("beta"));

  // The polytope's inputs are arrays (A, b, or vertices V): its class is written out.
  py::class_<PySmoothPolytope, PyShape>(
      m, "SmoothPolytope",
      "Smooth polytope: phi(y) = smax_beta((A y - b) / L), the LogSumExp smooth maximum over the half-spaces "
      "A y <= b in the polytope's own frame (A: (m, 3) outward normals, b: (m,) offsets in length units, m >= 4; "
      "rows normalised at construction, b scaled with them), beta the smoothing (dimensionless), L the length "
      "scale (length units). The polytope must hold its frame origin strictly inside. The smooth body lies "
      "inside the exact polytope.")
      .def(py::init([](py::handle A, py::handle b, double beta, double L) {
             const std::vector<Vec3> rows = to_points(A, "A");
             const CArray ba = float_array(b, "b");
             if (ba.ndim() != 1 || ba.shape(0) != static_cast<py::ssize_t>(rows.size()))
               throw py::value_error("b must have shape (" + std::to_string(rows.size()) + ",) to match A, got " +
                                     shape_str(ba));
             const std::vector<double> bv(ba.data(), ba.data() + ba.shape(0));
             PySmoothPolytope p = make_shape<PySmoothPolytope>(SmoothPolytope(rows, bv, beta, L));
             p.origin = py::make_tuple("_polytope", py::make_tuple(float_array(A, "A").attr("copy")(), ba.attr("copy")(),
                                                                   beta, L));
             return p;
           }),
           py::arg("A"), py::arg("b"), py::arg("beta"), py::arg("L") = 1.0)
      .def_static(
          "from_vertices",
          [](py::handle V, double beta, double L) {
            PySmoothPolytope p = make_shape<PySmoothPolytope>(SmoothPolytope::from_vertices(to_points(V, "V"), beta, L));
            p.origin = py::make_tuple("_polytope_from_vertices",
                                      py::make_tuple(float_array(V, "V").attr("copy")(), beta, L));
            return p;
          },
          py::arg("V"), py::arg("beta"), py::arg("L") = 1.0,
          "The convex hull of the vertices V (k, 3), length units in the polytope's own frame (which must lie "
          "strictly inside the hull), coplanar facets merged, smoothed with beta (dimensionless) at the length "
          "scale L (length units).")
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
}

}  // namespace idcol::python

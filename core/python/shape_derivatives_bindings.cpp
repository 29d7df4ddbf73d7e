// Python bindings: derivatives w.r.t. the shape parameters.
#include <sstream>
#include <string>

#include "bindings.hpp"

namespace idcol::python {

namespace {

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

}  // namespace

// Long: the module's declarations for shape_derivatives.hpp, one statement a
// binding.
void bind_shape_derivatives(py::module_& m) {
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
        return PyShapeKinematics{{}, shape_kinematics_derivatives(res.cast<const SolveResult&>(), s.s), s.names};
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
        return PyShapeWrench{{}, shape_wrench_derivatives(res.cast<const SolveResult&>(), s.s, h), s.names};
      },
      py::arg("res"), py::arg("sens"), py::arg("model") = py::none(),
      "The Hertz wrench (default HertzModel()) differentiated w.r.t. the parameters of sens "
      "(ShapeWrenchDerivatives); res must be the result sens was computed from.");
  // Built only by the functions above.
  for (const char* cls : {"ShapeSensitivity", "ShapeKinematicsDerivatives", "ShapeWrenchDerivatives"}) {
    forbid_new(m.attr(cls));
    forbid_pickle(m.attr(cls), "pickle the SolveResult and the shapes, and compute it again from the copies");
  }
}

}  // namespace idcol::python

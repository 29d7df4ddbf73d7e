// Python bindings: pose derivatives, contact kinematics and wrenches, SE(3) helpers.
#include <sstream>
#include <string>

#include "bindings.hpp"

namespace idcol::python {

// Long: the module's declarations for derivatives.hpp, one statement a binding.
void bind_derivatives(py::module_& m) {
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
      "separated); normal = body 1's outward unit normal at p1 (body 2's is -normal). representable: p1, p2 and gap "
      "within the double range. Derivatives (3, 6) or (6,) "
      "w.r.t. xi = (w, v) of X_12 when asked for, else None.")
      .def_property_readonly("valid", [](const PyKinematics& k) { return k.c.valid; })
      .def_property_readonly("alpha", [](const PyKinematics& k) { return k.c.alpha; })
      .def_property_readonly("x", [](const PyKinematics& k) { return to_numpy(k.c.x_1); })
      .def_property_readonly("p1", [](const PyKinematics& k) { return to_numpy(k.c.p1_1); })
      .def_property_readonly("p2", [](const PyKinematics& k) { return to_numpy(k.c.p2_1); })
      .def_property_readonly("normal", [](const PyKinematics& k) { return to_numpy(k.c.nhat_1); })
      .def_property_readonly("gap", [](const PyKinematics& k) { return k.c.gap; })
      .def_property_readonly("representable", [](const PyKinematics& k) { return k.c.representable; })
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

  py::class_<HertzModel>(m, "HertzModel", "Hertz penalty law f_n = stiffness * delta^exponent (force units), delta = -gap > 0 the penetration "
      "depth (length units); stiffness in force / length^exponent, exponent dimensionless.")
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
      })
      .def(py::pickle([](const HertzModel& h) { return py::make_tuple(h.stiffness, h.exponent); },
                      [](const py::tuple& t) {
                        if (t.size() != 2) throw py::value_error("HertzModel state must be (stiffness, exponent)");
                        HertzModel h{t[0].cast<double>(), t[1].cast<double>()};
                        h.validate();
                        return h;
                      }));

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
      py::arg("xi"),
      "(R (3, 3), p (3,)) = exp(xi^) for a twist xi (6,) = (w, v): w in rad (the rotation vector), v in length "
      "units, both in the moving frame (X exp(xi^) moves X by xi in its own frame).");

  m.def(
      "relative_twist_jacobians",
      [](py::handle R, py::handle p) {
        Mat6 d1, d2;
        relative_twist_jacobians(to_pose(R, p), d1, d2);
        return py::make_tuple(to_numpy(d1), to_numpy(d2));
      },
      py::arg("R"), py::arg("p"),
      "Takes X_12 = (R, p), the RELATIVE pose of body 2 in body 1's frame (R = R_W1^T R_W2, p = R_W1^T (p_W2 "
      "- p_W1); not a world pose), the pose the result was solved at. Returns (dxi/dxi1, dxi/dxi2), each (6, 6): "
      "how the body twists xi1 of X_W1 and xi2 of X_W2 (each (w, v): rad and length units, in that body's own "
      "frame) move the twist xi of X_12 = X_W1^-1 X_W2. So d alpha*/dxi1 = alpha_gradient(res) @ dxi_dxi1.");
  zero_new<HertzModel>();
  pickle_at_every_protocol(m.attr("HertzModel"));
  // Built only by the functions above.
  for (const char* cls : {"Conditioning", "SolutionSensitivity", "ContactKinematics", "ContactWrench"}) {
    forbid_new(m.attr(cls));
    forbid_pickle(m.attr(cls), "pickle the SolveResult it was computed from, and compute it again from the copy");
  }
}

}  // namespace idcol::python

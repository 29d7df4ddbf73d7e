// Python bindings: SolveStatus, SolveResult, WarmStart, solve and ContactPair.
#include <climits>
#include <cmath>
#include <sstream>
#include <string>

#include "bindings.hpp"

namespace idcol::python {

namespace {

const char* status_doc(const std::string& name) {
  if (name == "converged") return "The KKT conditions of the target shapes hold to SolverOptions.tolerance, lambda1, lambda2 > 0.";
  if (name == "concentric") return "r = 0 exactly: alpha* = 0, x* = 0; no normal, multipliers or derivatives.";
  if (name == "iteration_limit") return "Every run used max_iterations Newton steps without meeting the tolerance.";
  if (name == "line_search_failed") return "Backtracking and Levenberg-Marquardt made no progress (a stationary point of ||F||).";
  if (name == "numerical_failure") return "Non-finite residual or Jacobian, or an answer beyond the double range.";
  if (name == "spurious_root") return "Only KKT roots with a multiplier <= 0 or alpha outside the certified bounds were found.";
  if (name == "invalid_input")
    return "The pose has a NaN/Inf entry, a non-orthonormal rotation or det R = -1: a row of solve_batch (solve "
           "and ContactPair raise ValueError instead).";
  if (name == "separated")
    return "SolverOptions.alpha_max is finite and a certified lower bound on alpha* exceeds it; alpha holds that bound "
           "(alpha_max < alpha <= alpha*); no x, multipliers or derivatives (the derivative functions raise).";
  return "See SolveStatus in idcol/result.hpp.";
}

}  // namespace

py::dict solve_result_state(const SolveResult& r) {
  const SolveResult::Internal& in = r.internal;
  py::dict d;
  d["status"] = static_cast<int>(r.status);
  d["alpha"] = r.alpha;
  d["x"] = reals_tuple(r.x_1.data(), 3);
  d["lambda1"] = r.lambda1;
  d["lambda2"] = r.lambda2;
  d["iterations"] = r.iterations;
  d["restarts"] = r.restarts;
  d["used_continuation"] = r.used_continuation;
  d["used_barrier"] = r.used_barrier;
  d["warm_started"] = r.warm_started;
  d["warm_start_fell_back"] = r.warm_start_fell_back;
  d["residual_norm"] = r.residual_norm;
  d["factorised"] = in.factorised;
  // The factors are defined only once computed: not written otherwise.
  if (in.factorised) {
    d["lu_factors"] = reals_tuple(in.lu.factors(), 36);
    py::tuple rows(6);
    for (int i = 0; i < 6; ++i) rows[static_cast<std::size_t>(i)] = in.lu.rows()[i];
    d["lu_rows"] = rows;
  } else {
    d["lu_factors"] = py::none();
    d["lu_rows"] = py::none();
  }
  d["k"] = in.k;
  d["length"] = in.length;
  d["row_scale"] = reals_tuple(in.row_scale.data(), 6);
  d["R"] = reals_tuple(in.R.data(), 9);  // column-major, as stored
  d["r"] = reals_tuple(in.r.data(), 3);
  d["y1"] = reals_tuple(in.y1.data(), 3);
  d["y2"] = reals_tuple(in.y2.data(), 3);
  d["e1_phi"] = in.e1.phi;
  d["e1_grad"] = reals_tuple(in.e1.grad.data(), 3);
  d["e1_hess"] = reals_tuple(in.e1.hess.data(), 9);
  d["e2_phi"] = in.e2.phi;
  d["e2_grad"] = reals_tuple(in.e2.grad.data(), 3);
  d["e2_hess"] = reals_tuple(in.e2.hess.data(), 9);
  return d;
}

SolveResult solve_result_from_state(py::handle state, const std::string& what) {
  StateReader s(state, what);
  SolveResult r;
  r.status = static_cast<SolveStatus>(s.integer("status", 0, kNumSolveStatuses - 1));
  r.alpha = s.real("alpha");
  s.reals("x", r.x_1.data(), 3);
  r.lambda1 = s.real("lambda1");
  r.lambda2 = s.real("lambda2");
  r.iterations = static_cast<int>(s.integer("iterations", 0, INT_MAX));
  r.restarts = static_cast<int>(s.integer("restarts", 0, INT_MAX));
  r.used_continuation = s.flag("used_continuation");
  r.used_barrier = s.flag("used_barrier");
  r.warm_started = s.flag("warm_started");
  r.warm_start_fell_back = s.flag("warm_start_fell_back");
  r.residual_norm = s.real("residual_norm");
  SolveResult::Internal& in = r.internal;
  in.factorised = s.flag("factorised");
  if (in.factorised && r.status != SolveStatus::Converged)
    s.fail("factorised",
           "is True but status is " + camel(to_string(r.status)) + " (only a Converged result keeps one)");
  const py::object rows = s.get("lu_rows");
  const char* lu_field = "lu_factors";
  if (!in.factorised) {
    if (!s.get(lu_field).is_none() || !rows.is_none())
      s.fail(lu_field, "and 'lu_rows' must be None when not factorised");
  } else {
    double f[36];
    s.reals(lu_field, f, 36);
    int perm[6];
    if (!py::isinstance<py::tuple>(rows) || py::len(rows) != 6) s.fail("lu_rows", "must be a tuple of 6 ints");
    for (int i = 0; i < 6; ++i) {
      const py::object v = py::reinterpret_borrow<py::tuple>(rows)[static_cast<std::size_t>(i)];
      long long x = 0;
      if (!int_in(v, 0, 5, x))
        s.fail("lu_rows", "[" + std::to_string(i) + "] must be an int in [0, 5], got " + std::string(py::repr(v)));
      perm[i] = static_cast<int>(x);
    }
    if (!in.lu.assign(f, perm)) s.fail("lu_rows", "must be a permutation of 0..5, got " + std::string(py::repr(rows)));
  }
  in.k = s.real("k");
  in.length = s.real("length");
  s.reals("row_scale", in.row_scale.data(), 6);
  s.reals("R", in.R.data(), 9);
  s.reals("r", in.r.data(), 3);
  s.reals("y1", in.y1.data(), 3);
  s.reals("y2", in.y2.data(), 3);
  in.e1.phi = s.real("e1_phi");
  s.reals("e1_grad", in.e1.grad.data(), 3);
  s.reals("e1_hess", in.e1.hess.data(), 9);
  in.e2.phi = s.real("e2_phi");
  s.reals("e2_grad", in.e2.grad.data(), 3);
  s.reals("e2_hess", in.e2.hess.data(), 9);
  s.done();
  // A Converged result is an answer: what the solver guarantees of one.
  if (r.status == SolveStatus::Converged) {
    const std::pair<const char*, double> positive[] = {
        {"alpha", r.alpha}, {"lambda1", r.lambda1}, {"lambda2", r.lambda2}};
    for (const auto& [field, v] : positive)
      if (!(std::isfinite(v) && v > 0.0)) s.fail(field, "of a Converged result must be finite and > 0, got " + num(v));
    if (!r.x_1.allFinite()) s.fail("x", "of a Converged result must be finite");
  }
  return r;
}

// Long: the module's declarations for solver.hpp, one statement a binding.
void bind_solve(py::module_& m) {
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
  compare_with_ints(status);

  // --- Results --------------------------------------------------------------
  py::class_<SolveResult> result(
      m, "SolveResult",
      "Result of one query. When status == Converged (vectors in body 1's frame): alpha > 0; x/alpha lies on body "
      "1's surface and R.T @ (x - p)/alpha on body 2's; lambda1 grad phi1 + lambda2 grad phi2 = 0 with lambda1, "
      "lambda2 > 0; the gap (1 - 1/alpha)|p| is > 0 iff alpha > 1. Other statuses: the fields hold the last "
      "iterate and must not be used as an answer. Pickles and deep-copies whole (the factorisation for "
      "derivatives included), field by field: the same result gives the same bytes, and a state that is not one "
      "(a field missing, mistyped or out of range) is a ValueError naming the field.");
  result.def_property_readonly("status", [](const SolveResult& r) { return r.status; })
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
      })
      // Pickled whole, the factorisation for derivatives included, field by
      // field (solve_result_state): the bytes depend on the result alone,
      // and another build of the module reads them back.
      .def("__reduce__", [](const SolveResult& r) {
        return py::make_tuple(py::module_::import("idcol").attr("_restore_solve_result"),
                              py::make_tuple(solve_result_state(r)));
      });
  forbid_new(result);
  m.def(
      "_solve_result",
      [](const py::object& state, const py::object& layout) {
        if (!layout.is_none() || py::isinstance<py::bytes>(state))
          throw py::value_error("this SolveResult was pickled as raw memory by another (older) build of idcol, "
                                "which is not read back; solve again");
        return solve_result_from_state(state, "SolveResult state");
      },
      py::arg("state"), py::arg("layout") = py::none(),
      "Rebuilds a SolveResult from its pickled state (used by pickle), validated field by field.");

  // --- Warm start -----------------------------------------------------------
  py::class_<WarmStart>(
      m, "WarmStart",
      "The warm-start state carried from one query to the next (C++ idcol::WarmStart): pass the same object as "
      "solve(..., warm_start=ws) along a trajectory; each successful solve updates it, a failed one leaves it. "
      "ContactPair holds one of its own. Pickles and deep-copies (state included).")
      .def(py::init<>())
      .def("reset", &WarmStart::reset, "Forget the state: the next solve starts cold.")
      .def_readonly("valid", &WarmStart::valid, "Holds a solution to start from.")
      .def("__repr__", [](const WarmStart& w) {
        return std::string("WarmStart(valid=") + (w.valid ? "True" : "False") + ", history=" + std::to_string(w.history) + ")";
      })
      .def(py::pickle(
          [](const WarmStart& w) {
            return py::make_tuple(w.valid, to_numpy(w.z), w.length, to_numpy(w.z_prev[0]), to_numpy(w.z_prev[1]),
                                  w.history, w.extrapolate);
          },
          // Validated as the solver leaves a state: a valid one holds a
          // finite solution z, a length scale > 0 and `history` finite
          // earlier solutions; an invalid one has no history.
          [](const py::tuple& t) {
            const std::string what = "WarmStart state";
            if (t.size() != 7) throw py::value_error(what + " must have 7 entries, got " + std::to_string(t.size()));
            WarmStart w;
            auto vec6 = [&](py::handle h, const char* field) {
              const CArray a = float_array(h, what + " '" + field + "'", {6});
              return Vec6(Eigen::Map<const Vec6>(a.data()));
            };
            auto flag = [&](py::handle h, const char* field) {
              if (!py::isinstance<py::bool_>(h))
                throw py::value_error(what + ": '" + field + "' must be True or False, got " +
                                      std::string(py::repr(h)));
              return h.cast<bool>();
            };
            w.valid = flag(t[0], "valid");
            w.z = vec6(t[1], "z");
            if (!py::isinstance<py::float_>(t[2]))
              throw py::value_error(what + ": 'length' must be a float, got " + std::string(py::repr(t[2])));
            w.length = t[2].cast<double>();
            w.z_prev[0] = vec6(t[3], "z_prev[0]");
            w.z_prev[1] = vec6(t[4], "z_prev[1]");
            long long history = 0;
            if (!int_in(t[5], 0, 2, history))
              throw py::value_error(what + ": 'history' must be 0, 1 or 2, got " + std::string(py::repr(t[5])));
            w.history = static_cast<int>(history);
            w.extrapolate = flag(t[6], "extrapolate");
            if (w.valid) {
              if (!w.z.allFinite()) throw py::value_error(what + ": 'z' must be finite when valid");
              if (!(std::isfinite(w.length) && w.length > 0.0))
                throw py::value_error(what + ": 'length' must be finite and > 0 when valid, got " + num(w.length));
              for (int i = 0; i < w.history; ++i)
                if (!w.z_prev[i].allFinite())
                  throw py::value_error(what + ": 'z_prev[" + std::to_string(i) + "]' must be finite (history " +
                                        std::to_string(w.history) + ")");
            } else if (w.history != 0) {
              throw py::value_error(what + ": 'history' must be 0 when not valid, got " + std::to_string(w.history));
            }
            return w;
          }));

  zero_new<WarmStart>();
  pickle_at_every_protocol(m.attr("WarmStart"));

  // --- One query ------------------------------------------------------------
  m.def(
      "solve",
      [](py::handle a, py::handle b, py::handle R, py::handle p, const py::object& options,
         const py::object& derivatives, const py::object& alpha_max, const py::object& warm_start) {
        const PyShape& s1 = as_shape(a, "a");
        const PyShape& s2 = as_shape(b, "b");
        const SolverOptions o = solve_options(options, derivatives, alpha_max);
        WarmStart* ws = nullptr;
        if (py::isinstance<WarmStart>(warm_start)) {
          ws = &warm_start.cast<WarmStart&>();
        } else if (!warm_start.is_none() && !(py::isinstance<py::bool_>(warm_start) && !warm_start.cast<bool>())) {
          throw py::type_error("warm_start must be an idcol.WarmStart (the state carried between calls), False or "
                               "None, got " + std::string(py::repr(warm_start)) +
                               "; solve keeps no state of its own (ContactPair does)");
        }
        const Pose X = to_pose(R, p);
        return solve(*s1.shape, *s2.shape, X, o, ws);
      },
      py::arg("a"), py::arg("b"), py::arg("R"), py::arg("p"), py::kw_only(), py::arg("options") = py::none(),
      py::arg("derivatives") = py::none(), py::arg("alpha_max") = py::none(), py::arg("warm_start") = py::none(),
      "Solve body a (at the identity) against body b at the relative pose X_12 = (R, p): R (3, 3) the rotation "
      "R_12, p (3,) the translation p_12 in body 1's frame, length units of the shapes; any real dtype and layout "
      "(float32/float16 rotations re-orthonormalised within 16 epsilons of their type, ValueError beyond). "
      "A NaN or Inf entry, a rotation not orthonormal to 1e-9 (||R^T R - I||_F) or with det R = -1 (a "
      "reflection) raises ValueError naming the argument and the entry (solve_batch marks such a row "
      "InvalidInput instead). Returns a SolveResult.\n\nKeywords shared with solve_batch: options (SolverOptions or "
      "None = defaults); "
      "derivatives (None: options.derivatives; True keeps the factorisation the derivative functions read); "
      "alpha_max (None: options.alpha_max; an early exit, status Separated, once alpha* is certified above it); "
      "warm_start (None/False: cold; an idcol.WarmStart: start from it and update it).");

  py::class_<PyContactPair>(m, "ContactPair",
                            "Two shapes and options, fixed (and validated) at construction, with the warm-start state "
                            "of the pair: each solve() starts from the previous successful one. Pickling and "
                            "deepcopy keep the shapes and options and drop the warm-start state.")
      .def(py::init([](py::object a, py::object b, const py::object& options) {
             const PyShape& s1 = as_shape(a, "a");
             const PyShape& s2 = as_shape(b, "b");
             return PyContactPair(a, b, ContactPair(*s1.shape, *s2.shape, options_or_default(options)));
           }),
           py::arg("a"), py::arg("b"), py::arg("options") = py::none())
      .def(
          "solve", [](PyContactPair& c, py::handle R, py::handle p) { return c.pair.solve(to_pose(R, p)); },
          py::arg("R"), py::arg("p"),
          "Solve at X_12 = (R (3, 3) rotation R_12, p (3,) translation p_12 in body 1's frame, length units; any "
          "real dtype, as for idcol.solve; a bad pose raises ValueError, as there), warm-started from the previous "
          "successful query.")
      .def(
          "solve_cold", [](const PyContactPair& c, py::handle R, py::handle p) { return c.pair.solve_cold(to_pose(R, p)); },
          py::arg("R"), py::arg("p"),
          "Solve cold at X_12 = (R, p) (as solve); the warm-start state is neither used nor changed.")
      .def("reset_warm_start", [](PyContactPair& c) { c.pair.reset_warm_start(); })
      .def_readonly("body1", &PyContactPair::body1)
      .def_readonly("body2", &PyContactPair::body2)
      .def_property_readonly("options", [](const PyContactPair& c) { return c.pair.options(); },
                             "A copy of the pair's options.")
      .def("__repr__", [](const PyContactPair& c) {
        return "ContactPair(" + shape_repr(c.pair.body1()) + ", " + shape_repr(c.pair.body2()) + ")";
      })
      .def("__reduce__", [](const py::object& self) {
        const auto& c = self.cast<const PyContactPair&>();
        return py::make_tuple(py::type::handle_of(self), py::make_tuple(c.body1, c.body2, py::cast(c.pair.options())));
      },
      "Pickles (and deep-copies) the shapes and options; the warm-start state is dropped, so the copy's first "
      "solve is cold.");
}

}  // namespace idcol::python

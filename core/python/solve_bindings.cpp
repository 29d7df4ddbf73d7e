// Python bindings: SolveStatus, SolveResult, WarmStart, solve and ContactPair.
#include <cstring>
#include <sstream>
#include <string>

#include "bindings.hpp"

namespace idcol::python {

namespace {

/// What must agree for a pickled SolveResult to be read back as bytes.
std::string result_layout() {
  return "idcol-" IDCOL_VERSION "-" + std::to_string(sizeof(SolveResult)) + "-" +
         std::to_string(alignof(SolveResult)) + "-" + std::to_string(sizeof(Lu6)) + "-" +
         (py::module_::import("sys").attr("byteorder").cast<std::string>());
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

}  // namespace

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

  // --- Results --------------------------------------------------------------
  py::class_<SolveResult> result(
      m, "SolveResult",
      "Result of one query. When status == Converged (vectors in body 1's frame): alpha > 0; x/alpha lies on body "
      "1's surface and R.T @ (x - p)/alpha on body 2's; lambda1 grad phi1 + lambda2 grad phi2 = 0 with lambda1, "
      "lambda2 > 0; the gap (1 - 1/alpha)|p| is > 0 iff alpha > 1. Other statuses: the fields hold the last "
      "iterate and must not be used as an answer. Pickles and deep-copies whole (the factorisation for "
      "derivatives included) within one build of the module.");
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
      // Pickled whole, the factorisation for derivatives included, as the
      // bytes of the C++ value (fixed-size members only): for copies within
      // one build of the module (deepcopy, multiprocessing), refused by
      // another build whose layout differs.
      .def("__reduce__", [](const SolveResult& r) {
        return py::make_tuple(py::module_::import("idcol").attr("_restore_solve_result"),
                              py::make_tuple(py::bytes(reinterpret_cast<const char*>(&r), sizeof r), result_layout()));
      });
  forbid_new(result);
  m.def(
      "_solve_result",
      [](const py::bytes& b, const std::string& layout) {
        const std::string raw = b;
        if (layout != result_layout() || raw.size() != sizeof(SolveResult))
          throw py::value_error("this SolveResult was pickled by another build of idcol (layout " + layout +
                                ", this one " + result_layout() + "); solve again");
        SolveResult r;
        std::memcpy(static_cast<void*>(&r), raw.data(), sizeof r);
        return r;
      },
      py::arg("state"), py::arg("layout"), "Rebuilds a SolveResult from its pickled state (used by pickle).");

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
          [](const py::tuple& t) {
            if (t.size() != 7) throw py::value_error("WarmStart state must have 7 entries");
            WarmStart w;
            auto vec6 = [](py::handle h) {
              const CArray a = float_array(h, "WarmStart state", {6});
              return Vec6(Eigen::Map<const Vec6>(a.data()));
            };
            w.valid = t[0].cast<bool>();
            w.z = vec6(t[1]);
            w.length = t[2].cast<double>();
            w.z_prev[0] = vec6(t[3]);
            w.z_prev[1] = vec6(t[4]);
            w.history = t[5].cast<int>();
            if (w.history < 0 || w.history > 2) throw py::value_error("WarmStart state: history must be 0, 1 or 2");
            w.extrapolate = t[6].cast<bool>();
            return w;
          }));

  zero_new<WarmStart>();

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
      "Returns a SolveResult.\n\nKeywords shared with solve_batch: options (SolverOptions or None = defaults); "
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
          "real dtype, as for idcol.solve), warm-started from the previous successful query.")
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

// Python bindings of the time of impact (idcol/toi.hpp): the options, the
// status, one query and a batch over many motions that releases the GIL and
// marks the rows it cannot query.
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "bindings.hpp"
#include "idcol/batch.hpp"
#include "idcol/toi.hpp"

namespace idcol::python {

namespace {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

ToiOptions toi_options(const py::object& options) {
  if (options.is_none()) return ToiOptions{};
  if (!py::isinstance<ToiOptions>(options))
    throw py::type_error("options must be an idcol.ToiOptions or None, got " + type_name(options));
  ToiOptions o = options.cast<ToiOptions>();
  o.validate();
  return o;
}

const char* toi_status_doc(ToiStatus s) {
  switch (s) {
    case ToiStatus::Impact: return "alpha* reaches 1 at t in (0, 1]; t is the first such time (to t_tolerance).";
    case ToiStatus::NoImpact: return "alpha* > 1 is certified on the whole of [0, 1].";
    case ToiStatus::InitiallyInContact: return "alpha*(0) <= 1 + alpha_tolerance.";
    case ToiStatus::NumericalFailure:
      return "A solve failed or t could not resolve the step; certified free up to t_free.";
    case ToiStatus::IterationLimit: return "max_solves spent; certified free up to t_free.";
    case ToiStatus::InvalidInput:
      return "Only in a batch: the motion's pose or displacement was refused (time_of_impact raises ValueError for "
             "it); the message is in ToiBatchResult.errors.";
  }
  return "";
}

// --- ToiResult, pickled field by field ---------------------------------------

py::dict toi_result_state(const ToiResult& r) {
  py::dict d;
  d["status"] = static_cast<int>(r.status);
  d["t"] = r.t;
  d["contact"] = solve_result_state(r.contact);
  d["R"] = reals_tuple(r.X_12.R.data(), 9);  // column-major, as stored
  d["p"] = reals_tuple(r.X_12.p.data(), 3);
  d["t_free"] = r.t_free;
  d["alpha_rate"] = r.alpha_rate;
  d["has_derivatives"] = r.has_derivatives;
  d["dt_dX0"] = reals_tuple(r.dt_dX0.data(), 6);
  d["dt_dX1"] = reals_tuple(r.dt_dX1.data(), 6);
  d["solves"] = r.solves;
  d["probes"] = r.probes;
  return d;
}

/// The state validated as time_of_impact leaves a result: a status of one
/// query (never InvalidInput), t and t_free in [0, 1], probes <= solves,
/// derivatives only on an Impact, and a valid contact solve.
ToiResult toi_result_from_state(py::handle state) {
  StateReader s(state, "ToiResult state");
  ToiResult r;
  r.status = static_cast<ToiStatus>(s.integer("status", 0, static_cast<int>(ToiStatus::IterationLimit)));
  r.t = s.real("t");
  if (!(r.t >= 0.0 && r.t <= 1.0)) s.fail("t", "must be in [0, 1], got " + num(r.t));
  r.contact = solve_result_from_state(s.get("contact"), "ToiResult state: 'contact'");
  s.reals("R", r.X_12.R.data(), 9);
  s.reals("p", r.X_12.p.data(), 3);
  r.t_free = s.real("t_free");
  if (!(r.t_free >= 0.0 && r.t_free <= 1.0)) s.fail("t_free", "must be in [0, 1], got " + num(r.t_free));
  r.alpha_rate = s.real("alpha_rate");
  r.has_derivatives = s.flag("has_derivatives");
  if (r.has_derivatives && r.status != ToiStatus::Impact)
    s.fail("has_derivatives", "is True but status is not Impact (only an Impact has derivatives)");
  s.reals("dt_dX0", r.dt_dX0.data(), 6);
  s.reals("dt_dX1", r.dt_dX1.data(), 6);
  r.solves = static_cast<int>(s.integer("solves", 0, INT_MAX));
  r.probes = static_cast<int>(s.integer("probes", 0, r.solves));
  s.done();
  return r;
}

// --- ToiBatchResult ----------------------------------------------------------

struct ToiField {
  const char* name;
  const char* doc;
  char dtype;  // 'd' float64, 'i' int32, 'b' bool
  std::vector<py::ssize_t> tail;
};

/// Every array of a ToiBatchResult, in repr order.
const ToiField kToiFields[] = {
    {"status", "(N,) int32 codes of idcol.ToiStatus; InvalidInput where time_of_impact refused the motion (the "
               "message in errors).", 'i', {}},
    {"t", "(N,) the first time of contact (Impact), 0 (InitiallyInContact), 1 (NoImpact) or t_free; NaN where "
          "InvalidInput.", 'd', {}},
    {"t_free", "(N,) alpha* > 1 is certified on [0, t_free]; NaN where InvalidInput.", 'd', {}},
    {"alpha", "(N,) alpha* of the contact solve at t (NaN when none).", 'd', {}},
    {"solves", "(N,) int32 solves spent on the motion (0 where InvalidInput).", 'i', {}},
    {"has_derivatives", "(N,) bool: dt_dX0 and dt_dX1 hold derivatives (an Impact, as ToiResult).", 'b', {}},
    {"dt_dX0", "(N, 6) dt*/d eta0 (NaN rows where has_derivatives is False).", 'd', {6}},
    {"dt_dX1", "(N, 6) dt*/d eta1 (NaN rows where has_derivatives is False).", 'd', {6}},
};

/// Row k's status, checking the code.
ToiStatus toi_status_at(const py::array_t<std::int32_t>& status, py::ssize_t k, const std::string& what) {
  const std::int32_t s = status.data()[k];
  if (s < 0 || s > static_cast<std::int32_t>(ToiStatus::InvalidInput))
    throw py::value_error(what + ": 'status'[" + std::to_string(k) + "] = " + std::to_string(s) +
                          " is not a ToiStatus code (0.." + std::to_string(static_cast<int>(ToiStatus::InvalidInput)) +
                          ")");
  return static_cast<ToiStatus>(s);
}

/// A ToiBatchResult from its pickled state: the arrays as kToiFields says
/// (dtype, shape, one N), status codes in range, solves >= 0, derivatives
/// only on Impact rows, and `errors` a dict {row: message} of exactly the
/// InvalidInput rows. ValueError naming the field otherwise.
PyToiBatch toi_batch_from_state(py::handle state, py::handle errors) {
  const std::string what = "ToiBatchResult state";
  if (!py::isinstance<py::dict>(state)) throw py::value_error(what + " must be a dict, got " + type_name(state));
  const py::dict d = py::reinterpret_borrow<py::dict>(state);
  for (auto item : d) {
    bool known = false;
    for (const ToiField& f : kToiFields)
      known = known || (py::isinstance<py::str>(item.first) && item.first.cast<std::string>() == f.name);
    if (!known) throw py::value_error(what + " has an unknown field " + std::string(py::repr(item.first)));
  }
  PyToiBatch b;
  py::ssize_t n = -1;
  for (const ToiField& f : kToiFields) {
    if (!d.contains(f.name)) throw py::value_error(what + " lacks '" + f.name + "'");
    const py::object v = d[f.name];
    if (f.dtype == 'd') b.arrays[f.name] = state_array<double>(v, what, f.name, n, f.tail);
    else if (f.dtype == 'i') b.arrays[f.name] = state_array<std::int32_t>(v, what, f.name, n, f.tail);
    else b.arrays[f.name] = state_array<bool>(v, what, f.name, n, f.tail);
  }
  const auto status = b.arrays["status"].cast<py::array_t<std::int32_t>>();
  const auto solves = b.arrays["solves"].cast<py::array_t<std::int32_t>>();
  const auto deriv = b.arrays["has_derivatives"].cast<py::array_t<bool>>();
  py::ssize_t invalid = 0;
  for (py::ssize_t k = 0; k < n; ++k) {
    const ToiStatus s = toi_status_at(status, k, what);
    invalid += s == ToiStatus::InvalidInput;
    if (solves.data()[k] < 0)
      throw py::value_error(what + ": 'solves'[" + std::to_string(k) + "] = " + std::to_string(solves.data()[k]) +
                            " is negative");
    if (deriv.data()[k] && s != ToiStatus::Impact)
      throw py::value_error(what + ": 'has_derivatives'[" + std::to_string(k) + "] is True on a row that is not an "
                            "Impact");
  }
  if (!py::isinstance<py::dict>(errors))
    throw py::value_error(what + ": 'errors' must be a dict {row: message}, got " + type_name(errors));
  for (auto item : py::reinterpret_borrow<py::dict>(errors)) {
    const py::handle k = item.first;
    long long row = 0;
    if (!int_in(k, 0, static_cast<long long>(n) - 1, row) ||
        toi_status_at(status, static_cast<py::ssize_t>(row), what) != ToiStatus::InvalidInput ||
        !py::isinstance<py::str>(item.second))
      throw py::value_error(what + ": 'errors' must map each InvalidInput row to its message (a str); got " +
                            std::string(py::repr(k)) + ": " + std::string(py::repr(item.second)));
    b.errors[k] = item.second;
  }
  if (static_cast<py::ssize_t>(b.errors.size()) != invalid)
    throw py::value_error(what + ": 'errors' holds " + std::to_string(b.errors.size()) + " messages for " +
                          std::to_string(invalid) + " InvalidInput rows");
  return b;
}

std::string toi_batch_repr(const PyToiBatch& b) {
  const auto status = b.arrays["status"].cast<py::array_t<std::int32_t>>();
  const py::ssize_t n = status.shape(0);
  std::string s = "ToiBatchResult(N=" + std::to_string(n);
  for (int c = 0; c <= static_cast<int>(ToiStatus::InvalidInput); ++c) {
    const auto count = std::count(status.data(), status.data() + n, c);
    if (count > 0) s += ", " + std::string(to_string(static_cast<ToiStatus>(c))) + "=" + std::to_string(count);
  }
  return s + ")";
}

/// The threads a batch of n motions runs on: `threads` (0: every CPU this
/// process may use), never more than those CPUs nor than the rows.
int toi_threads(int threads, py::ssize_t n) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: every CPU), got " + std::to_string(threads));
  const int cpus = resolve_thread_count(0);
  const int nt = threads == 0 ? cpus : std::min(threads, cpus);
  return static_cast<int>(std::min<py::ssize_t>(nt, std::max<py::ssize_t>(n, 1)));
}

/// (N, 3, 3) rotations and (N, 3) translations of one end of the motions.
std::pair<CArray, CArray> motion_end(py::handle R, py::handle p, const char* Rname, const char* pname) {
  CArray Ra = rotations(R, Rname, true), pa = float_array(p, pname);
  if (pa.ndim() != 2 || pa.shape(1) != 3)
    throw py::value_error(std::string(pname) + " must have shape (N, 3), got " + shape_str(pa));
  return {Ra, pa};
}

// Long: the NumPy arrays' checks and views of a batch of motions, then one
// call; split, each piece would take all the arrays.
PyToiBatch run_toi_batch(const Shape& s1, const Shape& s2, py::handle R0, py::handle p0, py::handle R1,
                         py::handle p1, const ToiOptions& o, int threads) {
  const auto [R0a, p0a] = motion_end(R0, p0, "R0", "p0");
  const auto [R1a, p1a] = motion_end(R1, p1, "R1", "p1");
  const py::ssize_t n = R0a.shape(0);
  if (p0a.shape(0) != n || R1a.shape(0) != n || p1a.shape(0) != n)
    throw py::value_error("R0, p0, R1, p1 must hold the same number of motions, got " + shape_str(R0a) + ", " +
                          shape_str(p0a) + ", " + shape_str(R1a) + ", " + shape_str(p1a));
  const int nt = toi_threads(threads, n);
  const std::size_t N = static_cast<std::size_t>(n);
  const double *R0d = R0a.data(), *p0d = p0a.data(), *R1d = R1a.data(), *p1d = p1a.data();
  auto pose = [](const double* R, const double* p, py::ssize_t k) {
    return Pose{Eigen::Map<const RowMat3>(R + 9 * k), Eigen::Map<const Vec3>(p + 3 * k)};
  };
  // The poses are checked here, with the GIL (the messages name the row); what
  // else time_of_impact refuses (a displacement that overflows) in the rows.
  std::vector<std::string> errors(N);
  for (py::ssize_t k = 0; k < n; ++k) {
    const std::string at = "[" + std::to_string(k) + "]";
    const Pose X0 = pose(R0d, p0d, k), X1 = pose(R1d, p1d, k);
    errors[static_cast<std::size_t>(k)] = pose_problem(X0.R, X0.p, "R0" + at, "p0" + at);
    if (errors[static_cast<std::size_t>(k)].empty())
      errors[static_cast<std::size_t>(k)] = pose_problem(X1.R, X1.p, "R1" + at, "p1" + at);
  }
  std::vector<ToiResult> res(N);
  std::vector<std::exception_ptr> fatal(static_cast<std::size_t>(nt));
  {
    py::gil_scoped_release release;
    auto run = [&](int part, py::ssize_t begin, py::ssize_t end) {
      try {
        for (py::ssize_t k = begin; k < end; ++k) {
          const std::size_t i = static_cast<std::size_t>(k);
          if (!errors[i].empty()) continue;
          try {
            res[i] = time_of_impact(s1, s2, pose(R0d, p0d, k), pose(R1d, p1d, k), o);
          } catch (const std::invalid_argument& e) {
            errors[i] = e.what();
          }
        }
      } catch (...) {
        fatal[static_cast<std::size_t>(part)] = std::current_exception();  // out of memory: raised below
      }
    };
    // Chunk i on thread i; the calling thread runs chunk 0 and any chunk
    // whose thread could not be started (a process out of threads).
    std::vector<std::thread> pool;
    int started = 1;
    try {
      pool.reserve(static_cast<std::size_t>(nt - 1));
      for (; started < nt; ++started) pool.emplace_back(run, started, n * started / nt, n * (started + 1) / nt);
    } catch (const std::system_error&) {
    }
    run(0, 0, n / nt);
    for (int i = started; i < nt; ++i) run(i, n * i / nt, n * (i + 1) / nt);
    for (auto& th : pool) th.join();
  }
  for (const std::exception_ptr& e : fatal)
    if (e) std::rethrow_exception(e);

  auto status = py::array_t<std::int32_t>(n), solves = py::array_t<std::int32_t>(n);
  auto t = py::array_t<double>(n), t_free = py::array_t<double>(n), alpha = py::array_t<double>(n);
  auto has_d = py::array_t<bool>(n);
  auto d0 = py::array_t<double>({n, py::ssize_t(6)}), d1 = py::array_t<double>({n, py::ssize_t(6)});
  const double nan = std::nan("");
  PyToiBatch out;
  for (py::ssize_t k = 0; k < n; ++k) {
    const std::size_t i = static_cast<std::size_t>(k);
    const ToiResult& r = res[i];
    const bool invalid = !errors[i].empty();
    const bool contact = !invalid && (r.status == ToiStatus::Impact || r.status == ToiStatus::InitiallyInContact);
    const bool deriv = !invalid && r.has_derivatives;
    status.mutable_data()[k] = static_cast<std::int32_t>(invalid ? ToiStatus::InvalidInput : r.status);
    solves.mutable_data()[k] = invalid ? 0 : r.solves;
    t.mutable_data()[k] = invalid ? nan : r.t;
    t_free.mutable_data()[k] = invalid ? nan : r.t_free;
    alpha.mutable_data()[k] = contact ? r.contact.alpha : nan;
    has_d.mutable_data()[k] = deriv;
    for (int j = 0; j < 6; ++j) {
      d0.mutable_data()[6 * k + j] = deriv ? r.dt_dX0[j] : nan;
      d1.mutable_data()[6 * k + j] = deriv ? r.dt_dX1[j] : nan;
    }
    if (invalid) out.errors[py::int_(k)] = errors[i];
  }
  out.arrays["status"] = frozen(status), out.arrays["t"] = frozen(t), out.arrays["t_free"] = frozen(t_free);
  out.arrays["alpha"] = frozen(alpha), out.arrays["solves"] = frozen(solves);
  out.arrays["has_derivatives"] = frozen(has_d), out.arrays["dt_dX0"] = frozen(d0), out.arrays["dt_dX1"] = frozen(d1);
  return out;
}

}  // namespace

// Long: the module's declarations for toi.hpp, one statement a binding.
void bind_toi(py::module_& m) {
  py::enum_<ToiStatus> status(m, "ToiStatus", py::arithmetic(),
                              "How a time-of-impact query ended (C++ idcol::ToiStatus). Batch results hold these as "
                              "int32 codes: idcol.ToiStatus(code).");
  for (ToiStatus s : {ToiStatus::Impact, ToiStatus::NoImpact, ToiStatus::InitiallyInContact,
                      ToiStatus::NumericalFailure, ToiStatus::IterationLimit, ToiStatus::InvalidInput})
    status.value(camel(to_string(s)).c_str(), s, toi_status_doc(s));
  compare_with_ints(status);

  py::class_<ToiOptions>(m, "ToiOptions",
                         "Options of time_of_impact (C++ idcol::ToiOptions): t_tolerance, alpha_tolerance, max_solves, "
                         "derivatives, solver (an idcol.SolverOptions). Validated when the query runs. Pickles.")
      .def(py::init([](double t_tolerance, double alpha_tolerance, int max_solves, bool derivatives,
                       const py::object& solver) {
             ToiOptions o;
             o.t_tolerance = t_tolerance;
             o.alpha_tolerance = alpha_tolerance;
             o.max_solves = max_solves;
             o.derivatives = derivatives;
             if (!solver.is_none()) o.solver = solver.cast<SolverOptions>();
             o.validate();
             return o;
           }),
           py::kw_only(), py::arg("t_tolerance") = ToiOptions{}.t_tolerance,
           py::arg("alpha_tolerance") = ToiOptions{}.alpha_tolerance, py::arg("max_solves") = ToiOptions{}.max_solves,
           py::arg("derivatives") = ToiOptions{}.derivatives, py::arg("solver") = py::none())
      .def_readwrite("t_tolerance", &ToiOptions::t_tolerance)
      .def_readwrite("alpha_tolerance", &ToiOptions::alpha_tolerance)
      .def_readwrite("max_solves", &ToiOptions::max_solves)
      .def_readwrite("derivatives", &ToiOptions::derivatives)
      .def_readwrite("solver", &ToiOptions::solver)
      .def("__repr__",
           [](const ToiOptions& o) {
             return "ToiOptions(t_tolerance=" + num(o.t_tolerance) + ", alpha_tolerance=" + num(o.alpha_tolerance) +
                    ", max_solves=" + std::to_string(o.max_solves) + ", derivatives=" +
                    (o.derivatives ? "True" : "False") + ", solver=" + std::string(py::repr(py::cast(o.solver))) + ")";
           })
      .def(py::pickle(
          [](const ToiOptions& o) {
            py::dict d;
            d["t_tolerance"] = o.t_tolerance;
            d["alpha_tolerance"] = o.alpha_tolerance;
            d["max_solves"] = o.max_solves;
            d["derivatives"] = o.derivatives;
            d["solver"] = o.solver;
            return d;
          },
          [](const py::dict& state) {
            StateReader s(state, "ToiOptions state");
            ToiOptions o;
            o.t_tolerance = s.real("t_tolerance");
            o.alpha_tolerance = s.real("alpha_tolerance");
            o.max_solves = static_cast<int>(s.integer("max_solves", INT_MIN, INT_MAX));
            o.derivatives = s.flag("derivatives");
            const py::object solver = s.get("solver");
            if (!py::isinstance<SolverOptions>(solver))
              s.fail("solver", "must be an idcol.SolverOptions, got " + type_name(solver));
            o.solver = solver.cast<SolverOptions>();
            s.done();
            o.validate();
            return o;
          }));
  pickle_at_every_protocol(m.attr("ToiOptions"));

  py::class_<ToiResult> result(
      m, "ToiResult",
      "The first time of contact along a motion. contact is the SolveResult at t (Impact, InitiallyInContact), R "
      "and p the relative pose there; dt_dX0, dt_dX1 are dt*/d(eta0, eta1) for body twists (w, v) applied on the "
      "right of the end poses. Returned by time_of_impact only. Pickles and deep-copies field by field (a state "
      "that is not one is a ValueError naming the field).");
  result.def_readonly("status", &ToiResult::status)
      .def_readonly("t", &ToiResult::t)
      .def_readonly("contact", &ToiResult::contact)
      .def_property_readonly("R", [](const ToiResult& r) { return to_numpy(r.X_12.R); })
      .def_property_readonly("p", [](const ToiResult& r) { return to_numpy(r.X_12.p); })
      .def_readonly("t_free", &ToiResult::t_free, "alpha* > 1 is certified on [0, t_free].")
      .def_readonly("alpha_rate", &ToiResult::alpha_rate, "d alpha*/dt at t.")
      .def_readonly("has_derivatives", &ToiResult::has_derivatives)
      .def_property_readonly("dt_dX0", [](const ToiResult& r) { return to_numpy(r.dt_dX0); })
      .def_property_readonly("dt_dX1", [](const ToiResult& r) { return to_numpy(r.dt_dX1); })
      .def_readonly("solves", &ToiResult::solves)
      .def_readonly("probes", &ToiResult::probes)
      .def("__repr__",
           [](const ToiResult& r) {
             return "ToiResult(status=" + camel(to_string(r.status)) + ", t=" + num(r.t) +
                    ", solves=" + std::to_string(r.solves) + ")";
           })
      .def("__reduce__", [](const ToiResult& r) {
        return py::make_tuple(py::module_::import("idcol").attr("_restore_toi_result"),
                              py::make_tuple(toi_result_state(r)));
      });
  forbid_new(result);
  m.def("_toi_result", &toi_result_from_state, py::arg("state"),
        "Rebuilds a ToiResult from its pickled state (used by pickle), validated field by field.");

  m.def(
      "time_of_impact",
      [](py::handle a, py::handle b, py::handle R0, py::handle p0, py::handle R1, py::handle p1,
         const py::object& options) {
        const Shape& s1 = *as_shape(a, "a").shape;
        const Shape& s2 = *as_shape(b, "b").shape;
        const Pose X0 = to_pose(R0, p0, "R0", "p0"), X1 = to_pose(R1, p1, "R1", "p1");
        const ToiOptions o = toi_options(options);
        py::gil_scoped_release release;
        return time_of_impact(s1, s2, X0, X1, o);
      },
      py::arg("a"), py::arg("b"), py::arg("R0"), py::arg("p0"), py::arg("R1"), py::arg("p1"),
      py::arg("options") = py::none(),
      "First time of contact of body b moving relative to body a from X0 = (R0, p0) at t = 0 to X1 = (R1, p1) at "
      "t = 1 along the screw motion X(t) = X0 exp(t log(X0^-1 X1)) (exactly p0 + t (p1 - p0) when R0 == R1). "
      "Certified: alpha* > 1 on [0, t) is proven, not sampled. Returns a ToiResult. Poses as for solve (any real "
      "dtype); a NaN or Inf entry, a rotation not orthonormal to 1e-9 or a reflection, or a displacement beyond the "
      "double range raises ValueError naming the argument.");

  std::string doc =
      "Arrays of a time_of_impact_batch, one row per motion, all read-only; errors maps each InvalidInput row to "
      "the reason time_of_impact refused it. Pickles and deep-copies.\n\nFields:\n";
  for (const ToiField& f : kToiFields) doc += "  " + std::string(f.name) + ": " + f.doc + "\n";
  py::class_<PyToiBatch> batch(m, "ToiBatchResult", doc.c_str());
  for (const ToiField& f : kToiFields) {
    const std::string name = f.name;
    batch.def_property_readonly(
        f.name, [name](const PyToiBatch& b) -> py::object { return b.arrays[name.c_str()]; }, f.doc);
  }
  batch
      .def_property_readonly(
          "errors", [](const PyToiBatch& b) { return py::dict(b.errors.attr("copy")()); },
          "{row: message} for every row marked InvalidInput (a copy).")
      .def("__len__", [](const PyToiBatch& b) { return py::len(b.arrays["status"]); })
      .def("__repr__", &toi_batch_repr)
      .def("__reduce__", [](const PyToiBatch& b) {
        return py::make_tuple(py::module_::import("idcol").attr("_restore_toi_batch_result"),
                              py::make_tuple(b.arrays, b.errors));
      });
  forbid_new(batch);
  m.def("_toi_batch_result", &toi_batch_from_state, py::arg("state"), py::arg("errors"),
        "Rebuilds a ToiBatchResult from its pickled state (used by pickle), validated field by field.");

  m.def(
      "time_of_impact_batch",
      [](py::handle a, py::handle b, py::handle R0, py::handle p0, py::handle R1, py::handle p1,
         const py::object& options, int threads) {
        const Shape& s1 = *as_shape(a, "a").shape;
        const Shape& s2 = *as_shape(b, "b").shape;
        return run_toi_batch(s1, s2, R0, p0, R1, p1, toi_options(options), threads);
      },
      py::arg("a"), py::arg("b"), py::arg("R0"), py::arg("p0"), py::arg("R1"), py::arg("p1"),
      py::arg("options") = py::none(), py::arg("threads") = 1,
      "time_of_impact over N motions: R0, R1 (N, 3, 3), p0, p1 (N, 3), any real dtype (float32/float16 rotations "
      "as in solve_batch). The GIL is released; the rows are split in contiguous chunks over `threads` threads (0: "
      "every CPU this process may use; never more than those CPUs, nor than the rows), and each row's answer does "
      "not depend on the thread count. A motion that time_of_impact would refuse (a NaN or Inf entry, a rotation "
      "not orthonormal to 1e-9 or a reflection, a displacement beyond the double range) is marked "
      "ToiStatus.InvalidInput, NaN times, with its message in errors; the other rows are answered. Returns a "
      "ToiBatchResult of arrays.");
}

}  // namespace idcol::python

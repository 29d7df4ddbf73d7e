// Python bindings: solve_batch and BatchResult.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <sstream>
#include <string>
#include <tuple>

#include "bindings.hpp"
#include "idcol/batch.hpp"

namespace idcol::python {

namespace {

/// One shape for every row, or a sequence (list, tuple, NumPy object array)
/// of N shapes.
/// `keep` holds a reference to every shape used, so that no shape can be
/// freed while the GIL is released (another thread emptying the list).
void gather(py::handle obj, const char* name, std::size_t n, std::vector<const Shape*>& out,
            std::vector<std::shared_ptr<const Shape>>& keep) {
  if (py::isinstance<PyShape>(obj)) {
    keep.push_back(obj.cast<const PyShape&>().shape);
    out.assign(1, keep.back().get());
    return;
  }
  if (!py::isinstance<py::sequence>(obj) || py::isinstance<py::str>(obj))
    throw py::type_error(std::string(name) + " must be an idcol shape or a sequence of one shape per pose, got " +
                         std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(obj);
  if (seq.size() != n)
    throw py::value_error(std::string(name) + " holds " + std::to_string(seq.size()) + " shapes but R and p hold " +
                          std::to_string(n) + " poses");
  out.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::shared_ptr<const Shape>& s = as_shape(seq[k], std::string(name) + "[" + std::to_string(k) + "]").shape;
    if (keep.empty() || keep.back() != s) keep.push_back(s);
    out[k] = s.get();
  }
}

struct Field {
  const char* name;
  const char* doc;
  char dtype;  // 'd' float64, 'i' int32, 'b' bool
  std::vector<py::ssize_t> tail;  // shape after N
  /// Which fields come together: 'r' always; 'k' kinematics; 'w' world
  /// frame (with kinematics); 'd' dalpha_dxi; 'e' kinematics derivatives
  /// (kinematics and derivatives); 'f' world-frame derivatives; 'c' the
  /// contact wrench (contact=); 'g' its derivatives (contact and derivatives).
  char group;
};

/// Every array a BatchResult may hold, in repr order.
const Field kBatchFields[] = {
    {"alpha", "(N,) alpha*, the minimal common scaling (dimensionless).", 'd', {}, 'r'},
    {"x", "(N, 3) x*, the contact point of the scaled bodies, body-1 frame, length units.", 'd', {3}, 'r'},
    {"status", "(N,) int32 codes of SolveStatus (idcol.SolveStatus(code)).", 'i', {}, 'r'},
    {"iterations", "(N,) int32 Newton steps over every run.", 'i', {}, 'r'},
    {"converged", "(N,) bool, status == Converged.", 'b', {}, 'r'},
    {"gap", "(N,) gap = (1 - 1/alpha*)|p|, length units, > 0 separated (NaN where not converged).", 'd', {}, 'k'},
    {"normal", "(N, 3) body 1's outward unit normal at p1, body-1 frame (NaN where not converged).", 'd', {3}, 'k'},
    {"p1", "(N, 3) witness point on body 1, body-1 frame, length units (NaN where not converged).", 'd', {3}, 'k'},
    {"p2", "(N, 3) witness point on body 2, body-1 frame: p2 - p1 = gap p/|p| (NaN where not converged).", 'd', {3},
     'k'},
    {"normal_W", "(N, 3) normal in the world frame: R_W1 @ normal (None unless R_W1, p_W1 are given).", 'd', {3},
     'w'},
    {"p1_W", "(N, 3) p1 in the world frame: R_W1 @ p1 + p_W1 (None unless R_W1, p_W1 are given).", 'd', {3}, 'w'},
    {"p2_W", "(N, 3) p2 in the world frame: R_W1 @ p2 + p_W1 (None unless R_W1, p_W1 are given).", 'd', {3}, 'w'},
    {"dalpha_dxi", "(N, 6) d alpha*/d xi, xi = (w, v) the body twist of X_12 (derivatives=True; zero rows where "
                   "not converged).", 'd', {6}, 'd'},
    {"dgap_dxi", "(N, 6) d gap/d xi (derivatives=True; zero rows where not converged).", 'd', {6}, 'e'},
    {"dnormal_dxi", "(N, 3, 6) d normal/d xi, body-1 frame (derivatives=True).", 'd', {3, 6}, 'e'},
    {"dp1_dxi", "(N, 3, 6) d p1/d xi, body-1 frame (derivatives=True).", 'd', {3, 6}, 'e'},
    {"dp2_dxi", "(N, 3, 6) d p2/d xi, body-1 frame (derivatives=True).", 'd', {3, 6}, 'e'},
    {"dnormal_W_dxi", "(N, 3, 6) d normal_W/d xi = R_W1 @ dnormal_dxi: the same twist xi of X_12 (body 2 moved, body 1 "
                      "held), in the world frame (derivatives=True with R_W1, p_W1).", 'd', {3, 6}, 'f'},
    {"dp1_W_dxi", "(N, 3, 6) d p1_W/d xi = R_W1 @ dp1_dxi (derivatives=True with R_W1, p_W1).", 'd', {3, 6}, 'f'},
    {"dp2_W_dxi", "(N, 3, 6) d p2_W/d xi = R_W1 @ dp2_dxi (derivatives=True with R_W1, p_W1).", 'd', {3, 6}, 'f'},
    {"f_n", "(N,) Hertz force f_n = k delta^p, delta = -gap (contact=HertzModel; 0 when apart, NaN where a row's force "
            "is unknown: not converged, and not Separated with alpha_max >= 1).", 'd', {}, 'c'},
    {"F1", "(N, 6) wrench on body 1, body-1 frame about its origin, (moment, force) (contact=...).", 'd', {6}, 'c'},
    {"F2", "(N, 6) wrench on body 2, body-2 frame about its origin: -Ad_{X_12}^T F1 (contact=...).", 'd', {6}, 'c'},
    {"df_n_dxi", "(N, 6) d f_n/d xi (contact=... and derivatives=True; zeros where no active contact).", 'd', {6}, 'g'},
    {"dF1_dxi", "(N, 6, 6) d F1/d xi (contact=... and derivatives=True).", 'd', {6, 6}, 'g'},
    {"dF2_dxi", "(N, 6, 6) d F2/d xi (contact=... and derivatives=True).", 'd', {6, 6}, 'g'},
};

/// A BatchResult from its pickled state, every array checked: dtype, shape
/// and one N for all; the fields that come together present together; the
/// status codes in range, iterations >= 0, converged == (status ==
/// Converged). ValueError naming the field otherwise.
PyBatchResult batch_result_from_state(py::handle state) {
  const std::string what = "BatchResult state";
  if (!py::isinstance<py::dict>(state)) throw py::value_error(what + " must be a dict, got " + type_name(state));
  const py::dict d = py::reinterpret_borrow<py::dict>(state);
  for (auto item : d) {
    bool known = false;
    for (const Field& f : kBatchFields)
      known = known || (py::isinstance<py::str>(item.first) && item.first.cast<std::string>() == f.name);
    if (!known) throw py::value_error(what + " has an unknown field " + std::string(py::repr(item.first)));
  }
  PyBatchResult r;
  py::ssize_t n = -1;
  std::string have, lack;  // groups with a field present / absent
  for (const Field& f : kBatchFields) {
    // The wrench fields came later: a state without them (pickled by an
    // earlier build) reads them as None.
    const bool later = f.group == 'c' || f.group == 'g';
    if (!d.contains(f.name) && !later) throw py::value_error(what + " lacks '" + f.name + "'");
    const py::object v = d.contains(f.name) ? py::object(d[f.name]) : py::none();
    if (v.is_none()) {
      if (f.group == 'r') throw py::value_error(what + ": '" + f.name + "' must be an array, got None");
      r.arrays[f.name] = py::none();
      lack += f.group;
      continue;
    }
    have += f.group;
    if (f.dtype == 'd') r.arrays[f.name] = state_array<double>(v, what, f.name, n, f.tail);
    else if (f.dtype == 'i') r.arrays[f.name] = state_array<std::int32_t>(v, what, f.name, n, f.tail);
    else r.arrays[f.name] = state_array<bool>(v, what, f.name, n, f.tail);
  }
  auto has = [&](char g) { return have.find(g) != std::string::npos; };
  auto all = [&](char g) { return has(g) && lack.find(g) == std::string::npos; };
  auto first_of = [](char g) {
    for (const Field& f : kBatchFields)
      if (f.group == g) return std::string(f.name);
    return std::string();
  };
  for (char g : std::string("kwdefcg"))
    if (has(g) && !all(g))
      throw py::value_error(what + ": the fields of '" + first_of(g) + "' come together: some are None, some not");
  if (has('w') && !has('k')) throw py::value_error(what + ": 'normal_W' is given without 'normal' (kinematics)");
  if (has('e') != (has('k') && has('d')))
    throw py::value_error(what + ": 'dgap_dxi' must be given exactly when 'gap' and 'dalpha_dxi' are");
  if (has('f') != (has('w') && has('d')))
    throw py::value_error(what + ": 'dnormal_W_dxi' must be given exactly when 'normal_W' and 'dalpha_dxi' are");
  if (has('g') != (has('c') && has('d')))
    throw py::value_error(what + ": 'dF1_dxi' must be given exactly when 'F1' and 'dalpha_dxi' are");
  const auto status = r.arrays["status"].cast<py::array_t<std::int32_t>>();
  const auto its = r.arrays["iterations"].cast<py::array_t<std::int32_t>>();
  const auto conv = r.arrays["converged"].cast<py::array_t<bool>>();
  for (py::ssize_t k = 0; k < n; ++k) {
    const std::int32_t s = status.data()[k];
    if (s < 0 || s >= kNumSolveStatuses)
      throw py::value_error(what + ": 'status'[" + std::to_string(k) + "] = " + std::to_string(s) +
                            " is not a SolveStatus code (0.." + std::to_string(kNumSolveStatuses - 1) + ")");
    if (its.data()[k] < 0)
      throw py::value_error(what + ": 'iterations'[" + std::to_string(k) + "] = " + std::to_string(its.data()[k]) +
                            " is negative");
    if (conv.data()[k] != (s == static_cast<std::int32_t>(SolveStatus::Converged)))
      throw py::value_error(what + ": 'converged'[" + std::to_string(k) + "] disagrees with 'status'[" +
                            std::to_string(k) + "]");
  }
  return r;
}

std::pair<CArray, CArray> batch_poses(py::handle R, py::handle p, const char* Rname, const char* pname) {
  CArray Ra = rotations(R, Rname, true), pa = float_array(p, pname);
  if (pa.ndim() != 2 || pa.shape(1) != 3)
    throw py::value_error(std::string(pname) + " must have shape (N, 3), got " + shape_str(pa));
  if (Ra.shape(0) != pa.shape(0))
    throw py::value_error(std::string(Rname) + " holds " + std::to_string(Ra.shape(0)) + " poses but " + pname +
                          " holds " + std::to_string(pa.shape(0)));
  return {Ra, pa};
}

template <class T>
py::array_t<T> rows(py::ssize_t n, std::initializer_list<py::ssize_t> tail = {}) {
  std::vector<py::ssize_t> shape{n};
  shape.insert(shape.end(), tail.begin(), tail.end());
  return py::array_t<T>(shape);
}

template <class T>
Span<T> span_of(py::array_t<T>& a) {
  return {a.mutable_data(), static_cast<std::size_t>(a.size())};
}

/// What the calling thread's poll (BatchOptions::poll) needs: the batch's
/// cancel flag and whether Ctrl-C was seen.
struct SignalPoll {
  std::atomic<bool>* cancel;
  std::chrono::steady_clock::time_point last;
  bool interrupted = false;
};

/// Every 50 ms at most: take the GIL and run the signal handlers. Ctrl-C
/// sets the batch's cancel flag (the workers stop before their next row) and
/// leaves KeyboardInterrupt set in this thread, raised once the batch returns.
void poll_signals(void* data) {
  SignalPoll& s = *static_cast<SignalPoll*>(data);
  if (s.interrupted) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - s.last < std::chrono::milliseconds(50)) return;
  s.last = now;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) {
    s.interrupted = true;
    s.cancel->store(true);
  }
}

/// Runs core's batch with the GIL released, on the calling thread and
/// `threads - 1` workers. Only the main thread runs Python's signal handlers,
/// so a call from the main thread polls them between its rows (BatchOptions::
/// poll); a call from another thread does not (Ctrl-C is the main thread's).
void run_interruptible(Span<const Shape* const> s1, Span<const Shape* const> s2, Span<const double> Rs,
                       Span<const double> ps, BatchOptions& o, const BatchOutput& out) {
  std::atomic<bool> cancel{false};
  o.cancel = &cancel;
  SignalPoll poll{&cancel, std::chrono::steady_clock::now()};
  const py::module_ threading = py::module_::import("threading");
  if (threading.attr("current_thread")().is(threading.attr("main_thread")())) {
    o.poll = &poll_signals;
    o.poll_data = &poll;
  }
  {
    py::gil_scoped_release release;
    solve_batch(s1, s2, Rs, ps, o, out);
  }
  if (poll.interrupted) throw py::error_already_set();
}

/// Body 1's world pose: one (R_W1 (3, 3), p_W1 (3,)) for every row, or one
/// per row ((N, 3, 3), (N, 3)), as (K, 3, 3) and (K, 3) arrays. Each must be
/// a rigid pose: these are not the rows' queries but what turns their
/// answers into the world frame, so a bad one is a ValueError naming it
/// (R_W1[k] for a row), never a converged row with a wrong normal.
std::pair<CArray, CArray> world_poses(const py::object& R_W1, const py::object& p_W1) {
  const py::module_ np = py::module_::import("numpy");
  py::array Ra = np.attr("asarray")(R_W1), pa = np.attr("asarray")(p_W1);
  const bool single = Ra.ndim() == 2 && pa.ndim() == 1;
  if (Ra.ndim() == 2) Ra = Ra.attr("reshape")(1, 3, 3);
  if (pa.ndim() == 1) pa = pa.attr("reshape")(1, -1);
  auto [RW, pW] = batch_poses(Ra, pa, "R_W1", "p_W1");
  using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  for (py::ssize_t k = 0; k < RW.shape(0); ++k) {
    const std::string at = single ? std::string() : "[" + std::to_string(k) + "]";
    const std::string bad = pose_problem(Eigen::Map<const RowMat3>(RW.data() + 9 * k),
                                         Eigen::Map<const Vec3>(pW.data() + 3 * k), "R_W1" + at, "p_W1" + at);
    if (!bad.empty()) throw py::value_error(bad + " (body 1's world pose)");
  }
  return {RW, pW};
}

/// The per-row warm states of `warm` (None: none), N of them.
PyWarmStarts* warm_rows(const py::object& warm, std::size_t n, bool warm_start) {
  if (warm.is_none()) return nullptr;
  if (!py::isinstance<PyWarmStarts>(warm))
    throw py::type_error("warm must be an idcol.WarmStarts (one state per row) or None, got " + type_name(warm));
  PyWarmStarts& w = warm.cast<PyWarmStarts&>();
  if (w.states.size() != n)
    throw py::value_error("warm holds " + std::to_string(w.states.size()) + " states but R and p hold " +
                          std::to_string(n) + " poses");
  if (warm_start)
    throw py::value_error("warm (one state per row) and warm_start=True (chains of rows) are two modes: give one");
  return &w;
}

// Long: the NumPy arrays' checks and views for every batch mode, then one
// call; split, each piece would take all the arrays.
PyBatchResult run_batch(const std::vector<const Shape*>& b1, const std::vector<const Shape*>& b2, const CArray& R,
                        const CArray& p, const SolverOptions& so, bool warm_start, int threads,
                        long long warm_chain, bool kinematics, const py::object& R_W1, const py::object& p_W1,
                        const py::object& warm, const py::object& contact) {
  BatchOptions o;
  o.solver = so;
  o.warm_start = warm_start;
  o.derivatives = so.derivatives;
  if (threads < 0) throw py::value_error("BatchOptions: field 'threads' must be >= 0 (0 = all CPUs), got " +
                                         std::to_string(threads));
  // Never more threads than CPUs this process may run on.
  o.threads = threads == 0 ? 0 : std::min(threads, resolve_thread_count(0));
  if (warm_chain < 1) throw py::value_error("warm_chain must be >= 1, got " + std::to_string(warm_chain));
  o.warm_chain = static_cast<std::size_t>(warm_chain);
  o.validate();
  const auto n = static_cast<py::ssize_t>(p.shape(0));
  const std::size_t N = static_cast<std::size_t>(n);
  const bool world = !R_W1.is_none() || !p_W1.is_none();
  if (world && !kinematics) throw py::value_error("R_W1 and p_W1 give the kinematics in the world frame: they need kinematics=True");
  CArray RW, pW;
  if (world) {
    if (R_W1.is_none() || p_W1.is_none()) throw py::value_error("give both R_W1 and p_W1 (body 1's world pose) or neither");
    std::tie(RW, pW) = world_poses(R_W1, p_W1);
    if (RW.shape(0) != n && RW.shape(0) != 1)
      throw py::value_error("R_W1 and p_W1 must hold 1 pose or one per row (" + std::to_string(n) + "), got " +
                            std::to_string(RW.shape(0)));
  }

  auto alpha = rows<double>(n), x = rows<double>(n, {3});
  auto status = rows<std::int32_t>(n), iterations = rows<std::int32_t>(n);
  BatchOutput out;  // the optional spans stay empty unless asked for below
  out.alpha = span_of(alpha);
  out.x_1 = span_of(x);
  out.status = span_of(status);
  out.iterations = span_of(iterations);
  py::array_t<double> dalpha, gap, normal, p1, p2, dgap, dnormal, dp1, dp2;
  if (o.derivatives) dalpha = rows<double>(n, {6}), out.dalpha_dxi = span_of(dalpha);
  if (kinematics) {
    gap = rows<double>(n), normal = rows<double>(n, {3}), p1 = rows<double>(n, {3}), p2 = rows<double>(n, {3});
    out.gap = span_of(gap), out.normal_1 = span_of(normal), out.p1_1 = span_of(p1), out.p2_1 = span_of(p2);
    if (o.derivatives) {
      dgap = rows<double>(n, {6}), dnormal = rows<double>(n, {3, 6}), dp1 = rows<double>(n, {3, 6});
      dp2 = rows<double>(n, {3, 6});
      out.dgap_dxi = span_of(dgap), out.dnormal_dxi = span_of(dnormal), out.dp1_dxi = span_of(dp1);
      out.dp2_dxi = span_of(dp2);
    }
  }
  PyWarmStarts* ws = warm_rows(warm, N, warm_start);
  if (ws) out.warm = ws->states;
  const bool wrench = !contact.is_none();
  py::array_t<double> fn, F1, F2, dfn, dF1, dF2;
  if (wrench) {
    o.contact = hertz_model(contact);
    fn = rows<double>(n), F1 = rows<double>(n, {6}), F2 = rows<double>(n, {6});
    out.f_n = span_of(fn), out.F1_1 = span_of(F1), out.F2_2 = span_of(F2);
    if (o.derivatives) {
      dfn = rows<double>(n, {6}), dF1 = rows<double>(n, {6, 6}), dF2 = rows<double>(n, {6, 6});
      out.df_n_dxi = span_of(dfn), out.dF1_dxi = span_of(dF1), out.dF2_dxi = span_of(dF2);
    }
  }
  // The warm states are written by the workers while the GIL is released:
  // the WarmStarts object is kept alive by the caller's reference (`warm`).
  run_interruptible({b1.data(), b1.size()}, {b2.data(), b2.size()}, {R.data(), 9 * N}, {p.data(), 3 * N}, o, out);

  PyBatchResult r;
  for (const Field& f : kBatchFields) r.arrays[f.name] = py::none();
  auto conv = rows<bool>(n);
  for (std::size_t k = 0; k < N; ++k)
    conv.mutable_data()[k] = status.data()[k] == static_cast<std::int32_t>(SolveStatus::Converged);
  r.arrays["alpha"] = frozen(alpha), r.arrays["x"] = frozen(x), r.arrays["status"] = frozen(status);
  r.arrays["iterations"] = frozen(iterations), r.arrays["converged"] = frozen(conv);
  if (o.derivatives) r.arrays["dalpha_dxi"] = frozen(dalpha);
  if (kinematics) {
    r.arrays["gap"] = frozen(gap), r.arrays["normal"] = frozen(normal), r.arrays["p1"] = frozen(p1);
    r.arrays["p2"] = frozen(p2);
    if (o.derivatives) {
      r.arrays["dgap_dxi"] = frozen(dgap), r.arrays["dnormal_dxi"] = frozen(dnormal), r.arrays["dp1_dxi"] = frozen(dp1);
      r.arrays["dp2_dxi"] = frozen(dp2);
    }
  }
  if (wrench) {
    r.arrays["f_n"] = frozen(fn), r.arrays["F1"] = frozen(F1), r.arrays["F2"] = frozen(F2);
    if (o.derivatives) r.arrays["df_n_dxi"] = frozen(dfn), r.arrays["dF1_dxi"] = frozen(dF1), r.arrays["dF2_dxi"] = frozen(dF2);
  }
  if (world) {
    auto nW = rows<double>(n, {3}), p1W = rows<double>(n, {3}), p2W = rows<double>(n, {3});
    using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    const bool one = RW.shape(0) == 1;
    for (std::size_t k = 0; k < N; ++k) {
      const std::size_t w = one ? 0 : k;
      const Eigen::Map<const RowMat3> Rw(RW.data() + 9 * w);
      const Eigen::Map<const Vec3> pw(pW.data() + 3 * w);
      Eigen::Map<Vec3>(nW.mutable_data() + 3 * k) = Rw * Eigen::Map<const Vec3>(normal.data() + 3 * k);
      Eigen::Map<Vec3>(p1W.mutable_data() + 3 * k) = Rw * Eigen::Map<const Vec3>(p1.data() + 3 * k) + pw;
      Eigen::Map<Vec3>(p2W.mutable_data() + 3 * k) = Rw * Eigen::Map<const Vec3>(p2.data() + 3 * k) + pw;
    }
    r.arrays["normal_W"] = frozen(nW), r.arrays["p1_W"] = frozen(p1W), r.arrays["p2_W"] = frozen(p2W);
    if (o.derivatives) {
      // Body 1 held in the world: the world-frame derivatives are the body-1
      // frame ones turned by R_W1 (p_W1 is constant).
      using RowMat36 = Eigen::Matrix<double, 3, 6, Eigen::RowMajor>;
      auto turned = [&](const py::array_t<double>& d) {
        auto out = rows<double>(n, {3, 6});
        for (std::size_t k = 0; k < N; ++k) {
          const Eigen::Map<const RowMat3> Rw(RW.data() + 9 * (one ? 0 : k));
          Eigen::Map<RowMat36>(out.mutable_data() + 18 * k) = Rw * Eigen::Map<const RowMat36>(d.data() + 18 * k);
        }
        return out;
      };
      r.arrays["dnormal_W_dxi"] = frozen(turned(dnormal)), r.arrays["dp1_W_dxi"] = frozen(turned(dp1));
      r.arrays["dp2_W_dxi"] = frozen(turned(dp2));
    }
  }
  return r;
}

std::string batch_repr(const PyBatchResult& r) {
  const py::array alpha = r.arrays["alpha"];
  const py::array conv = r.arrays["converged"];
  const auto n = alpha.shape(0);
  py::ssize_t c = 0;
  for (py::ssize_t k = 0; k < n; ++k) c += static_cast<const bool*>(conv.data())[k] ? 1 : 0;
  std::string s = "BatchResult(N=" + std::to_string(n) + ", converged=" + std::to_string(c);
  if (n > 0) {
    double lo = 0, hi = 0;
    bool any = false;
    for (py::ssize_t k = 0; k < n; ++k) {
      if (!static_cast<const bool*>(conv.data())[k]) continue;
      const double a = static_cast<const double*>(alpha.data())[k];
      lo = any ? std::min(lo, a) : a, hi = any ? std::max(hi, a) : a, any = true;
    }
    if (any) s += ", alpha in [" + num(lo) + ", " + num(hi) + "]";
  }
  s += ", arrays=[";
  bool first = true;
  for (const Field& f : kBatchFields)
    if (!r.arrays[f.name].is_none()) s += (first ? "" : ", ") + std::string(f.name), first = false;
  return s + "])";
}

}  // namespace

// Long: the module's declarations for batch.hpp, one statement a binding.
void bind_batch(py::module_& m) {
  std::string doc =
      "Arrays of a batch, one row per pose, all read-only (np.array(a) gives a writable copy); None where not "
      "asked for. Frames: body-1 frame unless the name ends in _W (world frame, given R_W1, p_W1). Derivatives "
      "are w.r.t. xi = (w, v), the body twist of X_12 (angular first). Pickles and deep-copies.\n\nFields:\n";
  for (const Field& f : kBatchFields) doc += "  " + std::string(f.name) + ": " + f.doc + "\n";
  py::class_<PyBatchResult> cls(m, "BatchResult", doc.c_str());
  for (const Field& f : kBatchFields) {
    const std::string name = f.name;
    cls.def_property_readonly(f.name, [name](const PyBatchResult& r) -> py::object { return r.arrays[name.c_str()]; },
                              f.doc);
  }
  cls.def("__len__", [](const PyBatchResult& r) { return py::len(r.arrays["alpha"]); })
      .def("__repr__", &batch_repr)
      .def("__reduce__", [](const PyBatchResult& r) {
        return py::make_tuple(py::module_::import("idcol").attr("_restore_batch_result"), py::make_tuple(r.arrays));
      });
  m.def("_batch_result", &batch_result_from_state, py::arg("state"),
        "Rebuilds a BatchResult from its pickled state (used by pickle), validated field by field.");
  forbid_new(cls);

  const char* batch_doc =
      "Solve N queries in one call, with the GIL released, over `threads` worker threads (0 = every CPU this "
      "process may use; never more than those) in contiguous chunks (C++ idcol::solve_batch). Ctrl-C stops the "
      "workers before their next row and raises KeyboardInterrupt.\n\n"
      "R: (N, 3, 3) rotations R_12, p: (N, 3) translations p_12 (length units of the shapes): body 2's pose in "
      "body 1's frame, any layout and any real dtype: float32/float16 rotations are re-orthonormalised within 16 "
      "epsilons of their type (ValueError naming the row beyond it), integers converted; complex, bool and object "
      "arrays are a TypeError. A row whose pose has a NaN or Inf entry, a rotation not orthonormal to 1e-9 "
      "(||R^T R - I||_F) or det R = -1 is that row's status InvalidInput (NaN kinematics, zero derivatives); the "
      "other rows are solved. Bodies: `a` and `b` are each one shape for every row or a sequence of N shapes "
      "(mixed families are fine); or give `pairs`, a sequence of N (a, b) tuples.\n\n"
      "Keywords shared with solve: options (SolverOptions or None), derivatives (None: options.derivatives), "
      "alpha_max (None: options.alpha_max; rows certified beyond it end Separated early), warm_start.\n"
      "warm_start=True warm-starts each row from the previous one inside chains of `warm_chain` rows (reset at "
      "each chain start and where the pair changes), so results never depend on `threads`: they equal the serial "
      "loop of idcol.solve (cold) or of ContactPair.solve restarted every warm_chain rows (warm), bit for bit.\n"
      "kinematics=True (default) also returns gap, normal, p1, p2 (body-1 frame) and, with derivatives, "
      "dgap_dxi, dnormal_dxi, dp1_dxi, dp2_dxi; R_W1 (3, 3) or (N, 3, 3) and p_W1 (3,) or (N, 3), body 1's world "
      "pose (each a rigid pose as above, else a ValueError naming it), add normal_W, p1_W, p2_W (and with "
      "derivatives dnormal_W_dxi, dp1_W_dxi, dp2_W_dxi). derivatives=True returns dalpha_dxi (N, 6).\n"
      "warm=WarmStarts(N) gives every row its own warm state, in and out (a simulator's pairs, each carried from "
      "its last call; not with warm_start=True). contact=HertzModel(...) adds each row's Hertz wrench f_n, F1, F2 "
      "and, with derivatives, df_n_dxi, dF1_dxi, dF2_dxi. Every row equals the loop of idcol.solve and "
      "idcol.contact_wrench, bit for bit. Returns a BatchResult.";
  m.def(
      "solve_batch",
      [](py::handle pairs, py::handle R, py::handle p, const py::object& options,
                   const py::object& derivatives, const py::object& alpha_max, bool warm_start, int threads,
                   long long warm_chain, bool kinematics, const py::object& R_W1, const py::object& p_W1,
                   const py::object& warm, const py::object& contact) {
        const auto [Ra, pa] = batch_poses(R, p, "R", "p");
        const std::size_t n = static_cast<std::size_t>(pa.shape(0));
        if (!py::isinstance<py::sequence>(pairs))
          throw py::type_error("pairs must be a sequence of (a, b) shape tuples");
        const py::sequence seq = py::reinterpret_borrow<py::sequence>(pairs);
        if (seq.size() != n)
          throw py::value_error("pairs holds " + std::to_string(seq.size()) + " pairs but R and p hold " +
                                std::to_string(n) + " poses");
        std::vector<const Shape*> b1(n), b2(n);
        std::vector<std::shared_ptr<const Shape>> keep;  // alive while the GIL is released
        for (std::size_t k = 0; k < n; ++k) {
          const py::object item = seq[k];
          const std::string at = "pairs[" + std::to_string(k) + "]";
          if (!py::isinstance<py::sequence>(item) || py::len(item) != 2)
            throw py::type_error(at + " must be an (a, b) tuple of shapes");
          const auto& s1 = as_shape(item[py::int_(0)], at + "[0]").shape;
          const auto& s2 = as_shape(item[py::int_(1)], at + "[1]").shape;
          if (keep.size() < 2 || keep[keep.size() - 2] != s1 || keep.back() != s2) keep.push_back(s1), keep.push_back(s2);
          b1[k] = s1.get();
          b2[k] = s2.get();
        }
        return run_batch(b1, b2, Ra, pa, solve_options(options, derivatives, alpha_max), warm_start, threads,
                         warm_chain, kinematics, R_W1, p_W1, warm, contact);
      },
      py::arg("pairs"), py::arg("R"), py::arg("p"), py::kw_only(), py::arg("options") = py::none(),
      py::arg("derivatives") = py::none(), py::arg("alpha_max") = py::none(), py::arg("warm_start") = false,
      py::arg("threads") = 0, py::arg("warm_chain") = 1024, py::arg("kinematics") = true,
      py::arg("R_W1") = py::none(), py::arg("p_W1") = py::none(), py::arg("warm") = py::none(),
      py::arg("contact") = py::none(), batch_doc);
  m.def(
      "solve_batch",
      [](py::handle a, py::handle b, py::handle R, py::handle p, const py::object& options,
                   const py::object& derivatives, const py::object& alpha_max, bool warm_start, int threads,
                   long long warm_chain, bool kinematics, const py::object& R_W1, const py::object& p_W1,
                   const py::object& warm, const py::object& contact) {
        const auto [Ra, pa] = batch_poses(R, p, "R", "p");
        const std::size_t n = static_cast<std::size_t>(pa.shape(0));
        std::vector<const Shape*> b1, b2;
        std::vector<std::shared_ptr<const Shape>> keep;  // alive while the GIL is released
        gather(a, "a", n, b1, keep);
        gather(b, "b", n, b2, keep);
        return run_batch(b1, b2, Ra, pa, solve_options(options, derivatives, alpha_max), warm_start, threads,
                         warm_chain, kinematics, R_W1, p_W1, warm, contact);
      },
      py::arg("a"), py::arg("b"), py::arg("R"), py::arg("p"), py::kw_only(), py::arg("options") = py::none(),
      py::arg("derivatives") = py::none(), py::arg("alpha_max") = py::none(), py::arg("warm_start") = false,
      py::arg("threads") = 0, py::arg("warm_chain") = 1024, py::arg("kinematics") = true,
      py::arg("R_W1") = py::none(), py::arg("p_W1") = py::none(), py::arg("warm") = py::none(),
      py::arg("contact") = py::none(), batch_doc);
}

}  // namespace idcol::python

#include "idcol/batch.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <functional>
#include <iterator>
#include <tuple>
#include <utility>
#include <system_error>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#if defined(__linux__)
#include <sched.h>
#endif

#include "batch_simd.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"

namespace idcol {

namespace {

[[noreturn]] void bad(const std::string& what) { throw std::invalid_argument("solve_batch: " + what); }

std::string sz(std::size_t n) { return std::to_string(n); }

/// Row k's pose from a row-major 3x3 block and a 3-vector.
struct RowMajorPoses {
  const double* R;
  const double* p;
  detail::PoseRows rows() const { return {nullptr, R, p}; }
  Pose operator()(std::size_t k) const {
    Pose X;
    X.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R + 9 * k);
    X.p = Eigen::Map<const Vec3>(p + 3 * k);
    return X;
  }
};

struct PoseList {
  const Pose* poses;
  detail::PoseRows rows() const { return {poses, nullptr, nullptr}; }
  const Pose& operator()(std::size_t k) const { return poses[k]; }
};

void check_bodies(const char* field, Span<const Shape* const> bodies, std::size_t n) {
  if (bodies.size() != 1 && bodies.size() != n)
    bad(std::string(field) + " must hold 1 shape or one per row (" + sz(n) + "), got " + sz(bodies.size()));
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies[i] == nullptr) bad(std::string(field) + "[" + sz(i) + "] is a null shape");
}

void check_output(const char* field, std::size_t got, std::size_t want) {
  if (got != want) bad("output " + std::string(field) + " must hold " + sz(want) + " values, got " + sz(got));
}

bool wants_kinematics(const BatchOutput& out) {
  return !out.gap.empty() || !out.normal_1.empty() || !out.p1_1.empty() || !out.p2_1.empty();
}

bool wants_kinematics_derivatives(const BatchOutput& out) {
  return !out.dgap_dxi.empty() || !out.dnormal_dxi.empty() || !out.dp1_dxi.empty() || !out.dp2_dxi.empty();
}

bool wants_wrench(const BatchOutput& out) { return !out.f_n.empty() || !out.F1_1.empty() || !out.F2_2.empty(); }

bool wants_wrench_derivatives(const BatchOutput& out) {
  return !out.df_n_dxi.empty() || !out.dF1_dxi.empty() || !out.dF2_dxi.empty();
}

/// n values of row k from src (entry j at src[j * stride]), or zeros.
void put_row(Span<double> dst, std::size_t k, int n, const double* src, int stride = 1) {
  static constexpr double kZeros[36] = {};
  if (dst.empty()) return;
  if (!src) src = kZeros, stride = 1;
  for (int j = 0; j < n; ++j) dst[n * k + j] = src[j * stride];
}

/// The optional wrench outputs of row k (BatchOutput) from w, the row's
/// contact_wrench() (an invalid one where the row did not converge), and
/// `derivatives()`, its contact_wrench_derivatives(), called only for an
/// active contact. Zero where the bodies certainly do not touch (inactive,
/// or `known`: Separated with alpha_max >= 1), NaN values where the force
/// is unknown (another status); zero derivatives wherever there is no
/// active converged contact.
template <class Derivatives>
void put_wrench(std::size_t k, const ContactWrench& w, bool known, Derivatives derivatives, const BatchOutput& out) {
  if (wants_wrench(out)) {
    const double v = known ? 0.0 : std::numeric_limits<double>::quiet_NaN();
    const Vec6 fill = Vec6::Constant(v);
    if (!out.f_n.empty()) out.f_n[k] = w.active ? w.f_n : v;
    put_row(out.F1_1, k, 6, (w.active ? w.F1_1 : fill).data());
    put_row(out.F2_2, k, 6, (w.active ? w.F2_2 : fill).data());
  }
  if (!wants_wrench_derivatives(out)) return;
  if (w.active) {
    const ContactWrenchDerivatives d = derivatives();
    if (d.valid) {
      // Row-major 6 x 6 blocks (Eigen's matrices are column-major).
      const Mat6r dF1 = d.dF1_1_dxi, dF2 = d.dF2_2_dxi;
      put_row(out.df_n_dxi, k, 6, d.df_n_dxi.data());
      put_row(out.dF1_dxi, k, 36, dF1.data());
      put_row(out.dF2_dxi, k, 36, dF2.data());
      return;
    }
  }
  put_row(out.df_n_dxi, k, 6, nullptr);  // no active converged contact: zero derivatives
  put_row(out.dF1_dxi, k, 36, nullptr);
  put_row(out.dF2_dxi, k, 36, nullptr);
}

/// The wrench outputs of row k from its result (put_wrench). The
/// sensitivity is formed only for an active contact.
void write_wrench(std::size_t k, const SolveResult& res, const BatchOptions& o, const SolverOptions& so,
                  const BatchOutput& out) {
  ContactWrench w;
  if (res.converged()) w = contact_wrench(res, o.contact);
  const bool known = res.converged() || (res.status == SolveStatus::Separated && so.alpha_max >= 1.0);
  put_wrench(k, w, known, [&] { return contact_wrench_derivatives(res, solution_sensitivity(res), o.contact); }, out);
}

/// The kinematics' derivatives of row k (zeros where d is not valid).
void put_kinematics_derivatives(std::size_t k, const ContactKinematicsDerivatives& d, const BatchOutput& out) {
  auto put36 = [&](Span<double> dst, const Mat36& M) {
    const Eigen::Matrix<double, 3, 6, Eigen::RowMajor> R = M;
    put_row(dst, k, 18, d.valid ? R.data() : nullptr);
  };
  put_row(out.dgap_dxi, k, 6, d.valid ? d.dgap_dxi.data() : nullptr);
  put36(out.dnormal_dxi, d.dnhat_1_dxi);
  put36(out.dp1_dxi, d.dp1_1_dxi);
  put36(out.dp2_dxi, d.dp2_1_dxi);
}

/// The optional kinematics outputs of row k (BatchOutput): NaN values and
/// zero derivatives where the result has no valid kinematics.
void write_kinematics(std::size_t k, const SolveResult& res, const BatchOutput& out) {
  auto put3 = [k](Span<double> dst, const Vec3& v) {
    if (!dst.empty())
      for (int j = 0; j < 3; ++j) dst[3 * k + j] = v[j];
  };
  if (wants_kinematics(out)) {
    // Only a converged result has a contact (contact_kinematics throws for
    // Separated, which carries a bound, not a contact).
    ContactKinematics c;
    if (res.converged()) c = contact_kinematics(res);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (!out.gap.empty()) out.gap[k] = c.valid ? c.gap : nan;
    put3(out.normal_1, c.valid ? c.nhat_1 : Vec3::Constant(nan));
    put3(out.p1_1, c.valid ? c.p1_1 : Vec3::Constant(nan));
    put3(out.p2_1, c.valid ? c.p2_1 : Vec3::Constant(nan));
  }
  if (wants_kinematics_derivatives(out))
    put_kinematics_derivatives(
        k, res.converged() ? contact_kinematics_derivatives(res, solution_sensitivity(res)) : ContactKinematicsDerivatives{},
        out);
}

/// Row k's outputs beyond alpha, x_1, status and iterations, from its result.
void write_optional(std::size_t k, const SolveResult& res, const BatchOptions& o, const SolverOptions& so,
                    const BatchOutput& out) {
  if (o.derivatives) {
    const Row6 g = res.converged() ? alpha_gradient(res) : Row6::Zero();
    for (int j = 0; j < 6; ++j) out.dalpha_dxi[6 * k + j] = g[j];
  }
  write_kinematics(k, res, out);
  if (wants_wrench(out) || wants_wrench_derivatives(out)) write_wrench(k, res, o, so, out);
}

/// The same for a converged row whose derivatives and wrench the Newton
/// lanes formed (d: NewtonFinishIO's rows, entry e at d[e * W]; the row's
/// kinematics written already, with its answer): as put_wrench writes
/// them, zeros where the contact is inactive, and zero derivatives where
/// its force is not representable.
void write_derived(std::size_t k, const double* d, int W, const BatchOptions& o, const BatchOutput& out) {
  using namespace detail;  // the rows' names
  if (o.derivatives) put_row(out.dalpha_dxi, k, 6, d + kDerivAlpha * W, W);
  put_row(out.dgap_dxi, k, 6, d + kDerivGap * W, W);
  put_row(out.dnormal_dxi, k, 18, d + kDerivNormal * W, W);
  put_row(out.dp1_dxi, k, 18, d + kDerivP1 * W, W);
  put_row(out.dp2_dxi, k, 18, d + kDerivP2 * W, W);
  const bool active = d[kDerivActive * W] != 0.0;
  if (!out.f_n.empty()) out.f_n[k] = active ? d[kDerivFn * W] : 0.0;
  put_row(out.F1_1, k, 6, active ? d + kDerivF1 * W : nullptr, W);
  put_row(out.F2_2, k, 6, active ? d + kDerivF2 * W : nullptr, W);
  const bool derived = active && d[kDerivRepresentable * W] != 0.0;
  put_row(out.df_n_dxi, k, 6, derived ? d + kDerivDFn * W : nullptr, W);
  put_row(out.dF1_dxi, k, 36, derived ? d + kDerivDF1 * W : nullptr, W);
  put_row(out.dF2_dxi, k, 36, derived ? d + kDerivDF2 * W : nullptr, W);
}

/// Every output of row k from its result. For a result Separated at once
/// (SolveResult's defaults but status and alpha) no output but alpha
/// reads alpha: copy_separated relies on it to write such rows as copies
/// of one, and test_batch_rows.cpp compares every output with the loop's.
void write_row(std::size_t k, const SolveResult& res, const BatchOptions& o, const SolverOptions& so,
               const BatchOutput& out) {
  out.alpha[k] = res.alpha;
  out.x_1[3 * k] = res.x_1[0];
  out.x_1[3 * k + 1] = res.x_1[1];
  out.x_1[3 * k + 2] = res.x_1[2];
  out.status[k] = static_cast<std::int32_t>(res.status);
  out.iterations[k] = res.iterations;
  write_optional(k, res, o, so, out);
}

/// Rows between two calls of BatchOptions::poll on the calling thread.
constexpr std::size_t kPollRows = 64;
/// Cold rows a thread takes at a time: a multiple of kPollRows and of every
/// SIMD lane count; small enough that the last blocks even out the threads'
/// finishing times, large enough that taking one costs nothing.
constexpr std::size_t kColdBlock = 256;

/// Rows [lo, hi): one contiguous chunk, run by one thread. `lo` is a chain
/// start when warm-starting, so the chunk repeats the serial loop exactly.
/// `caller`: this is the thread that called solve_batch, which polls.
template <class Poses>
void run_rows(std::size_t lo, std::size_t hi, Span<const Shape* const> b1, Span<const Shape* const> b2,
              const Poses& poses, const BatchOptions& o, const SolverOptions& so, const BatchOutput& out,
              bool caller, WarmStart* chain_ws = nullptr, const detail::ColdResume* resume = nullptr) {
  const bool per_row1 = b1.size() != 1, per_row2 = b2.size() != 1;
  const bool polls = caller && o.poll != nullptr;
  WarmStart local;
  WarmStart& ws = chain_ws ? *chain_ws : local;  // the chain's, when the SIMD path hands a row back mid-chain
  for (std::size_t k = lo; k < hi; ++k) {
    if (polls && k != lo && (k - lo) % kPollRows == 0) o.poll(o.poll_data);
    if (o.cancel != nullptr && o.cancel->load(std::memory_order_relaxed)) return;
    const Shape& a = *b1[per_row1 ? k : 0];
    const Shape& b = *b2[per_row2 ? k : 0];
    if (o.warm_start && (k % o.warm_chain == 0 || (per_row1 && b1[k] != b1[k - 1]) || (per_row2 && b2[k] != b2[k - 1])))
      ws.reset();
    WarmStart* const warm = !out.warm.empty() ? &out.warm[k] : o.warm_start ? &ws : nullptr;
    const SolveResult res =
        resume ? detail::solve_cold_resumed(a, b, poses(k), so, *resume) : solve(a, b, poses(k), so, warm);
    write_row(k, res, o, so, out);
  }
}

template <class Poses>
void run(std::size_t n, Span<const Shape* const> b1, Span<const Shape* const> b2, const Poses& poses,
         const BatchOptions& o, const BatchOutput& out, bool screened = false);

/// The double output fields of BatchOutput: name, member, values per row.
/// From kFirstOptional on, each may be empty (not asked for).
struct DoubleField {
  const char* name;
  Span<double> BatchOutput::*field;
  std::size_t per_row;
};
constexpr DoubleField kDoubleFields[] = {
    {"alpha", &BatchOutput::alpha, 1},         {"x_1", &BatchOutput::x_1, 3},
    {"dalpha_dxi", &BatchOutput::dalpha_dxi, 6}, {"gap", &BatchOutput::gap, 1},
    {"normal_1", &BatchOutput::normal_1, 3},   {"p1_1", &BatchOutput::p1_1, 3},
    {"p2_1", &BatchOutput::p2_1, 3},           {"dgap_dxi", &BatchOutput::dgap_dxi, 6},
    {"dnormal_dxi", &BatchOutput::dnormal_dxi, 18}, {"dp1_dxi", &BatchOutput::dp1_dxi, 18},
    {"dp2_dxi", &BatchOutput::dp2_dxi, 18},    {"f_n", &BatchOutput::f_n, 1},
    {"F1_1", &BatchOutput::F1_1, 6},           {"F2_2", &BatchOutput::F2_2, 6},
    {"df_n_dxi", &BatchOutput::df_n_dxi, 6},   {"dF1_dxi", &BatchOutput::dF1_dxi, 36},
    {"dF2_dxi", &BatchOutput::dF2_dxi, 36}};
constexpr std::size_t kFirstOptional = 3;
constexpr Span<std::int32_t> BatchOutput::*kIntFields[] = {&BatchOutput::status, &BatchOutput::iterations};

/// n values of T, default-initialised (doubles and ints left as they are).
template <class T>
struct RawBuffer {
  std::unique_ptr<T[]> p;
  std::size_t n = 0;
  void resize(std::size_t m) {
    p.reset(new T[m]);
    n = m;
  }
  T* data() const { return p.get(); }
  std::size_t size() const { return n; }
};

/// The rows `rows` of a batch as a batch of their own: their poses and warm
/// states copied in (and, when the run may be cancelled, their outputs'
/// present values, so that the rows it does not reach stay as they were),
/// run with `b1`, `b2` (one shape, or one per row of the sub-batch) and
/// options `o`, and every output copied back. `screened`: no row is
/// Separated at once (screen_group found none), so the lanes need not test.
template <class Poses>
void run_sub_batch(const std::vector<std::size_t>& rows, Span<const Shape* const> b1, Span<const Shape* const> b2,
                   const Poses& poses, const BatchOptions& o, const BatchOutput& out, bool screened = false) {
  const std::size_t m = rows.size();
  std::vector<Pose> X(m);
  for (std::size_t i = 0; i < m; ++i) X[i] = poses(rows[i]);
  constexpr std::size_t nd = sizeof(kDoubleFields) / sizeof(kDoubleFields[0]);
  // Left uninitialised until the sub-batch writes them (a zero fill was one
  // more pass over every output: at 10,000 bodies with derivatives, 170
  // values a row, a third of what the copies cost).
  RawBuffer<double> dbuf[nd];
  RawBuffer<std::int32_t> ibuf[2];
  RawBuffer<WarmStart> wbuf;
  BatchOutput sub;
  // `state`: the field is read as well as written (the warm states).
  auto copy = [&](auto& buf, auto field, std::size_t per, bool in, bool state = false) {
    auto& whole = out.*field;
    if (whole.empty()) return;
    if (in) buf.resize(per * m);
    sub.*field = {buf.data(), buf.size()};
    if (in && o.cancel == nullptr && !state) return;  // every row is written
    for (std::size_t i = 0; i < m; ++i) {  // a row's values are contiguous in either
      auto* a = whole.data() + per * rows[i];
      auto* b = buf.data() + per * i;
      if (in) std::copy_n(a, per, b);
      else std::copy_n(b, per, a);
    }
  };
  auto copy_all = [&](bool in) {
    for (std::size_t f = 0; f < nd; ++f) copy(dbuf[f], kDoubleFields[f].field, kDoubleFields[f].per_row, in);
    for (std::size_t f = 0; f < 2; ++f) copy(ibuf[f], kIntFields[f], 1, in);
    copy(wbuf, &BatchOutput::warm, 1, in, true);
  };
  copy_all(true);
  run(m, b1, b2, PoseList{X.data()}, o, sub, screened);
  copy_all(false);
}

/// Row k's outputs written as row `first`'s, but alpha: both Separated at
/// once (separated_bound), whose results differ in alpha alone (the bound),
/// and no output of such a row but alpha reads it (write_row: no contact,
/// zero derivatives, the wrench's zeros or NaN by status and alpha_max).
void copy_separated(std::size_t first, std::size_t k, double alpha, const BatchOutput& out) {
  // The rows' lengths known at compile time, so that each copy is a few
  // moves in line rather than a call of memmove (which took a fifth of the
  // Separated rows' time in bench_sim_batch's ten64_separated).
  auto copy = [](const double* a, double* b, auto per_row) {
    for (std::size_t j = 0; j < decltype(per_row)::value; ++j) b[j] = a[j];
  };
  for (const DoubleField& f : kDoubleFields) {
    const Span<double>& v = out.*f.field;
    if (v.empty()) continue;
    const double* a = v.data() + f.per_row * first;
    double* b = v.data() + f.per_row * k;
    switch (f.per_row) {
      case 1: copy(a, b, std::integral_constant<std::size_t, 1>{}); break;
      case 3: copy(a, b, std::integral_constant<std::size_t, 3>{}); break;
      case 6: copy(a, b, std::integral_constant<std::size_t, 6>{}); break;
      case 18: copy(a, b, std::integral_constant<std::size_t, 18>{}); break;
      case 36: copy(a, b, std::integral_constant<std::size_t, 36>{}); break;
      default: std::copy_n(a, f.per_row, b);
    }
  }
  for (const auto field : kIntFields) (out.*field)[k] = (out.*field)[first];
  out.alpha[k] = alpha;
}

/// Row k, which solve() answers Separated at once with the bound `lower`
/// (separated_bound), written as run_rows writes solve()'s answer: in full
/// (write_row of SolveResult's defaults but status and alpha), or, where
/// `like` names a row written so before (npos: none), as a copy of its
/// outputs (copy_separated). The row's warm state is left as solve()
/// leaves it there: its predictor history restarts.
void write_separated(std::size_t k, double lower, std::size_t like, const BatchOptions& o, const SolverOptions& so,
                     const BatchOutput& out) {
  if (like != detail::kNoRow) {
    copy_separated(like, k, lower, out);
  } else {
    SolveResult sep;
    sep.status = SolveStatus::Separated;
    sep.alpha = lower;
    write_row(k, sep, o, so, out);
  }
  if (!out.warm.empty()) out.warm[k].history = 0;
}

/// Of the rows k marked kScreen in `state`, those that solve() answers
/// Separated at once (a finite alpha_max below their certified bound:
/// separated_bound) written here as solve()'s answer (write_separated: the
/// first in full, the next as copies of it), and marked kAnswered. In row order, as the loop reads the poses and writes
/// the outputs: screened a pair's group at a time, rows 45 apart in the 64
/// ten-body scenes of bench_sim_batch, each row's pose and outputs were a
/// cache miss, and its Separated rows cost the batch 1.4x the loop's time.
/// The lanes screen each group's rows first (separated_rows_lanes, W rows
/// of one pair a call, the bounds only: no output written there), and
/// this loop then writes the rows they found Separated at once and passes
/// over those they found solved; separated_bound decides the rest.
/// Whether any row was answered.
enum RowState : std::uint8_t { kLoop, kScreen, kAnswered };
template <class Poses, class Pair>
bool screen_rows(std::vector<std::uint8_t>& state, const Pair& pair, const Poses& poses, const BatchOptions& o,
                 const SolverOptions& so, const BatchOutput& out,
                 const std::vector<std::pair<const Shape*, const Shape*>>& pair_of, const std::vector<std::size_t>& start,
                 const std::vector<std::size_t>& idx, const std::vector<std::uint8_t>& takes) {
  if (!(so.alpha_max < std::numeric_limits<double>::infinity())) return false;
  const std::size_t n = state.size();
  std::vector<double> lanes_lower(n), at(n);
  std::vector<std::int8_t> verdict(n, -1), at_verdict(n);  // by row, and in idx's order
  for (std::size_t g = 0; g < pair_of.size(); ++g) {
    if (!takes[g]) continue;
    const std::size_t g0 = start[g], m = start[g + 1] - g0;
    detail::separated_rows_lanes(*pair_of[g].first, *pair_of[g].second, so, poses.rows(), idx.data() + g0, m,
                                 at.data() + g0, at_verdict.data() + g0);
    for (std::size_t i = g0; i < g0 + m; ++i) lanes_lower[idx[i]] = at[i], verdict[idx[i]] = at_verdict[i];
  }
  std::size_t first = detail::kNoRow;  // the first row written in full
  for (std::size_t k = 0; k < n; ++k) {
    if (k != 0 && k % kPollRows == 0) {  // as run_rows polls and stops
      if (o.poll != nullptr) o.poll(o.poll_data);
      if (o.cancel != nullptr && o.cancel->load(std::memory_order_relaxed)) break;
    }
    if (state[k] != kScreen) continue;
    const auto [a, b] = pair(k);
    double lower = 0.0;
    if (!detail::separated_at_once(verdict[k], lanes_lower[k], *a, *b, [&] { return poses(k); }, so, lower)) continue;
    state[k] = kAnswered;
    write_separated(k, lower, first, o, so, out);
    if (first == detail::kNoRow) first = k;
  }
  return first != detail::kNoRow;
}

/// A hash of a row's pair of shape objects (their addresses).
inline std::size_t pair_hash(const std::pair<const Shape*, const Shape*>& key) {
  const std::uint64_t h = (reinterpret_cast<std::uintptr_t>(key.first) * 0x9E3779B97F4A7C15ull) ^
                          (reinterpret_cast<std::uintptr_t>(key.second) * 0xC2B2AE3D27D4EB4Full);
  return static_cast<std::size_t>(h >> 32);
}

/// Whether some pair has at least `need` of the n rows, counted on the
/// stack where n is small (else true: the grouping decides). A scene of a
/// few dozen rows of as many pairs (the ten-body scene's 45) then skips the
/// grouping's allocations, which cost it a tenth of its step (bench_sim_batch).
template <class Pair>
bool some_pair_fills(std::size_t n, const Pair& pair, std::size_t need) {
  constexpr std::size_t kSlots = 256;
  if (n > kSlots / 2) return true;
  std::pair<const Shape*, const Shape*> key[kSlots];
  std::size_t count[kSlots] = {};
  for (std::size_t k = 0; k < n; ++k) {
    const auto p = pair(k);
    std::size_t i = pair_hash(p) & (kSlots - 1);
    while (count[i] != 0 && key[i] != p) i = (i + 1) & (kSlots - 1);
    key[i] = p;
    if (++count[i] >= need) return true;
  }
  return false;
}

/// The rows [0, n) grouped by pair(k) (two shapes' addresses), the groups
/// in the order of their first row and the rows in their order within
/// each: group g's rows are idx[start[g], start[g + 1]), its pair
/// pair_of[g]. A small open-addressing table of the addresses gives each
/// row its group, and a counting sort lays the groups out (a sort of the
/// rows by address took 3% of a 1,000-body step's batch).
template <class Pair>
void group_by_pair(std::size_t n, const Pair& pair, std::vector<std::pair<const Shape*, const Shape*>>& pair_of,
                   std::vector<std::size_t>& start, std::vector<std::size_t>& idx) {
  std::vector<std::uint32_t> group(n);
  std::vector<std::uint32_t> slots(64, 0);  // 1 + group, 0 empty
  auto slot_of = [&](const std::pair<const Shape*, const Shape*>& key) {
    const std::size_t mask = slots.size() - 1;
    for (std::size_t i = pair_hash(key) & mask;; i = (i + 1) & mask)
      if (slots[i] == 0 || pair_of[slots[i] - 1] == key) return i;
  };
  for (std::size_t k = 0; k < n; ++k) {
    const auto key = pair(k);
    const std::size_t i = slot_of(key);
    if (slots[i] != 0) {
      group[k] = slots[i] - 1;
      continue;
    }
    pair_of.push_back(key);
    group[k] = static_cast<std::uint32_t>(pair_of.size() - 1);
    slots[i] = static_cast<std::uint32_t>(pair_of.size());
    if (2 * pair_of.size() > slots.size()) {  // keep the table at most half full
      slots.assign(2 * slots.size(), 0);
      for (std::size_t g = 0; g < pair_of.size(); ++g) slots[slot_of(pair_of[g])] = static_cast<std::uint32_t>(g + 1);
    }
  }
  const std::size_t G = pair_of.size();
  start.assign(G + 1, 0);
  for (std::size_t k = 0; k < n; ++k) ++start[group[k] + 1];
  for (std::size_t g = 0; g < G; ++g) start[g + 1] += start[g];
  idx.resize(n);
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  for (std::size_t k = 0; k < n; ++k) idx[next[group[k]]++] = k;
}

/// Whether the SIMD path takes the rows of the pair (a, b) under these
/// options and outputs: a pair it covers, and per-row warm rows with
/// derivatives only where the lanes form the derivatives (a warm row takes
/// a Newton step or two, which the lanes save less of than rebuilding its
/// result on one core for the derivatives costs: an evaluation of both
/// bodies, the Jacobian and its LU; bench_sim_batch: 1.05-1.2x the loop's
/// time).
bool lanes_take(const Shape& a, const Shape& b, const BatchOptions& o, const SolverOptions& so, const BatchOutput& out) {
  return detail::batch_simd_covers(a, b, so) &&
         (!(o.derivatives && !out.warm.empty()) || detail::batch_simd_finishes(a, b, so));
}

/// Rows of many pairs (one shape object per row), cold or each warm from
/// its own state: the rows of each pair (the same two shape objects) that
/// the SIMD path covers, when they fill its lanes (under a finite alpha_max,
/// the rows not Separated at once), run as one batch of that pair in lanes;
/// every other row in one batch on the loop. A row's answer
/// does not depend on the rows beside it in these modes, so every row is
/// still the loop's, bit for bit. False (nothing done) where the lanes
/// cannot help: chained warm starts, or a CPU without lanes.
template <class Poses>
bool run_grouped(std::size_t n, Span<const Shape* const> b1, Span<const Shape* const> b2, const Poses& poses,
                 const BatchOptions& o, const SolverOptions& so, const BatchOutput& out) {
  const std::size_t lanes = static_cast<std::size_t>(detail::batch_simd_lanes());
  if (o.warm_start || lanes < 2 || n < lanes) return false;
  auto pair = [&](std::size_t k) {
    return std::make_pair(b1[b1.size() == 1 ? 0 : k], b2[b2.size() == 1 ? 0 : k]);
  };
  constexpr std::size_t kGroupLanes = 2;  // a group's fewest rows, in calls of the lanes (below)
  if (!some_pair_fills(n, pair, kGroupLanes * lanes)) return false;
  std::vector<std::pair<const Shape*, const Shape*>> pair_of;  // group -> its pair
  std::vector<std::size_t> start, idx;
  group_by_pair(n, pair, pair_of, start, idx);
  const std::size_t G = pair_of.size();
  // The groups of rows of one pair, [g0, g1) of idx, that lanes take: at
  // least kGroupLanes lanes' worth, and together at least half the rows.
  // Each group is a batch of its own (its constants formed, its rows and
  // outputs copied in and out), and the rows outside the groups a batch on
  // the loop: on fewer rows that costs more than the lanes save (the
  // 100-body scene of bench_multibody_scaling, about five rows a pair of
  // kinds: a step up to 20% slower than the loop when every group of W
  // rows took lanes).
  // Under a finite alpha_max, the rows of such a group that solve()
  // answers Separated at once are answered here (screen_rows) and only the
  // others count: a sparse scene's far pairs (most of its candidate pairs
  // under alpha_max = 1) otherwise filled groups whose lanes then ran
  // nearly empty, at a cost over the loop's (bench_sim_batch's ten64
  // scene, warm with wrenches: 0.84x the loop). Once rows are answered, the
  // others run here too, the rest on the loop. The rows of the other
  // groups go to the loop unscreened, which screens them as it solves.
  std::vector<std::uint8_t> state(n, kLoop);
  std::vector<std::uint8_t> takes(G, 0);
  for (std::size_t g = 0; g < G; ++g) {
    const auto& key = pair_of[g];
    takes[g] = start[g + 1] - start[g] >= kGroupLanes * lanes && lanes_take(*key.first, *key.second, o, so, out);
    if (takes[g])
      for (std::size_t i = start[g]; i < start[g + 1]; ++i) state[idx[i]] = kScreen;
  }
  const bool answered = screen_rows(state, pair, poses, o, so, out, pair_of, start, idx, takes);
  std::vector<std::pair<std::size_t, std::size_t>> groups;  // ranges of idx
  std::vector<std::size_t> rest;
  for (std::size_t g = 0; g < G; ++g) {
    const std::size_t g0 = start[g], g1 = start[g + 1];
    std::size_t live = g0;  // the group's rows not answered, in their order, to idx[g0, live)
    for (std::size_t i = g0; i < g1; ++i)
      if (state[idx[i]] != kAnswered) idx[live++] = idx[i];
    if (takes[g] && live - g0 >= kGroupLanes * lanes)
      groups.emplace_back(g0, live);
    else rest.insert(rest.end(), idx.begin() + static_cast<std::ptrdiff_t>(g0), idx.begin() + static_cast<std::ptrdiff_t>(live));
  }
  if (2 * rest.size() > n && !answered) return false;
  std::vector<std::size_t> rows;
  for (const auto& [g0, g1] : groups) {
    if (o.cancel != nullptr && o.cancel->load(std::memory_order_relaxed)) return true;
    const auto key = pair(idx[g0]);
    rows.assign(idx.begin() + static_cast<std::ptrdiff_t>(g0), idx.begin() + static_cast<std::ptrdiff_t>(g1));
    run_sub_batch(rows, Span<const Shape* const>(&key.first, 1), Span<const Shape* const>(&key.second, 1), poses, o,
                  out, true);
  }
  if (!rest.empty()) {
    std::sort(rest.begin(), rest.end());  // the loop's rows in their own order
    if (resolve_thread_count(o.threads) == 1) {
      // On one thread, each row on the loop where it lies, without a
      // sub-batch's copies in and out (box100 of bench_sim_batch, warm
      // with wrenches, its rest through a sub-batch: 0.87-0.89x the loop).
      for (std::size_t i = 0; i < rest.size(); ++i) {
        if (o.poll != nullptr && i != 0 && i % kPollRows == 0) o.poll(o.poll_data);
        run_rows(rest[i], rest[i] + 1, b1, b2, poses, o, so, out, false);
      }
      return true;
    }
    std::vector<const Shape*> rest1(rest.size()), rest2(rest.size());
    for (std::size_t i = 0; i < rest.size(); ++i) std::tie(rest1[i], rest2[i]) = pair(rest[i]);
    BatchOptions loop_o = o;
    loop_o.simd = false;
    run_sub_batch(rest, Span<const Shape* const>(rest1), Span<const Shape* const>(rest2), poses, loop_o, out);
  }
  return true;
}

// Long: every input and output array checked first (each error names its
// field), then the rows split between the lanes and the loop and the work
// between the threads, over one set of row indices.
template <class Poses>
void run(std::size_t n, Span<const Shape* const> b1, Span<const Shape* const> b2, const Poses& poses,
         const BatchOptions& o, const BatchOutput& out, bool screened) {
  o.validate();
  check_bodies("body1", b1, n);
  check_bodies("body2", b2, n);
  check_output("alpha", out.alpha.size(), n);
  check_output("x_1", out.x_1.size(), 3 * n);
  check_output("status", out.status.size(), n);
  check_output("iterations", out.iterations.size(), n);
  check_output("dalpha_dxi", out.dalpha_dxi.size(), o.derivatives ? 6 * n : 0);
  auto check_optional = [&](const char* field, std::size_t got, std::size_t per_row) {
    if (got != 0) check_output(field, got, per_row * n);
  };
  for (std::size_t f = kFirstOptional; f < std::size(kDoubleFields); ++f)
    check_optional(kDoubleFields[f].name, (out.*kDoubleFields[f].field).size(), kDoubleFields[f].per_row);
  if (wants_kinematics_derivatives(out) && !o.derivatives)
    bad("kinematics derivatives (dgap_dxi, dnormal_dxi, dp1_dxi, dp2_dxi) need BatchOptions::derivatives");
  if (wants_wrench_derivatives(out) && !o.derivatives)
    bad("wrench derivatives (df_n_dxi, dF1_dxi, dF2_dxi) need BatchOptions::derivatives");
  if (wants_wrench(out) || wants_wrench_derivatives(out)) {
    try {
      o.contact.validate();
    } catch (const std::invalid_argument& e) {
      bad(std::string("BatchOptions::contact: ") + e.what());
    }
  }
  check_optional("warm", out.warm.size(), 1);
  if (!out.warm.empty() && o.warm_start)
    bad("BatchOutput::warm (one warm state per row) and BatchOptions::warm_start (chains of rows) are two modes; "
        "set warm_start = false to use the per-row states");
  if (n == 0) return;

  SolverOptions so = o.solver;
  so.derivatives = so.derivatives || o.derivatives;
  // Rows of many pairs: each pair's rows in lanes where they fill them.
  if (o.simd && (b1.size() != 1 || b2.size() != 1) && run_grouped(n, b1, b2, poses, o, so, out))
    return;
  // Units of work. Cold: blocks of kColdBlock rows, each handed to whichever
  // thread is free next (an atomic counter), so every thread stays busy to
  // the end however the rows' costs cluster (the paper sweep's costly poses
  // do) and however fast each CPU runs; a row's answer does not depend on
  // the thread that solves it. Warm: chains (a chunk boundary must be a
  // chain boundary), in contiguous runs, one a thread.
  const std::size_t unit = o.warm_start ? o.warm_chain : kColdBlock;
  const std::size_t units = (n + unit - 1) / unit;
  const std::size_t threads =
      std::min<std::size_t>(static_cast<std::size_t>(resolve_thread_count(o.threads)), units);
  // The SIMD path (batch_simd.hpp) takes the rows of one covered pair, cold,
  // warm in chains or warm per row; the rows it declines come back to
  // run_rows (lanes_take says which pairs and modes it takes). Its lanes
  // write alpha, x_1, status, iterations and the contact kinematics; the
  // derivatives and the wrench of a row the lanes answer come from
  // finish_rows.
  const bool simd = o.simd && b1.size() == 1 && b2.size() == 1 && lanes_take(*b1[0], *b2[0], o, so, out);
  const bool finishes = o.derivatives || wants_wrench(out) || wants_wrench_derivatives(out);
  // The SIMD path checks BatchOptions::cancel between blocks (cold: the
  // blocks of kColdBlock rows; warm: at least 1024 rows of whole chains),
  // as run_rows does before each row.
  // Warm, a block holds a whole number of lane groups of chains, and the
  // last block of a thread also the chains left after it when they are
  // fewer than the lanes: each kernel call takes a row of W chains, and
  // more than W chains in a block rotate through the lanes, so that the
  // calls stay full (a block of fewer chains than lanes would leave lanes
  // idle; a block of one chain runs the scalar loop).
  const std::size_t lanes = simd ? static_cast<std::size_t>(detail::batch_simd_lanes()) : 1;
  const std::size_t block_units = std::max<std::size_t>(1, (1024 + unit - 1) / unit);
  const std::size_t simd_block = unit * ((block_units + lanes - 1) / lanes * lanes);
  // The rows the lanes hand back (a few in each block) do not poll: the
  // block does, before it starts.
  auto scalar_rows = [&](std::size_t lo, std::size_t hi, WarmStart* ws, const detail::ColdResume* resume) {
    run_rows(lo, hi, b1, b2, poses, o, so, out, false, ws, resume);
  };
  using ScalarRows = decltype(scalar_rows);
  // The derivatives: the Newton lanes form them, with the wrench
  // (LaneRow::derivatives); the closed-form lanes' rows rebuild solve()'s
  // whole result at the lane's z on one core (solve_finished) and form them
  // from it. Without derivatives, the kinematics and the wrench read only
  // alpha*, x_1, body 1's gradient and the pose (contact_kinematics,
  // contact_wrench), which the lane holds.
  auto finish_rows = [&](std::size_t k, const detail::LaneRow& r) {
    if (r.derivatives != nullptr) return write_derived(k, r.derivatives, r.stride, o, out);
    if (o.derivatives) {
      Vec6 z;
      for (int j = 0; j < 6; ++j) z[j] = r.z[j * r.stride];
      return write_optional(k, detail::solve_finished(*b1[0], *b2[0], poses(k), so, z, r.iterations), o, so, out);
    }
    SolveResult res;
    res.status = SolveStatus::Converged;
    res.alpha = r.alpha[0];
    const Pose X = poses(k);
    for (int j = 0; j < 3; ++j) {
      res.x_1[j] = r.x[j * r.stride];
      res.internal.e1.grad[j] = r.g1[j * r.stride];
    }
    res.internal.R = X.R;
    res.internal.r = X.p;
    write_optional(k, res, o, so, out);
  };
  using FinishRows = decltype(finish_rows);
  // A row known without a solve (write_separated). The callbacks share one
  // context: finish_rows, which this one reaches through.
  auto result_row = [&](std::size_t k, double lower, std::size_t like) { write_separated(k, lower, like, o, so, out); };
  struct Sinks {
    const FinishRows* finish;
    const decltype(result_row)* result;
  } sinks{&finish_rows, &result_row};
  auto simd_rows = [&](std::size_t lo, std::size_t hi) {
    detail::solve_rows_simd(
        *b1[0], *b2[0], so, o.derivatives ? &o.contact : nullptr, poses.rows(), lo, hi, o.warm_start ? o.warm_chain : 0, screened, out,
        [](const void* f, std::size_t a, std::size_t b, WarmStart* ws, const detail::ColdResume* r) {
          (*static_cast<const ScalarRows*>(f))(a, b, ws, r);
        },
        &scalar_rows,
        finishes ? [](const void* f, std::size_t k, const detail::LaneRow& r) { (*static_cast<const Sinks*>(f)->finish)(k, r); }
                 : detail::FinishRowFn{nullptr},
        [](const void* f, std::size_t k, double lower, std::size_t like) { (*static_cast<const Sinks*>(f)->result)(k, lower, like); },
        &sinks);
  };
  std::atomic<std::size_t> next_block{0};
  auto chunk = [&](std::size_t t, bool caller) {
    if (!o.warm_start) {  // the next free block until none is left
      for (bool first = true;; first = false) {
        const std::size_t lo = next_block.fetch_add(kColdBlock, std::memory_order_relaxed);
        if (lo >= n) return;
        const std::size_t hi = std::min(n, lo + kColdBlock);
        if (caller && o.poll != nullptr && !first) o.poll(o.poll_data);
        if (o.cancel != nullptr && o.cancel->load(std::memory_order_relaxed)) return;
        if (simd) simd_rows(lo, hi);
        else run_rows(lo, hi, b1, b2, poses, o, so, out, caller);
      }
    }
    const std::size_t lo = std::min(n, units * t / threads * unit);
    const std::size_t hi = std::min(n, units * (t + 1) / threads * unit);
    if (simd) {
      for (std::size_t blo = lo, bhi; blo < hi; blo = bhi) {
        bhi = std::min(hi, blo + simd_block);
        if (hi - bhi < lanes * unit) bhi = hi;
        if (caller && o.poll != nullptr && blo != lo) o.poll(o.poll_data);
        if (o.cancel != nullptr && o.cancel->load(std::memory_order_relaxed)) return;
        simd_rows(blo, bhi);
      }
    } else
      run_rows(lo, hi, b1, b2, poses, o, so, out, caller);
  };
  if (threads <= 1) return chunk(0, true);
  // Nothing below throws except std::thread's constructor; solve(), and
  // alpha_gradient(), contact_kinematics(), solution_sensitivity() and
  // contact_kinematics_derivatives() on a converged result with its
  // factorisation (kept: derivatives are on whenever they are asked for), do
  // not.
  std::mutex mu;
  std::condition_variable cv;
  std::size_t finished = 0;  // workers done, under mu
  auto worker = [&](std::size_t t) {
    chunk(t, false);
    {
      std::lock_guard<std::mutex> lock(mu);
      ++finished;
    }
    cv.notify_one();
  };
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  try {
    for (std::size_t t = 1; t < threads; ++t) workers.emplace_back(worker, t);
  } catch (const std::system_error&) {
    // No more threads to be had: the chunks not handed out run below.
  }
  chunk(0, true);
  // A thread that could not be started leaves its chunks to this one.
  for (std::size_t t = workers.size() + 1; t < threads; ++t) chunk(t, true);
  if (o.poll != nullptr) {
    std::unique_lock<std::mutex> lock(mu);
    while (!cv.wait_for(lock, std::chrono::milliseconds(20), [&] { return finished == workers.size(); })) {
      lock.unlock();
      o.poll(o.poll_data);
      lock.lock();
    }
  }
  for (std::thread& w : workers) w.join();
}

}  // namespace

void BatchOptions::validate() const {
  solver.validate();
  if (warm_chain < 1) bad("BatchOptions: field 'warm_chain' must be >= 1, got " + sz(warm_chain));
  if (threads < 0) bad("BatchOptions: field 'threads' must be >= 0 (0 = all CPUs), got " + std::to_string(threads));
}

int resolve_thread_count(int threads) {
  if (threads > 0) return threads;
#if defined(__linux__)
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return n;
  }
#endif
  const unsigned hc = std::thread::hardware_concurrency();
  return hc > 0 ? static_cast<int>(hc) : 1;
}

const char* batch_simd_isa() { return detail::batch_simd_isa(); }

void solve_batch(Span<const Shape* const> body1, Span<const Shape* const> body2, Span<const double> R,
                 Span<const double> p, const BatchOptions& options, const BatchOutput& out) {
  if (p.size() % 3 != 0) bad("p must hold 3 values per row, got " + sz(p.size()));
  const std::size_t n = p.size() / 3;
  if (R.size() != 9 * n) bad("R must hold 9 values per row (" + sz(9 * n) + " for " + sz(n) + " rows), got " + sz(R.size()));
  run(n, body1, body2, RowMajorPoses{R.data(), p.data()}, options, out);
}

void solve_batch(Span<const Shape* const> body1, Span<const Shape* const> body2, Span<const Pose> poses,
                 const BatchOptions& options, const BatchOutput& out) {
  run(poses.size(), body1, body2, PoseList{poses.data()}, options, out);
}

}  // namespace idcol

// The smoothing study (smoothing.hpp describes its grid file). For each grid
// value the study builds the shape (a value the constructor rejects is recorded as an invalid grid point with
// the constructor's message) and measures, over the same N poses of the
// harness's "paper" trajectory (pose k at t = k dt; body 1 = the partner
// sphere at the identity, body 2 = the family's shape at X_12):
//   * geometry: sup over sampled directions of |rho_smooth - rho_exact|
//     (an estimate of an upper bound on the Hausdorff distance) and the
//     largest depth of a sampled smooth surface point inside the exact body
//     (a lower bound on it), both divided by the exact body's outer radius;
//   * alpha*: iDCOL's cold solve against the exact oracle of the exact body
//     and the same sphere (relative error: mean, p99, max);
//   * conditioning: singular values of the solver's KKT Jacobian at the
//     solution (inverse rebuilt from the stored LU, JacobiSVD), and the LU
//     pivot ratio;
//   * smoothness along the trajectory: jumps of alpha* and of the normal
//     between consecutive poses per unit step, and the first-order (IFT)
//     prediction error of the next pose relative to the change;
//   * cost (single thread, pinned): cold and warm (chained along the
//     trajectory) time per solve, iterations, convergence.
// The exact body is the family's sharp limit in the baselines' independent
// geometry (geom::sharp_limit of the shape's public parameters, through
// core_adapter): its radial function, depth, distance, radii and corner
// directions are closed forms there, so no figure here depends on core's own
// vertices, radii or evaluation other than the smooth body being measured.
#include "studies/smoothing/smoothing.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <map>
#include <string>
#include <vector>

#include "stats/stats.hpp"
#include "studies/entry_shards.hpp"
#include "studies/smoothing/smoothing_keys.hpp"
#include "studies/smoothing/smoothing_spec.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "idcol_baselines/baselines.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/geometry.hpp"
#include "idcol_baselines/oracles.hpp"
#include "gen/poses.hpp"
#include "exec/chains.hpp"
#include "scene/scene.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

json summary(const std::vector<double>& v) {
  if (v.empty()) return {{"count", 0}};
  double s = 0.0, mx = -INFINITY, mn = INFINITY;
  for (double x : v) {
    s += x;
    mx = std::max(mx, x);
    mn = std::min(mn, x);
  }
  return {{"count", v.size()},       {key::mean, s / v.size()},          {"min", mn},
          {"p01", percentile(v, 0.01)}, {"p50", percentile(v, 0.5)}, {key::p99, percentile(v, 0.99)},
          {key::max, mx}};
}

/// xi with X_b = X_a exp(xi^), xi = (w, v) (derivatives.hpp convention).
Vec6 se3_log_between(const Pose& Xa, const Pose& Xb) {
  const Mat3 Rr = Xa.R.transpose() * Xb.R;
  const Vec3 pr = Xa.R.transpose() * (Xb.p - Xa.p);
  const Eigen::AngleAxisd aa(Rr);
  const double th = aa.angle();
  const Vec3 w = th * aa.axis();
  const Mat3 W = skew(w);
  Mat3 V = Mat3::Identity();
  if (th > 1e-8) {
    V += (1.0 - std::cos(th)) / (th * th) * W + (th - std::sin(th)) / (th * th * th) * W * W;
  } else {
    V += 0.5 * W + W * W / 6.0;
  }
  Vec6 xi;
  xi << w, V.lu().solve(pr);
  return xi;
}

/// The smooth body's radial function by bisection on phi(t u) = 0 over
/// t in [0, t_hi] (phi(t u) is convex in t and negative at 0, so the root is
/// unique); t_hi must have phi(t_hi u) >= 0. 80 halvings: exact to rounding.
double smooth_radial(const Shape& s, const Vec3& u, double t_hi) {
  double lo = 0.0, hi = t_hi;
  ShapeEval e;
  for (int i = 0; i < 80 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    eval(s, mid * u, e);
    (e.phi <= 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// Exact-body alpha* for the partner sphere (radius Rs, body 1 at the
/// identity) and the exact body K at X_12: the bodies scaled by alpha touch
/// iff dist(c / alpha, K) = Rs with c = -R^T r (the sphere's centre in K's
/// frame); dist(t c, K) is convex in t and 0 at t = 0, so nondecreasing, and
/// alpha* is found by bisection to relative 1e-14.
double exact_alpha(const baselines::geom::Convex& K, double Rs, const Pose& X) {
  const Vec3 c = -(X.R.transpose() * X.p);
  const double r = c.norm();
  const auto radii = baselines::geom::radii(K);
  double lo = r / (Rs + radii[1]), hi = r / (Rs + radii[0]);
  auto touching_or_overlap = [&](double a) { return baselines::geom::distance(K, c / a) <= Rs; };
  while (touching_or_overlap(lo)) lo *= 0.5;
  while (!touching_or_overlap(hi)) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-14 * hi; ++i) {
    const double m = 0.5 * (lo + hi);
    (touching_or_overlap(m) ? hi : lo) = m;
  }
  return 0.5 * (lo + hi);
}

struct PoseData {
  SolveStatus status = SolveStatus::InvalidInput;
  int iterations = 0;
  double alpha = NAN, alpha_exact = NAN;
  bool oracle_ok = false;
  double rcond = NAN, pivot = NAN;
  Vec3 n = Vec3::Zero();
  Row6 dalpha = Row6::Zero();
  Mat36 dn = Mat36::Zero();
  bool deriv_ok = false;
};

/// One valid grid point: its shape S against the partner sphere (radius Rs)
/// over the trajectory gen, K the exact body S approximates.
struct GridPoint {
  const Shape& partner;
  double Rs;
  const Shape& S;
  const baselines::geom::Convex& K;  // its sharp limit, from the baselines' independent geometry
  std::string body2;  // the failure records' name of S
  const PoseGenerator& gen;
  std::uint64_t N;
  FailureSite site(std::uint64_t k, const char* pass) const { return {"partner", body2, &partner, &S, pass, k, "paper"}; }
};

/// Geometry: the smooth body's radial function against the exact body's,
/// along the direction sample and K's special directions.
json geometry_figures(const GridPoint& g, const std::vector<Vec3>& fib) {
  namespace geom = baselines::geom;
  const geom::Convex& K = g.K;
  const double outer = geom::radii(K)[1];
  std::vector<Vec3> dirs = fib;
  for (const Vec3& d : geom::feature_directions(K)) dirs.push_back(d);
  double up = 0.0, lowb = 0.0;
  Vec3 argmax = Vec3::Zero();
  int outside = 0;
  double outside_max = 0.0;
  ShapeEval e;
  for (const Vec3& u : dirs) {
    const double re = geom::radial(K, u);
    eval(g.S, re * u, e);
    if (e.phi < 0.0) {  // the smooth body reaches beyond the exact one along u, by about -phi/|grad phi|
      ++outside;
      const double gn = e.grad.norm();
      if (gn > 0.0) outside_max = std::max(outside_max, -e.phi / gn);
    }
    const double rs = smooth_radial(g.S, u, re * (e.phi < 0.0 ? 2.0 : 1.0));
    const double gap = std::abs(re - rs);
    if (gap > up) {
      up = gap;
      argmax = u;
    }
    lowb = std::max(lowb, geom::depth(K, rs * u));
  }
  return {{"directions", dirs.size()},
          {"special_directions", dirs.size() - fib.size()},
          {"exact_outer_radius", outer},
          {key::radial_gap_max_rel, up / outer},
          {key::hausdorff_lower_rel, lowb / outer},
          {"argmax_direction", {argmax[0], argmax[1], argmax[2]}},
          {key::smooth_outside_exact_count, outside},
          // LogSumExp and superquadric bodies lie inside their exact bodies, so
          // these are rounding where the two surfaces coincide (flat faces):
          // the largest such distance, relative to the outer radius.
          {"smooth_outside_exact_max_rel", outside_max / outer}};
}

/// The accuracy pass on `threads` threads: at every pose a cold solve, the
/// exact body's alpha*, the KKT conditioning and the derivatives. Failed
/// solves are appended to `failures`, in pose order per thread.
std::vector<PoseData> accuracy_pass(const GridPoint& g, const SolverOptions& opt, int threads, json& failures) {
  std::unique_ptr<baselines::BaselinePair> bp;
  if (!baselines::geom::has_distance(g.K)) bp = std::make_unique<baselines::BaselinePair>(g.partner, g.S);
  std::vector<PoseData> D(g.N);
  std::vector<json> fails(threads);
  auto work = [&](int t) {
    for (std::uint64_t k = t; k < g.N; k += threads) {
      if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
      const Pose X = g.gen(k);
      PoseData& d = D[k];
      const SolveResult r = solve(g.partner, g.S, X, opt);
      d.status = r.status;
      d.iterations = r.iterations;
      if (!r.converged()) fails[t].push_back(failure_record(g.site(k, "cold"), X, &r));
      if (baselines::geom::has_distance(g.K)) {
        d.alpha_exact = exact_alpha(g.K, g.Rs, X);
        d.oracle_ok = true;
      } else {
        const baselines::OracleAnswer o = bp->oracle(X);
        d.oracle_ok = o.ok;
        d.alpha_exact = o.alpha;
      }
      if (!r.converged()) continue;
      d.alpha = r.alpha;
      d.pivot = r.internal.lu.pivot_ratio();
      const Mat6 Jinv = r.internal.lu.solve_many<6>(Mat6::Identity());
      const Eigen::JacobiSVD<Mat6> svd(Jinv);
      const auto sv = svd.singularValues();  // of J^{-1}: sigma_min/max(J) = sv_min/sv_max(J^-1)
      d.rcond = sv[5] / sv[0];
      const SolutionSensitivity sens = solution_sensitivity(r);
      const ContactKinematics ck = contact_kinematics(r);
      const ContactKinematicsDerivatives ckd = contact_kinematics_derivatives(r, sens);
      d.n = ck.nhat_1;
      d.dalpha = sens.dalpha_dxi();
      d.dn = ckd.dnhat_1_dxi;
      d.deriv_ok = sens.valid && ckd.valid;
    }
  };
  {
    std::vector<std::future<void>> jobs;
    for (int t = 0; t < threads; ++t) jobs.push_back(std::async(std::launch::async, work, t));
    for (auto& j : jobs) j.get();
  }
  for (auto& f : fails)
    for (auto& x : f) failures.push_back(std::move(x));
  return D;
}

/// The accuracy pass's figures: statuses, alpha* error against the exact
/// body (P["cold_accuracy_pass"]) and conditioning (P["conditioning"]).
void accuracy_figures(const GridPoint& g, const std::vector<PoseData>& D, json& P) {
  std::map<std::string, std::uint64_t> status_counts;
  std::vector<double> aerr, iters, rcond, pivot;
  std::uint64_t oracle_fail = 0;
  for (const PoseData& d : D) {
    status_counts[to_string(d.status)]++;
    iters.push_back(d.iterations);
    if (!d.oracle_ok) ++oracle_fail;
    if (d.status != SolveStatus::Converged) continue;
    if (d.oracle_ok) aerr.push_back(std::abs(d.alpha - d.alpha_exact) / d.alpha_exact);
    rcond.push_back(d.rcond);
    pivot.push_back(d.pivot);
  }
  const auto conv_it = status_counts.find(to_string(SolveStatus::Converged));
  const std::uint64_t n_conv = conv_it == status_counts.end() ? 0 : conv_it->second;
  P["cold_accuracy_pass"] = {{"poses", g.N},
                             {"statuses", status_counts},
                             {key::converged_fraction, double(n_conv) / g.N},
                             {key::iterations, summary(iters)},
                             {"oracle", baselines::geom::has_distance(g.K)
                                            ? std::string("bisection over closed-form distance to the exact body")
                                            : std::string("baselines::BaselinePair::oracle: ") +
                                                  baselines::to_string(baselines::oracle_for(g.partner, g.S)) +
                                                  " on the exact body (no FCL or libccd)"},
                             {key::oracle_failures, oracle_fail},
                             {key::alpha_rel_error, summary(aerr)}};
  P["conditioning"] = {{"rcond_svd", summary(rcond)}, {"pivot_ratio", summary(pivot)}};
}

/// Cross-check of the closed-form oracle against the baselines' oracle for
/// the box as an exact polytope (the support-function bracket,
/// support_oracle.hpp, for a sphere partner: no code shared with either).
json oracle_cross_check(const GridPoint& g, const Superellipsoid& se, int poses) {
  const double h[3] = {se.a(), se.b(), se.c()};
  std::vector<Vec3> A;
  std::vector<double> b;
  for (int i = 0; i < 3; ++i)
    for (int s = -1; s <= 1; s += 2) {
      Vec3 a = Vec3::Zero();
      a[i] = s;
      A.push_back(a);
      b.push_back(h[i]);
    }
  const Shape box = SmoothPolytope(A, b, 1000.0);  // only its exact polytope is used
  const baselines::BaselinePair chk(g.partner, box);
  double worst = 0.0;
  for (int k = 0; k < poses; ++k) {
    const Pose X = g.gen(k * (g.N / poses));
    const auto o = chk.oracle(X);
    if (o.ok) worst = std::max(worst, std::abs(o.alpha - exact_alpha(g.K, g.Rs, X)) / o.alpha);
  }
  return {{"poses", poses},
          {"against", std::string("BaselinePair::oracle (") + baselines::to_string(baselines::oracle_for(g.partner, box)) +
                          ") on the box as an exact polytope"},
          {"max_rel_diff", worst}};
}

/// Smoothness along the trajectory, from the accuracy pass: jumps of alpha*
/// and of the normal per unit step (Lpair scales the translation), and the
/// IFT prediction's error relative to the change.
json smoothness_figures(const GridPoint& g, const std::vector<PoseData>& D, double Lpair) {
  std::vector<double> ajump, njump, apred, npred;
  for (std::uint64_t k = 0; k + 1 < g.N; ++k) {
    const PoseData &a = D[k], &b = D[k + 1];
    if (a.status != SolveStatus::Converged || b.status != SolveStatus::Converged) continue;
    const Vec6 xi = se3_log_between(g.gen(k), g.gen(k + 1));
    Vec6 xs = xi;
    xs.tail<3>() /= Lpair;
    const double step = xs.norm();  // dimensionless: rad, and length / L
    const double da = b.alpha - a.alpha;
    const Vec3 dn = b.n - a.n;
    ajump.push_back(std::abs(da) / (a.alpha * step));
    njump.push_back(dn.norm() / step);
    if (!a.deriv_ok) continue;
    const double ea = std::abs(da - a.dalpha.dot(xi));
    const double en = (dn - a.dn * xi).norm();
    if (std::abs(da) > 1e-12 * a.alpha) apred.push_back(ea / std::abs(da));
    if (dn.norm() > 1e-12) npred.push_back(en / dn.norm());
  }
  return {{"step_definition", "|(w, v / L)|, xi = log(X_k^-1 X_k+1), L = partner radius + outer radius"},
          {key::alpha_jump_rel_per_step, summary(ajump)},
          {key::normal_jump_per_step, summary(njump)},
          {"ift_alpha_prediction_error_rel_change", summary(apred)},
          {"ift_normal_prediction_error_rel_change", summary(npred)}};
}

/// The timing passes, cold then warm (chained along the trajectory), on this
/// thread (pinned to `pin` unless -1), each after `warmup` solves. Failed warm
/// solves are appended to `failures`.
json timing_passes(const GridPoint& g, const SolverOptions& opt, std::uint64_t warmup, int pin, json& failures) {
  if (pin >= 0) pin_to_cpu(pin);
  const double overhead = measure_timer_overhead_ns();
  json T;
  for (const char* pass : {"cold", "warm"}) {
    const bool warm = std::string(pass) == "warm";
    WarmStart ws;
    for (std::uint64_t k = 0; k < std::min<std::uint64_t>(warmup, g.N); ++k)
      (void)solve(g.partner, g.S, g.gen(k), opt, warm ? &ws : nullptr);
    ws.reset();
    std::vector<double> ns(g.N), it(g.N);
    std::uint64_t conv = 0, fell_back = 0;
    const double cpu0 = thread_cpu_seconds();
    const auto w0 = Clock::now();
    for (std::uint64_t k = 0; k < g.N; ++k) {
      const Pose X = g.gen(k);
      const WarmStart before = ws;
      const auto t0 = Clock::now();
      const SolveResult r = solve(g.partner, g.S, X, opt, warm ? &ws : nullptr);
      const auto t1 = Clock::now();
      ns[k] = std::chrono::duration<double, std::nano>(t1 - t0).count() - overhead;
      it[k] = r.iterations;
      if (r.converged()) ++conv;
      else if (warm) failures.push_back(failure_record(g.site(k, "warm"), X, &r, &before));
      if (r.warm_start_fell_back) ++fell_back;
    }
    const double wall = std::chrono::duration<double>(Clock::now() - w0).count();
    const double cpu = thread_cpu_seconds() - cpu0;
    T[pass] = {{"poses", g.N},
               {"converged", conv},
               {key::converged_fraction, double(conv) / g.N},
               {"warm_fell_back", fell_back},
               {"time_ns", summary(ns)},
               {key::iterations, summary(it)},
               {"loop_wall_s", wall},
               {"loop_cpu_s", cpu},
               {"cpu_ns_per_solve", 1e9 * cpu / g.N}};
  }
  T["timer_overhead_ns_subtracted"] = overhead;
  T["pinned_cpu"] = pin;
  return T;
}

/// The grid's shapes, one per value; a value the family rejects has none
/// and its error instead (recorded in its point, not fatal). `sharpest`:
/// the last valid value's index, whose shape sets the trajectory's range.
struct GridShapes {
  std::vector<std::optional<Shape>> shapes;
  std::vector<std::string> errors;
  std::size_t sharpest = 0;
};

GridShapes grid_shapes(const Scene& scene, const GridSpec& cfg) {
  GridShapes out;
  int last_valid = -1;
  for (std::size_t i = 0; i < cfg.values.size(); ++i) {
    try {
      const ShapeSpec s = parse_shape_inline(cfg.shape_texts[i], scene.path, "grid.values[" + std::to_string(i) + "]");
      out.shapes.push_back(*s.shape);
      out.errors.emplace_back();
      last_valid = static_cast<int>(i);
    } catch (const std::exception& e) {
      out.shapes.emplace_back();
      out.errors.emplace_back(e.what());
    }
  }
  if (last_valid < 0) throw std::runtime_error(scene.path + ": no valid grid value");
  out.sharpest = static_cast<std::size_t>(last_valid);
  return out;
}

/// The line on stderr after each grid point: its headline figures.
void print_point_line(const GridSpec& cfg, std::size_t gi, const json& P) {
  const auto& cold = P["timing"]["cold"];
  const auto& warm = P["timing"]["warm"];
  std::fprintf(stderr,
               "%s = %g: converged cold %.6f warm %.6f | alpha err p99 %.3e max %.3e | radial gap %.3e | "
               "cold %.0f ns warm %.0f ns (median) | rcond p50 %.2e min %.2e\n",
               cfg.parameter.c_str(), cfg.values[gi], cold[key::converged_fraction].get<double>(),
               warm[key::converged_fraction].get<double>(),
               P["cold_accuracy_pass"][key::alpha_rel_error].value(key::p99, NAN),
               P["cold_accuracy_pass"][key::alpha_rel_error].value(key::max, NAN),
               P[key::geometry][key::radial_gap_max_rel].get<double>(), cold["time_ns"]["p50"].get<double>(),
               warm["time_ns"]["p50"].get<double>(), P["conditioning"]["rcond_svd"].value("p50", NAN),
               P["conditioning"]["rcond_svd"].value("min", NAN));
}

/// The figures of one valid grid value into its point P: the smooth body
/// against its exact body, the accuracy pass and its smoothness along the
/// trajectory, the oracle cross-check (superellipsoids), then the timed
/// passes. Failed solves go to `failures`.
void measure_point(const Scene& scene, const StudyOptions& o, const Shape& partner, const Shape& S, const PoseGenerator& gen,
                   double Lpair, const std::vector<Vec3>& fib, double value, json& P, json& failures) {
  const GridSpec& cfg = scene.spec.as<GridSpec>();
  SolverOptions opt_derivatives = scene.solver;  // the accuracy pass reads the KKT factorisation
  opt_derivatives.derivatives = true;
  P["valid"] = true;
  P["shape"] = describe(S);
  const baselines::geom::Convex K = baselines::geom::sharp_limit(baselines::to_desc(S));
  P["exact_body"] = baselines::geom::describe(K);
  const GridPoint g{partner, cfg.partner_radius, S, K, scene.name + "@" + std::to_string(value), gen, scene.poses};
  P[key::geometry] = geometry_figures(g, fib);
  {
    const std::vector<PoseData> D = accuracy_pass(g, opt_derivatives, std::max(1, o.threads), failures);
    accuracy_figures(g, D, P);
    if (const auto* se = std::get_if<Superellipsoid>(&S); se && cfg.oracle_check_poses > 0)
      P["oracle_cross_check"] = oracle_cross_check(g, *se, cfg.oracle_check_poses);
    P[key::smoothness] = smoothness_figures(g, D, Lpair);
  }
  // The timed passes: alpha* alone unless the grid asks for more.
  P["timing"] = timing_passes(g, scene.solver, scene.warmup, o.pin, failures);
}

}  // namespace

json run_smoothing(const Scene& scene, const StudyOptions& o, const json& meta, json& failures_out) {
  const GridSpec& cfg = scene.spec.as<GridSpec>();
  const int threads = std::max(1, o.threads);
  const auto wall0 = Clock::now();
  const Shape partner = Sphere(cfg.partner_radius);
  const GridShapes grid = grid_shapes(scene, cfg);
  const Shape& sharpest = *grid.shapes[grid.sharpest];
  // One trajectory for the whole grid: the harness's paper sweep with the
  // radial range of the partner and the sharpest shape.
  const RadialRange range = radial_range(partner, sharpest);
  const PoseGenerator gen(GeneratorKind::Paper, range, scene.dt);
  const double Lpair = cfg.partner_radius + radii(sharpest).outer;
  const std::vector<Vec3> fib = fibonacci_sphere(cfg.directions);  // dense direction sample: Fibonacci sphere

  json points = json::array();
  json failures = json::array();
  std::vector<std::size_t> ran;
  for (std::size_t gi = 0; gi < cfg.values.size(); ++gi) {
    if (!in_shard(gi, o.shard_index, o.shard_count)) continue;
    ran.push_back(gi);
    json P = {{"value", cfg.values[gi]}, {"shape_text", cfg.shape_texts[gi]}};
    if (!grid.shapes[gi]) {
      P["valid"] = false;
      P["invalid_reason"] = grid.errors[gi];
      std::fprintf(stderr, "%s = %g: invalid: %s\n", cfg.parameter.c_str(), cfg.values[gi], grid.errors[gi].c_str());
    } else {
      measure_point(scene, o, partner, *grid.shapes[gi], gen, Lpair, fib, cfg.values[gi], P, failures);
      print_point_line(cfg, gi, P);
    }
    points.push_back(P);
  }

  // Every valid value is of the one family: named by the sharpest, so that
  // a shard without valid values names it too.
  json out = results_header(kSmoothingSchema, meta, {scene.path, scene.name, scene.text}, scene.solver);
  out.update(json{{"name", scene.name},
                  {"description", scene.description},
                  {"family", family_name(sharpest)},
                  {"parameter", cfg.parameter},
                  {"partner", describe(partner)},
                  {"pairing", "body 1 = partner sphere at the identity, body 2 = the family's shape at X_12"},
                  {"sweep", {{"generator", "paper"}, {"poses", scene.poses}, {"dt", scene.dt}, {"warmup", scene.warmup},
                             {"rmin", range.rmin}, {"rmax", range.rmax}}},
                  {"threads_non_timing", threads},
                  {"wall_seconds", std::chrono::duration<double>(Clock::now() - wall0).count()},
                  {"points", points},
                  {key::recommend_error_below, cfg.recommend_error_below},
                  {"failures_file", o.failures_path},
                  {"failure_count", failures.size()}});
  if (o.shard_count > 1) out["shard"] = entry_shard_json(o.shard_index, o.shard_count, ran);
  append_failures(failures_out, std::move(failures), o.failures_path);
  return out;
}

}  // namespace idcol::harness

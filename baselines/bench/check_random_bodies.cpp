// Random bodies of every family at random poses, each solved cold, in the
// swapped order (body 2 at the inverse pose) and warm (from the solution of
// a nearby pose), and every converged answer checked against the
// support-function bracket (support_oracle.hpp), which shares no code with
// the solver. A converged alpha* outside its bracket is a false convergence.
//
// Bodies (seeded; one new pair per pose):
//   sphere          R = s
//   superellipsoid  (s, s a1, s a2), n in {1, 1.5, 2, 3, 4, 8, 16} (wide: ..., 32, 64)
//   cylinder        R = s, h = s a1, the same n
//   box             half-extents (s, s a1, s a2), beta in {5, 20, 100, 1000} (wide: 1e4
//                   instead of 1000), L = the smallest half-extent (wide: the largest,
//                   with beta raised to 3 h_max log 6 / h_min where the smooth box
//                   would not hold its centre, at most 1e4)
//   polytope        hull of 6-25 random points on the ellipsoid (s, s a1, s a2) and its
//                   6 axis points, beta as the box
//   truncated cone  Rb = s, Rt = s U(0.1, 1), a = s a1 / 2, b = a U(0.3, 1), beta as the box
// where s is log-uniform in [10^-0.5, 10^0.5] (wide: [1e-3, 1e3]) and the aspect
// ratios a1, a2 log-uniform in [1, 10] (wide: [1, 1000]).
// Poses: a uniform rotation and |r| = (r1_in + r2_in) 10^U(-3, 3) along a uniform
// direction; the warm solve starts from the pose itself and solves |r| x 1.01
// with a further rotation of 0.02 rad.
//
//   build/baselines/idcol_check_random_bodies [poses per ordered pair = 1000] [wide = 0] [seed = 1] [strict = 0]
//
// Prints one row per ordered family pair and the totals; exit status 1 if any
// converged answer falls outside its bracket, or (strict) if any solve does
// not converge.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "idcol/solver.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/support_oracle.hpp"

using namespace idcol;
using namespace idcol::baselines;

namespace {

using Rng = std::mt19937_64;
double uni(Rng& g, double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }

Mat3 random_rotation(Rng& g) {
  std::normal_distribution<double> N;
  Eigen::Quaterniond q(N(g), N(g), N(g), N(g));
  q.normalize();
  return q.toRotationMatrix();
}

const char* kFamily[] = {"sphere", "superellipsoid", "cylinder", "box", "polytope", "cone"};

struct Ranges {
  bool wide = false;
  double beta(Rng& g) const {
    static const double normal[] = {5, 20, 100, 1000}, large[] = {5, 20, 100, 1e4};
    return (wide ? large : normal)[g() % 4];
  }
  double n(Rng& g) const {
    static const double normal[] = {1, 1.5, 2, 3, 4, 8, 16}, large[] = {1, 1.5, 2, 3, 4, 32, 64};
    return (wide ? large : normal)[g() % 7];
  }
  double size(Rng& g) const { return wide ? std::pow(10.0, uni(g, -3, 3)) : std::pow(10.0, uni(g, -0.5, 0.5)); }
  double aspect(Rng& g) const { return std::pow(10.0, uni(g, 0.0, wide ? 3.0 : 1.0)); }
};

Shape make_body(int family, const Ranges& rg, Rng& g) {
  const double s = rg.size(g);
  switch (family) {
    case 0: return Sphere(s);
    case 1: return Superellipsoid(s, s * rg.aspect(g), s * rg.aspect(g), rg.n(g));
    case 2: return SuperellipticCylinder(s, s * rg.aspect(g), rg.n(g));
    case 3: {
      const double h[3] = {s, s * rg.aspect(g), s * rg.aspect(g)};
      const double hmin = std::min({h[0], h[1], h[2]}), hmax = std::max({h[0], h[1], h[2]});
      std::vector<Vec3> A;
      std::vector<double> b;
      for (int i = 0; i < 3; ++i)
        for (int sg = -1; sg <= 1; sg += 2) {
          Vec3 a = Vec3::Zero();
          a[i] = sg;
          A.push_back(a);
          b.push_back(h[i]);
        }
      const double beta = rg.beta(g);
      if (!rg.wide) return SmoothPolytope(A, b, beta, hmin);
      return SmoothPolytope(A, b, std::min(std::max(beta, 3.0 * hmax * std::log(6.0) / hmin), 1e4), hmax);
    }
    case 4: {
      std::normal_distribution<double> N;
      const Vec3 ax(s, s * rg.aspect(g), s * rg.aspect(g));
      std::vector<Vec3> V;
      const int m = 6 + static_cast<int>(g() % 20);
      for (int i = 0; i < m; ++i) V.push_back(Vec3(N(g), N(g), N(g)).normalized().cwiseProduct(ax));
      for (int i = 0; i < 3; ++i)
        for (int sg = -1; sg <= 1; sg += 2) {
          Vec3 v = Vec3::Zero();
          v[i] = sg * ax[i];
          V.push_back(v);
        }
      const double beta = rg.beta(g);
      if (!rg.wide) return SmoothPolytope::from_vertices(V, beta, 0.3 * ax.minCoeff());
      const SmoothPolytope sharp = SmoothPolytope::from_vertices(V, 1e4, ax.maxCoeff());
      double bmin = 1e300;
      for (int i = 0; i < sharp.num_halfspaces(); ++i) bmin = std::min(bmin, sharp.offset(i));
      const double need = 3.0 * ax.maxCoeff() * std::log(static_cast<double>(sharp.num_halfspaces())) / bmin;
      return SmoothPolytope::from_vertices(V, std::min(std::max(beta, need), 1e4), ax.maxCoeff());
    }
    default: {
      const double Rb = s, Rt = s * uni(g, 0.1, 1.0), a = 0.5 * s * rg.aspect(g), b = a * uni(g, 0.3, 1.0);
      return SmoothTruncatedCone(Rb, Rt, a, b, rg.beta(g));
    }
  }
}

struct Row {
  long solves = 0, converged = 0, outside = 0, oracle_failed = 0, iterations = 0, barrier = 0;
  std::map<std::string, long> failures;
  void add(const Row& o) {
    solves += o.solves;
    converged += o.converged;
    outside += o.outside;
    oracle_failed += o.oracle_failed;
    iterations += o.iterations;
    barrier += o.barrier;
    for (const auto& [k, v] : o.failures) failures[k] += v;
  }
  /// "status=count " for each failure status.
  std::string failure_text() const {
    std::string why;
    for (const auto& [k, v] : failures) why += k + "=" + std::to_string(v) + " ";
    return why;
  }
};

/// Converged alpha against the bracket of the same pose: 0 inside, else the relative distance.
double outside(double alpha, const AlphaBracket& b) {
  // The solver's tolerance (1e-10 relative) on top of the oracle's own margin.
  const double tol = 1e-9;
  if (alpha < b.lo * (1.0 - tol)) return b.lo / alpha - 1.0;
  if (alpha > b.hi * (1.0 + tol)) return alpha / b.hi - 1.0;
  return 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  const int per = argc > 1 ? std::atoi(argv[1]) : 1000;
  Ranges rg;
  rg.wide = argc > 2 && std::atoi(argv[2]) != 0;
  const unsigned seed = argc > 3 ? static_cast<unsigned>(std::atoi(argv[3])) : 1u;
  const bool strict = argc > 4 && std::atoi(argv[4]) != 0;
  if (per < 1) {
    std::fprintf(stderr, "idcol_check_random_bodies: poses per pair must be >= 1, got %s\n", argv[1]);
    return 2;
  }
  std::printf("random bodies, %s range, %d poses per ordered pair, seed %u; each pose solved cold, swapped and warm\n",
              rg.wide ? "wide" : "normal", per, seed);
  std::printf("%-30s %8s %10s %8s %8s %10s %s\n", "pair", "solves", "converged", "outside", "no_oracle", "mean_iter", "failures");
  Row total;
  for (int f1 = 0; f1 < 6; ++f1)
    for (int f2 = 0; f2 < 6; ++f2) {
      Rng g(seed * 1000003ull + 1000ull * f1 + f2);
      Row row;
      for (int k = 0; k < per; ++k) {
        const Shape a = make_body(f1, rg, g), b = make_body(f2, rg, g);
        std::normal_distribution<double> N;
        Pose X{random_rotation(g), Vec3::Zero()};
        X.p = Vec3(N(g), N(g), N(g)).normalized() * ((radii(a).inner + radii(b).inner) * std::pow(10.0, uni(g, -3, 3)));
        Pose X2 = X;
        X2.p *= 1.01;
        X2.R = X.R * Eigen::AngleAxisd(0.02, Vec3::UnitZ()).toRotationMatrix();
        WarmStart w;
        (void)solve(a, b, X, {}, &w);
        const SolveResult r[3] = {solve(a, b, X), solve(b, a, X.inverse()), solve(a, b, X2, {}, &w)};
        const Pose* poses[3] = {&X, &X, &X2};
        const SupportOracle oracle(to_desc(a), to_desc(b));
        AlphaBracket br[2];
        for (int j = 0; j < 2; ++j) {
          const Pose& P = j == 0 ? X : X2;
          br[j] = oracle.bracket(geom::Pose{P.R, P.p});
        }
        for (int j = 0; j < 3; ++j) {
          ++row.solves;
          row.iterations += r[j].iterations;
          row.barrier += r[j].used_barrier;
          if (!r[j].converged()) {
            ++row.failures[to_string(r[j].status)];
            // A record to replay: both bodies and the pose at 17 digits
            // (solve 1 is body 2 against body 1 at the inverse pose).
            const Pose& P = *poses[j];
            std::printf("  FAILED %s-%s pose %d solve %d: %s, residual %.3g, %d iterations%s%s\n    %s\n    %s\n"
                        "    R = [%.17g, %.17g, %.17g; %.17g, %.17g, %.17g; %.17g, %.17g, %.17g], p = [%.17g, %.17g, %.17g]\n",
                        kFamily[f1], kFamily[f2], k, j, to_string(r[j].status), r[j].residual_norm, r[j].iterations,
                        r[j].used_continuation ? ", continuation" : "", r[j].used_barrier ? ", barrier" : "", describe(a).c_str(),
                        describe(b).c_str(), P.R(0, 0), P.R(0, 1), P.R(0, 2), P.R(1, 0), P.R(1, 1), P.R(1, 2), P.R(2, 0), P.R(2, 1),
                        P.R(2, 2), P.p[0], P.p[1], P.p[2]);
            continue;
          }
          ++row.converged;
          const AlphaBracket& bj = br[poses[j] == &X ? 0 : 1];
          if (!bj.ok) {
            ++row.oracle_failed;
            continue;
          }
          const double d = outside(r[j].alpha, bj);
          if (d > 0.0) {
            ++row.outside;
            std::printf("  OUTSIDE %s-%s pose %d solve %d: alpha %.17g, bracket [%.17g, %.17g], residual %.3g, %d iterations%s%s\n    %s\n    %s\n",
                        kFamily[f1], kFamily[f2], k, j, r[j].alpha, bj.lo, bj.hi, r[j].residual_norm, r[j].iterations,
                        r[j].used_continuation ? ", continuation" : "", r[j].used_barrier ? ", barrier" : "", describe(a).c_str(),
                        describe(b).c_str());
          }
        }
      }
      const std::string name = std::string(kFamily[f1]) + "-" + kFamily[f2];
      std::printf("%-30s %8ld %9.3f%% %8ld %8ld %10.1f %s\n", name.c_str(), row.solves, 100.0 * row.converged / row.solves, row.outside,
                  row.oracle_failed, static_cast<double>(row.iterations) / row.solves, row.failure_text().c_str());
      total.add(row);
    }
  const std::string why = total.failure_text();
  std::printf("total: %ld solves, %ld converged (%.4f%%), %ld not converged (%s), %ld converged outside the bracket "
              "(false convergences), %ld without an oracle bracket, %ld used the barrier\n",
              total.solves, total.converged, 100.0 * total.converged / total.solves, total.solves - total.converged,
              why.empty() ? "none" : why.c_str(), total.outside, total.oracle_failed, total.barrier);
  return total.outside == 0 && (!strict || total.converged == total.solves) ? 0 : 1;
}

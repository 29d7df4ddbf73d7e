// The solver against closed forms, invariances and its own KKT conditions,
// over many seeded poses for every pair of the catalogue.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <limits>
#include <random>
#include <sstream>

#include "src/solver/solver_impl.hpp"
#include "idcol/kkt.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

/// Independent check of a converged answer: both witness points on their
/// surfaces, outward normals opposite, multipliers positive.
// Uses core's own eval: a consistency check of the KKT point. The same hard
// cases are checked against the independent geometry and oracles (nothing of
// core's shapes or solver) in baselines/tests/test_oracles.cpp,
// IndependentChecks.HardCasesAgreeWithIndependentGeometry.
void expect_kkt(const Shape& a, const Shape& b, const Pose& X, const SolveResult& r, const std::string& what) {
  ASSERT_TRUE(r.converged()) << what << " status=" << to_string(r.status);
  EXPECT_GT(r.lambda1, 0.0) << what;
  EXPECT_GT(r.lambda2, 0.0) << what;
  const Vec3 p1 = r.x_1 / r.alpha;
  const Vec3 p2 = X.R.transpose() * (r.x_1 - X.p) / r.alpha;
  ShapeEval e1, e2;
  eval(a, p1, e1);
  eval(b, p2, e2);
  // |phi| / |grad phi| is the distance to the surface to first order.
  const double L = radii(a).outer + radii(b).outer;
  EXPECT_LT(std::abs(e1.phi) / e1.grad.norm(), 1e-8 * L) << what;
  EXPECT_LT(std::abs(e2.phi) / e2.grad.norm(), 1e-8 * L) << what;
  const Vec3 n1 = e1.grad.normalized(), n2 = (X.R * e2.grad).normalized();
  EXPECT_LT((n1 + n2).norm(), 1e-7) << what;
}

Pose scaled(const Pose& X, double c) { return Pose{X.R, c * X.p}; }

Shape scale_shape(const Shape& s, double c) {
  return std::visit(
      [c](const auto& x) -> Shape {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, Sphere>) return Sphere(c * x.R());
        else if constexpr (std::is_same_v<T, Superellipsoid>) return Superellipsoid(c * x.a(), c * x.b(), c * x.c(), x.n());
        else if constexpr (std::is_same_v<T, SuperellipticCylinder>) return SuperellipticCylinder(c * x.R(), c * x.h(), x.n());
        else if constexpr (std::is_same_v<T, SmoothPolytope>) {
          std::vector<Vec3> A;
          std::vector<double> b;
          for (int i = 0; i < x.num_halfspaces(); ++i) A.push_back(x.normal(i)), b.push_back(c * x.offset(i));
          return SmoothPolytope(A, b, x.beta(), c * x.L());
        } else return SmoothTruncatedCone(c * x.Rb(), c * x.Rt(), c * x.a(), c * x.b(), x.beta());
      },
      s);
}

/// The certified lower bound on alpha* along the unit u from the bodies'
/// own support functions: u.p / (h_a(u) + h_b(-R^T u)).
double support_lower_bound(const Shape& a, const Shape& b, const Pose& X, const Vec3& u) {
  auto support = [](const Shape& s, const Vec3& v) { return std::visit([&v](const auto& x) { return x.support(v); }, s); };
  return u.dot(X.p) / (support(a, u) + support(b, Vec3(-(X.R.transpose() * u))));
}

/// The witness points of a converged answer (p2 in body 2's frame) with the
/// shapes evaluated there; expects both on their surfaces to 1e-8 of the
/// body's size.
struct Witnesses {
  Vec3 p1, p2;
  ShapeEval e1, e2;
};
Witnesses expect_witnesses_on_surfaces(const Shape& a, const Shape& b, const Pose& X, const SolveResult& r,
                                       const std::string& what) {
  Witnesses w{r.x_1 / r.alpha, X.R.transpose() * (r.x_1 - X.p) / r.alpha, {}, {}};
  eval(a, w.p1, w.e1);
  eval(b, w.p2, w.e2);
  EXPECT_LT(std::abs(w.e1.phi) / w.e1.grad.norm(), 1e-8 * radii(a).outer) << what;
  EXPECT_LT(std::abs(w.e2.phi) / w.e2.grad.norm(), 1e-8 * radii(b).outer) << what;
  return w;
}

}  // namespace

TEST(Kkt, JacobianMatchesCentralDifferences) {
  std::mt19937_64 rng(21);
  const auto cat = test::catalogue();
  for (const auto& A : cat) {
    for (const auto& B : cat) {
      std::visit(
          [&](const auto& s1, const auto& s2) {
            using S1 = std::decay_t<decltype(s1)>;
            using S2 = std::decay_t<decltype(s2)>;
            for (int trial = 0; trial < 5; ++trial) {
              KktProblem<S1, S2> P{&s1, &s2, test::random_rotation(rng), Vec3::Zero(), Vec3::Zero(), 0.0, s1.sharpness(), s2.sharpness(), 0, 0};
              const Vec3 u = test::random_unit(rng);
              P.c1 = 0.4 * u;
              P.c2 = 0.6 * u;
              P.L = s1.radii().outer + s2.radii().outer;
              P.inv_sigma1 = 1.0 / s1.phi_scale();
              P.inv_sigma2 = 1.0 / s2.phi_scale();
              Vec6 z;
              z.head<3>() = 0.4 * test::random_unit(rng);
              z[3] = std::log(1.3);
              z[4] = 0.7;
              z[5] = 0.9;
              KktPoint p, q;
              kkt_residual(P, z, p);
              Mat6 J;
              kkt_jacobian(P, p, J);
              Mat6 Jfd;
              for (int k = 0; k < 6; ++k) {
                const double h = 1e-6;
                Vec6 dz = Vec6::Zero();
                dz[k] = h;
                kkt_residual(P, z + dz, q);
                const Vec6 Fp = q.F;
                kkt_residual(P, z - dz, q);
                Jfd.col(k) = (Fp - q.F) / (2 * h);
              }
              EXPECT_LT((J - Jfd).norm(), 1e-6 * std::max(1.0, J.norm())) << A.name << "-" << B.name << "\n" << J << "\n\n" << Jfd;
            }
          },
          A.shape, B.shape);
    }
  }
}

TEST(Solver, SphereSphereClosedForm) {
  std::mt19937_64 rng(1);
  const SolverOptions opt;
  for (int i = 0; i < 2000; ++i) {
    const double R1 = std::exp(std::uniform_real_distribution<double>(-3, 3)(rng));
    const double R2 = std::exp(std::uniform_real_distribution<double>(-3, 3)(rng));
    const Pose X = test::random_pose(rng, 1e-3 * (R1 + R2), 1e3 * (R1 + R2));
    const SolveResult r = solve(Sphere(R1), Sphere(R2), X, opt);
    ASSERT_TRUE(r.converged());
    EXPECT_NEAR(r.alpha, X.p.norm() / (R1 + R2), 1e-12 * r.alpha);
  }
}

TEST(Solver, EveryPairSatisfiesKktAndInvariances) {
  std::mt19937_64 rng(2);
  const auto cat = test::catalogue();
  for (const auto& A : cat) {
    for (const auto& B : cat) {
      const double L = radii(A.shape).outer + radii(B.shape).outer;
      for (int i = 0; i < 60; ++i) {
        const Pose X = test::random_pose(rng, 0.02 * L, 5.0 * L);
        const std::string what = A.name + "-" + B.name + " pose " + std::to_string(i);
        const SolveResult r = solve(A.shape, B.shape, X);
        expect_kkt(A.shape, B.shape, X, r, what);
        if (!r.converged()) continue;
        // A/B swap.
        const SolveResult s = solve(B.shape, A.shape, X.inverse());
        ASSERT_TRUE(s.converged()) << what;
        EXPECT_NEAR(s.alpha, r.alpha, 1e-9 * r.alpha) << what;
        // A common rigid motion of both bodies.
        const Pose T{test::random_rotation(rng), test::random_unit(rng) * 3.7};
        const SolveResult w = solve_world(A.shape, T, B.shape, T * X);
        ASSERT_TRUE(w.converged()) << what;
        EXPECT_NEAR(w.alpha, r.alpha, 1e-9 * r.alpha) << what;
        EXPECT_LT((w.x_1 - r.x_1).norm(), 1e-8 * L * r.alpha) << what;
        // Scaling every length by c.
        const double c = 0.37;
        const SolveResult u = solve(scale_shape(A.shape, c), scale_shape(B.shape, c), scaled(X, c));
        ASSERT_TRUE(u.converged()) << what;
        EXPECT_NEAR(u.alpha, r.alpha, 1e-9 * r.alpha) << what;
      }
    }
  }
}

// A chord step (the last Newton step's LU reused near the root) is kept only
// when it meets the tolerance: it always ends its run as converged, so it
// can never add a step, and each run makes at most one.
TEST(Solver, ChordStepOnlyEndsARunAtTheTolerance) {
  struct Recorder : TraceSink {
    std::vector<TraceRecord> recs;
    void record(const TraceRecord& r) override { recs.push_back(r); }
  };
  std::mt19937_64 rng(5);
  const auto cat = test::catalogue();
  const SolverOptions o;
  int chords = 0;
  for (const auto& A : cat) {
    for (const auto& B : cat) {
      const double L = radii(A.shape).outer + radii(B.shape).outer;
      for (int i = 0; i < 20; ++i) {
        const Pose X = test::random_pose(rng, 0.02 * L, 5.0 * L);
        const std::string what = A.name + "-" + B.name + " pose " + std::to_string(i);
        Recorder rec;
        const SolveResult r = solve(A.shape, B.shape, X, o, nullptr, &rec);
        std::map<int, int> per_run;
        for (std::size_t k = 0; k < rec.recs.size(); ++k) {
          if (std::string(rec.recs[k].step) != "chord") continue;
          ++chords;
          EXPECT_EQ(++per_run[rec.recs[k].run], 1) << what;
          ASSERT_LT(k + 1, rec.recs.size()) << what;
          const TraceRecord& next = rec.recs[k + 1];
          EXPECT_EQ(next.run, rec.recs[k].run) << what;
          EXPECT_STREQ(next.step, "converged") << what;
          EXPECT_LE(next.residual, o.tolerance) << what;
        }
        if (!per_run.empty()) {
          ASSERT_TRUE(r.converged()) << what;
          expect_kkt(A.shape, B.shape, X, r, what);
        }
      }
    }
  }
  EXPECT_GT(chords, 100);  // the rule is exercised, not only allowed
}

// Two ellipsoids start from their contact in closed form up to one scalar
// (ellipsoid_contact, Perram and Wertheim's function), from 1:1 to 1000:1:
// a cold solve takes at most one Newton step. The answer is checked against
// the support functions, which share nothing with that guess: for every unit
// n, alpha* >= n.r / (h1(n) + h2(-R^T n)) with h(n) = |diag(a, b, c) n|,
// with equality at the contact normal.
TEST(Solver, EllipsoidPairsStartAtTheirContact) {
  const std::vector<Vec3> axes = {{0.5, 1.0, 1.5}, {1.0, 1.0, 1.0}, {0.02, 1.0, 0.7}, {0.3, 0.3, 6.0}, {0.001, 1.0, 1.0}};
  auto h = [](const Vec3& ax, const Vec3& n) { return ax.cwiseProduct(n).norm(); };
  std::mt19937_64 rng(11);
  for (const Vec3& A : axes) {
    for (const Vec3& B : axes) {
      int its = 0;
      double worst = 0.0;
      const Superellipsoid e1(A[0], A[1], A[2], 1.0), e2(B[0], B[1], B[2], 1.0);
      const double L = e1.radii().outer + e2.radii().outer;
      for (int i = 0; i < 40; ++i) {
        const Pose X = test::random_pose(rng, 0.02 * L, 5.0 * L);
        std::ostringstream what;
        what << A.transpose() << " / " << B.transpose() << " pose " << i;
        const SolveResult r = solve(e1, e2, X);
        expect_kkt(e1, e2, X, r, what.str());
        ASSERT_TRUE(r.converged()) << what.str();
        its += r.iterations;
        EXPECT_LE(r.iterations, 1) << what.str();
        EXPECT_EQ(r.restarts, 0) << what.str();
        const Vec3 y = r.x_1 / r.alpha;  // the witness point on body 1, unscaled
        // Both witness points on their ellipsoids, |diag(1/a) y| = 1.
        const Vec3 y2 = X.R.transpose() * (y - X.p / r.alpha);
        worst = std::max({worst, std::abs(y.cwiseQuotient(A).norm() - 1.0), std::abs(y2.cwiseQuotient(B).norm() - 1.0)});
        const Vec3 n = y.cwiseQuotient(A.cwiseProduct(A)).normalized();
        const double at_normal = n.dot(X.p) / (h(A, n) + h(B, Vec3(-(X.R.transpose() * n))));
        EXPECT_NEAR(at_normal, r.alpha, 1e-9 * r.alpha) << what.str();
        for (int k = 0; k < 50; ++k) {
          const Vec3 m = test::random_unit(rng);
          EXPECT_LE(m.dot(X.p) / (h(A, m) + h(B, Vec3(-(X.R.transpose() * m)))), r.alpha * (1.0 + 1e-12)) << what.str();
        }
      }
      // The closed form itself is the answer: its l is settled to rounding
      // (a Newton step under 1e-9 is taken even where rounding noise in
      // F'(l) has closed the bracket on the wrong side of the root), so the
      // solver takes no step. Bisecting there instead left some 8% of the
      // paper sweep's poses off the surfaces by up to 9e-10, and a step to
      // go. Only a 1000:1 disc as body 2 still needs one, on a few poses.
      if (B[0] != 0.001) {
        EXPECT_EQ(its, 0) << A.transpose() << " / " << B.transpose();
        EXPECT_LE(worst, 1e-12) << A.transpose() << " / " << B.transpose();
      }
    }
  }
}

TEST(Solver, WarmStartSequenceMatchesColdAndNeverFailsMore) {
  std::mt19937_64 rng(4);
  for (const auto& A : test::paper_shapes()) {
    for (const auto& B : test::paper_shapes()) {
      ContactPair pair(A.shape, B.shape);
      Pose X{test::random_rotation(rng), Vec3(1.5, 0.3, -0.2)};
      for (int i = 0; i < 300; ++i) {
        const Pose dX = test::se3_exp(0.02 * test::random_unit(rng), 0.03 * test::random_unit(rng));
        X = X * dX;
        if (X.p.norm() > 5.0) X.p *= 0.5;
        const SolveResult w = pair.solve(X);
        const SolveResult c = pair.solve_cold(X);
        ASSERT_TRUE(c.converged()) << A.name << "-" << B.name;
        ASSERT_TRUE(w.converged()) << A.name << "-" << B.name;
        EXPECT_TRUE(w.warm_started || i == 0);
        EXPECT_NEAR(w.alpha, c.alpha, 1e-9 * c.alpha);
      }
    }
  }
}

// The warm predictor (SolverOptions::warm_predictor_order): on a pose moving
// at a steady rate it cuts the warm Newton steps; after a jump (a predictor
// far off) the solve still converges, to the cold answer.
TEST(Solver, WarmPredictorCutsStepsOnSteadyMotionAndSurvivesJumps) {
  std::mt19937_64 rng(8);
  int pairs = 0;
  long total[3] = {0, 0, 0};
  for (const auto& A : test::paper_shapes()) {
    for (const auto& B : test::paper_shapes()) {
      const Pose X0{test::random_rotation(rng), Vec3(1.6, 0.4, -0.3)};
      const Vec3 w = 0.01 * test::random_unit(rng), v = 0.004 * test::random_unit(rng);
      long its[3] = {0, 0, 0};
      for (int order = 0; order <= 2; ++order) {
        SolverOptions o;
        o.warm_predictor_order = order;
        ContactPair pair(A.shape, B.shape, o);
        Pose X = X0;
        for (int i = 0; i < 200; ++i) {
          if (i == 120) X.p *= 1.8;  // a jump: the extrapolation is far off
          X = X * test::se3_exp(w, v);
          const SolveResult r = pair.solve(X);
          ASSERT_TRUE(r.converged()) << A.name << "-" << B.name << " order " << order << " step " << i;
          if (i == 0 || i % 40 == 0 || i == 120) {
            const SolveResult c = pair.solve_cold(X);
            ASSERT_TRUE(c.converged());
            EXPECT_NEAR(r.alpha, c.alpha, 1e-9 * c.alpha) << A.name << "-" << B.name << " order " << order << " step " << i;
          }
          its[order] += r.iterations;
        }
      }
      // Per pair the predictor may lose a few steps where the motion is
      // nearly linear and the jump costs its capped attempt (a compiler's
      // rounding moves single solves by a step); over all pairs it must cut
      // the warm steps clearly.
      EXPECT_LE(its[2], its[0] + 20) << A.name << "-" << B.name;
      EXPECT_LE(its[1], its[0] + 20) << A.name << "-" << B.name;
      for (int order = 0; order <= 2; ++order) total[order] += its[order];
      ++pairs;
    }
  }
  EXPECT_EQ(pairs, 16);
  std::printf("warm steps over 16 pairs x 200 poses: order 0 %ld, order 1 %ld, order 2 %ld\n", total[0], total[1], total[2]);
  // Measured: 0.55-0.58 (quadratic) and 0.73-0.81 (linear) of the steps
  // without the predictor, with GCC 12 -O3 and clang 14 with sanitizers.
  EXPECT_LT(total[2], 0.7 * total[0]);
  EXPECT_LT(total[1], 0.9 * total[0]);
}

// On a random walk the steps are short but point anywhere: extrapolating
// them misses, and the predictor must stand aside (WarmStart::extrapolate)
// rather than cost its two capped steps a query. Before it did, these walks
// took 1.6x the warm steps of no predictor, 0.8-1.3x those of cold solves.
// A steady motion with 10% jitter per step is the middle ground: at steps of
// 0.01 the predictor costs a little (README, Known limits).
TEST(Solver, WarmPredictorStandsAsideOnARandomWalk) {
  const Shape se = Superellipsoid(0.5, 1.0, 1.5, 8.0), sec = SuperellipticCylinder(1.0, 2.0, 8.0), poly = test::paper_poly(20.0);
  const std::pair<const Shape*, const Shape*> pairs[] = {{&se, &sec}, {&poly, &se}, {&poly, &poly}};
  struct Motion {
    const char* name;
    double step, jitter;  // per twist component: a steady drift of `step`, plus `jitter` x step of noise (a walk: no drift)
  };
  const Motion motions[] = {{"random walk 0.01", 0.0, 0.01}, {"steady 0.01, jitter 10%", 0.01, 0.1}, {"steady 0.001, jitter 10%", 0.001, 0.1}};
  for (const Motion& m : motions) {
    for (const auto& [A, B] : pairs) {
      long its[3] = {0, 0, 0};  // order 0, order 2, cold
      for (int order : {0, 2}) {
        std::mt19937_64 rng(2);
        std::normal_distribution<double> g(0.0, 1.0);
        auto twist = [&](double sd) { return Vec3(sd * g(rng), sd * g(rng), sd * g(rng)); };
        const Vec3 w = twist(m.step), v = twist(m.step);
        const double sd = m.step > 0.0 ? m.jitter * m.step : m.jitter;
        SolverOptions o;
        o.warm_predictor_order = order;
        ContactPair pair(*A, *B, o);
        Pose X{test::random_rotation(rng), 2.0 * test::random_unit(rng)};
        for (int k = 0; k < 1000; ++k) {
          X = X * test::se3_exp(w + twist(sd), v + twist(sd));
          if (X.p.norm() < 0.3 || X.p.norm() > 4.0) X.p *= 2.0 / X.p.norm();
          const SolveResult r = pair.solve(X);
          ASSERT_TRUE(r.converged()) << m.name << ", " << describe(*A) << " step " << k;
          its[order == 0 ? 0 : 1] += r.iterations;
          if (order == 0) its[2] += pair.solve_cold(X).iterations;
        }
      }
      std::printf("%s, warm steps: predictor %ld, none %ld; cold %ld\n", m.name, its[1], its[0], its[2]);
      // Measured (GCC 12 -O3): random walks 0.3% over no predictor and
      // 0.5-0.8x cold; jitter at 0.01 4-10% over, at 0.001 0-2% under.
      EXPECT_LE(its[1], (m.step == 0.0 ? 1.05 : 1.2) * its[0]) << m.name << ", " << describe(*A) << " / " << describe(*B);
      EXPECT_LT(its[1], its[2]) << m.name << ", " << describe(*A) << " / " << describe(*B);
    }
  }
}

// Two n = 8 superellipsoids nearly face to face (pose k = 4 of the paper's
// sweep for SE-SE): the Hessians vanish at the face centres, so J_c is
// singular where the ray guess starts, and LM stalls at a stationary point
// of ||F|| that is not a root. The stall ends the run and the rounding
// continuation solves it; without the rule the restarts stall at the same
// point until the rounding continuation runs anyway. Same answer, a fraction
// of the iterations. (From the ray guess: the support guess, on by default,
// starts at the rim where the faces meet and needs neither.)
TEST(Solver, StalledFirstRunHandsOverToRounding) {
  const Shape se = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  Pose X;
  X.R << -3.1918845344591773e-10, 0.0024122685466222843, 0.99999709047599672,  //
      0.015710789119626208, -0.99987366877120021, 0.0024119708244743068,      //
      0.99987657793611628, 0.015710743409478027, -3.7898323287599567e-05;
  X.p << 2.827349841167321, 0.015889454329052762, 0.01933357504031517;
  ASSERT_EQ(check_pose(X), PoseCheck::Ok);
  SolverOptions ray;
  ray.support_guess = false;
  const SolveResult r = solve(se, se, X, ray);
  ASSERT_TRUE(r.converged()) << to_string(r.status);
  EXPECT_TRUE(r.used_continuation);
  EXPECT_EQ(r.restarts, 0);
  EXPECT_LE(r.iterations, 30);
  const SolveResult g = solve(se, se, X);
  ASSERT_TRUE(g.converged()) << to_string(g.status);
  EXPECT_FALSE(g.used_continuation);
  EXPECT_LE(g.iterations, 8);
  EXPECT_NEAR(g.alpha, r.alpha, 1e-12 * r.alpha);
  SolverOptions crawl = ray;
  crawl.lm_stall_limit = 0;
  const SolveResult c = solve(se, se, X, crawl);
  ASSERT_TRUE(c.converged()) << to_string(c.status);
  EXPECT_GT(c.iterations, 3 * r.iterations);
  EXPECT_NEAR(r.alpha, c.alpha, 1e-12 * c.alpha);
  // The two faces are nearly parallel and flat to high order (n = 8), so the
  // witness point slides along them at a residual of 1e-11 far more than
  // alpha changes: both runs meet the tolerance 3e-8 apart along the faces.
  EXPECT_LT((r.x_1 - c.x_1).norm(), 1e-7 * c.x_1.norm());
}

// The support-function first guess (SolverOptions::support_guess) against
// the ray guess alone, on the same random poses of the flat-faced pairs of
// the paper's Table 1 (n = 8 bodies, the beta = 20 cone and polytope) and
// a pair of sharp boxes (beta = 1000): both answers agree; the guess takes
// fewer Newton steps on every pair, a fifth fewer in all, and no paper pair
// has a long tail (at this commit, on these 400 poses a pair: SE-SE 2159
// steps, at most 25, against 3610, at most 88; the boxes 57,429 against
// 91,499). Iteration counts are deterministic; no timing here.
TEST(Solver, SupportGuessShortensColdSolvesOfFlatFacedPairs) {
  const Shape se = Superellipsoid(0.5, 1.0, 1.5, 8.0), sec = SuperellipticCylinder(1.0, 2.0, 8.0);
  const Shape tc = SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0), poly = test::paper_poly();
  const Shape box = test::box(0.6, 0.9, 0.4, 1000.0);
  const std::pair<Shape, Shape> pairs[] = {{se, se}, {tc, se}, {se, sec}, {poly, poly}, {tc, tc}, {box, box}};
  SolverOptions ray;
  ray.support_guess = false;
  std::mt19937_64 rng(17);
  long with = 0, without = 0;
  for (std::size_t i = 0; i < std::size(pairs); ++i) {
    const auto& [a, b] = pairs[i];
    const std::string name = std::string(family_name(a)) + "-" + family_name(b);
    const double rmin = 0.1 * std::min(radii(a).inner, radii(b).inner), rmax = 2.0 * std::max(radii(a).outer, radii(b).outer);
    long w = 0, wo = 0;
    int worst = 0;
    for (int k = 0; k < 400; ++k) {
      const Pose X = test::random_pose(rng, rmin, rmax);
      const SolveResult r = solve(a, b, X), o = solve(a, b, X, ray);
      ASSERT_TRUE(r.converged() && o.converged()) << name << " k=" << k;
      EXPECT_NEAR(r.alpha, o.alpha, 1e-9 * o.alpha) << name << " k=" << k;
      w += r.iterations;
      wo += o.iterations;
      worst = std::max(worst, r.iterations);
    }
    EXPECT_LT(w, wo) << name;
    if (i + 1 < std::size(pairs)) EXPECT_LE(worst, 30) << name;  // the paper's pairs
    with += w;
    without += wo;
  }
  EXPECT_LT(with, 0.8 * without) << with << " against " << without;
}

TEST(Solver, HardCasesConvergeToGenuineAnswers) {
  std::mt19937_64 rng(5);
  // Two spheres, cold and warm, including a warm start after a huge jump.
  {
    ContactPair p(Sphere(1.0), Sphere(0.5));
    for (int i = 0; i < 200; ++i) {
      const Pose X = test::random_pose(rng, 1e-6, 1e6);
      const SolveResult r = p.solve(X);
      ASSERT_TRUE(r.converged());
      // Warm starts end at the residual tolerance (1e-10), not at the exact guess.
      EXPECT_NEAR(r.alpha, X.p.norm() / 1.5, 1e-9 * r.alpha);
    }
  }
  // A sphere against an ellipsoid along its long axis: alpha = d / (R + c).
  {
    const Shape s = Sphere(0.3), e = Superellipsoid(0.2, 0.5, 4.0, 1.0);
    for (double d : {1e-6, 0.5, 4.3, 1e4}) {
      const SolveResult r = solve(s, e, Pose{test::random_rotation(rng) * 0 + Mat3::Identity(), Vec3(0, 0, d)});
      ASSERT_TRUE(r.converged());
      EXPECT_NEAR(r.alpha, d / 4.3, 1e-12 * r.alpha);
    }
  }
  // Bodies of size 1e-3 against 1e3, in both orders, and beta = 1000 corners.
  const std::vector<std::pair<Shape, Shape>> hard = {
      {Superellipsoid(1e-3, 2e-3, 1.5e-3, 1.0), Superellipsoid(1e3, 2e3, 1.5e3, 1.0)},
      {Superellipsoid(1e3, 2e3, 1.5e3, 2.0), Sphere(1e-3)},
      {test::box(1e-3, 2e-3, 1e-3, 2e4), Superellipsoid(1e3, 2e3, 1.5e3, 1.0)},
      {test::paper_poly(1000.0), test::paper_poly(1000.0)},
      {test::paper_poly(1000.0), Superellipsoid(0.5, 1.0, 1.5, 8.0)},
  };
  for (std::size_t h = 0; h < hard.size(); ++h) {
    const auto& [a, b] = hard[h];
    const double L = radii(a).outer + radii(b).outer;
    const double rin = std::min(radii(a).inner, radii(b).inner);
    for (int i = 0; i < 300; ++i) {
      const Pose X = test::random_pose(rng, 1e-3 * rin, 3 * L);
      expect_kkt(a, b, X, solve(a, b, X), "hard case " + std::to_string(h) + " pose " + std::to_string(i));
    }
  }
}

// 1000:1 ellipsoids need the rounding continuation. Every solve converges,
// as the suite claims of the library's range (aspect ratios to 1000:1):
// with 5000 random poses per case (this seed), 5000 of 5000 converged for
// the needles crossed and for the plate against the needle, and so do the
// 3000 per case solved here. No failure is accepted: the poses are a fixed
// sequence, so the count is exact, not a statistical floor.
TEST(Solver, ExtremeAspectRatioEllipsoids) {
  std::mt19937_64 rng(6);
  const std::vector<std::pair<Shape, Shape>> cases = {
      {Superellipsoid(1000.0, 1.0, 1.0, 1.0), Superellipsoid(1.0, 1.0, 1000.0, 1.0)},
      {Superellipsoid(1.0, 0.001, 1.0, 1.0), Superellipsoid(1.0, 1.0, 1000.0, 1.0)},
  };
  for (const auto& [a, b] : cases) {
    const double L = radii(a).outer + radii(b).outer;
    int ok = 0;
    const int N = 3000;
    for (int i = 0; i < N; ++i) {
      const Pose X = test::random_pose(rng, 1e-3, 3 * L);
      const SolveResult r = solve(a, b, X);
      if (!r.converged()) {
        ADD_FAILURE() << "aspect 1000 pose " << i << ": " << to_string(r.status);
        continue;
      }
      ++ok;
      expect_kkt(a, b, X, r, "aspect 1000 pose " + std::to_string(i));
    }
    EXPECT_EQ(ok, N);
  }
}

// The stress suite's box_needle_plate poses that ended line_search_failed at
// a relative residual of 2-4e-10: the needle (beta h / L = 10^6) touches at
// its far corner, 10 from its centre with a rounding length of 1e-5, where
// a unit in the last place of y moves F5 (the stationarity in alpha) by
// ~2e-10. kkt_rounding_floor now counts that, so the best candidate is
// returned; the normals and surfaces still hold to expect_kkt's tolerances.
TEST(Solver, SharpNeedleCornerEndsAtTheRoundingFloor) {
  const std::vector<Vec3> A = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const Shape plate = SmoothPolytope(A, {10, 10, 10, 10, 0.01, 0.01}, 1000, 0.01);
  const Shape needle = SmoothPolytope(A, {10, 10, 0.01, 0.01, 0.01, 0.01}, 1000, 0.01);
  struct Case {
    Mat3 R;
    Vec3 p;
  };
  std::vector<Case> cases(4);
  cases[0].R << -0.41691601079855856, 0.026185305755474286, 0.90856775735346695, -0.90834373202431118, -0.048355192949439463,
      -0.41541959487603469, 0.033056080105822228, -0.99848690781467675, 0.043945312500000222;
  cases[0].p = Vec3(33.185278719010583, 18.987436102075282, -51.892702877182984);
  cases[1].R << -0.1795321723039307, 0.1163914390597639, 0.97684248065971691, 0.98371199571192591, 0.012273922386491165,
      0.17933226235597044, 0.0088830512940095141, 0.99312757677090413, -0.11669921875000022;
  cases[1].p = Vec3(0.41928341260231028, 0.32312936021696748, -1.0574203760855976);
  cases[2].R << 0.10948925441142532, 0.9931454840027778, -0.040916387588822579, -0.99351257413425387, 0.10807115284690794,
      -0.03540326198910676, -0.030738708586393597, 0.044527222316565612, 0.99853515625;
  cases[2].p = Vec3(0.0064365532942657292, 0.030852997900813646, -0.025418582070474833);
  cases[3].R << -0.99710883988857812, -0.025131324939527647, -0.071710375280279057, 0.070611516338819985, 0.042179712388552559,
      -0.99661170253170905, 0.028070895539457592, -0.99879391686653907, -0.040283203125;
  cases[3].p = Vec3(30.660940732659665, -2.8370561798005456, -138.24595278830753);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Pose X{cases[i].R, cases[i].p};
    const SolveResult r = solve(plate, needle, X);
    expect_kkt(plate, needle, X, r, "box_needle_plate pose " + std::to_string(i));
    EXPECT_LT(r.residual_norm, 1e-9) << i;
  }
}

// Millimetre bodies with a beta = 10^4 rim against partners 10^5..10^7
// times larger (the random-body stress scene's wide range): the multipliers
// differ as much as the sizes, so the unweighted barrier leaves the small
// body 10 rounding widths inside its rim, where the KKT Newton iteration
// stalls; they used to end IterationLimit. The weighted barrier solves them.
// The last two cases are of one size but sharp and slender (a 200:1 box
// against a 190:1 cone, both at beta = 10^4; a 1:600 n = 2 plate against a
// beta = 10^4 cone): the barrier solves their smoothest stage, and only
// splits of the last continuation's steps (625 -> 1250 for the cone; n = 1
// -> 2 with the cone's 2973 -> 5000, split through real n) carry them to
// the target. The last case (a 0.2 m cone against a 962 x 871970 x 3118 box
// 10^4..10^6 times its size) defeats every strategy in this order and
// converges with the bodies swapped: the swapped solve's answer, mapped back
// and polished by one Newton step.
// Checked in both body orders: each witness point on its surface (to 1e-8 of
// that body's own size, not the pair's), outward normals opposite, alpha
// above the certified bound of the exact bodies' support functions (closed
// forms that share nothing with the iteration) along the contact normal and
// the line of centres, and the same alpha in both orders.
TEST(Solver, MillimetreSharpBodyBesideAHugeOneConverges) {
  struct Case {
    const char* what;
    Shape a, b;
    Mat3 R;
    Vec3 p;
  };
  const std::vector<Vec3> box_normals = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  std::vector<Case> cases = {
      {"cylinder R = 499, h = 49542 / cone of 7.5e-3", SuperellipticCylinder(499.20288275385121, 49542.24436285979, 1.0),
       SmoothTruncatedCone(0.0016602034776630168, 0.00040751251754247791, 0.0075106254915336401, 0.0062835223546424783, 10000.0),
       Mat3::Zero(), Vec3(-0.070163527770477893, -1.7110117648529026, 0.83614201133803379)},
      {"box 281 x 159576 x 194068 / cone of 3e-3",
       SmoothPolytope(box_normals,
                      {280.79342798963523, 280.79342798963523, 159575.9627784325, 159575.9627784325, 194068.26992600303,
                       194068.26992600303},
                      3715.0833209257739, 194068.26992600303),
       SmoothTruncatedCone(0.001103064499539608, 0.00091651403524163372, 0.0030806323788550782, 0.0024090964334416275, 10000.0),
       Mat3::Zero(), Vec3(-6.6641950720944365, 2.7846363367997045, -27.783485853760109)},
      {"cone of 0.4 / superellipsoid 89 x 233 x 72337",
       SmoothTruncatedCone(0.0038222165553648442, 0.0026662593744640269, 0.39676027860293062, 0.32997038747847879, 10000.0),
       Superellipsoid(88.761516254472596, 233.0083166515733, 72336.612865280447, 1.5), Mat3::Zero(),
       Vec3(0.10139378878833548, -0.0080748171240891346, -0.17208966321799046)},
      {"cone of 4.9e4 / cone of 5.7e-3",
       SmoothTruncatedCone(143.02907027698876, 95.119606693019733, 48763.961757807054, 22933.296674235607, 10000.0),
       SmoothTruncatedCone(0.0022673627753770258, 0.0010288369365728236, 0.005745147303127785, 0.0025156458588308441, 10000.0),
       Mat3::Zero(), Vec3(1357.253081995216, -28.257464959539057, 252.32462458059297)},
      {"box 0.069 x 14.4 x 1.4 / cone 0.034 x 6.4, both at beta = 10^4",
       SmoothPolytope(box_normals,
                      {0.068930494637746906, 0.068930494637746906, 14.439310676678469, 14.439310676678469, 1.3958426782437265,
                       1.3958426782437265},
                      10000.0, 14.439310676678469),
       SmoothTruncatedCone(0.034248341851832322, 0.031781745158333652, 6.3818244018394044, 5.4684498614092591, 10000.0),
       Mat3::Zero(), Vec3(0.020660438283519343, 0.040718842538521656, 0.048948909105099581)},
      {"superellipsoid 0.046 x 20.8 x 27.4, n = 2 / cone 8.4 x 24.8 at beta = 10^4",
       Superellipsoid(0.04631943564430329, 20.750792363627575, 27.393247248297168, 2.0),
       SmoothTruncatedCone(8.3913188714359439, 4.2547901872131169, 24.831181554065484, 9.3341422587490221, 10000.0),
       Mat3::Zero(), Vec3(-426.64627006236844, -1971.039534897413, 10.277084468913891)},
      {"box 962 x 871970 x 3118 / cone of 0.19 at beta = 10^4",
       SmoothPolytope(box_normals,
                      {962.80478925780767, 962.80478925780767, 871970.05323991028, 871970.05323991028, 3117.9414471104838,
                       3117.9414471104838},
                      4868.1538060698758, 871970.05323991028),
       SmoothTruncatedCone(0.18872900768178688, 0.028433356349874948, 0.099716446747985271, 0.046173647720457012, 10000.0),
       Mat3::Zero(), Vec3(-8291.857285601036, 426.91109816832744, -8481.3490376351347)},
  };
  cases[0].R << -0.90173818961945806, 0.36224526259265355, -0.23589533083764519, 0.40801843061077947, 0.53297290688410293,
      -0.74125625852968413, -0.14279074782260637, -0.76466871928743674, -0.62840476770913534;
  cases[1].R << -0.7006767661982698, -0.71149290215579641, -0.053196987620142744, 0.68616363733545016, -0.65154286185949717,
      -0.32352953800004286, 0.19552885236844247, -0.26319146897621631, 0.94472150316885517;
  cases[2].R << 0.82295463314624262, -0.30981241797615977, 0.4761952723945278, -0.035947291472754966, -0.86493173624774866,
      -0.50060052323906767, 0.56696866228999476, 0.39485358970031004, -0.72293649699117668;
  cases[3].R << -0.89905098427057384, 0.40409750649871135, -0.16856017597177636, 0.22654931859422356, 0.099895705735387863,
      -0.96886338263974126, -0.37467683932504453, -0.90924477079450527, -0.18135934730871184;
  cases[4].R << 0.43421753727802448, -0.60185347600944805, -0.670244376131238, 0.36229310651597668, 0.79789804419865951,
      -0.4817700862807458, 0.82474167791570396, -0.033631896754402035, 0.56450868924179587;
  cases[5].R << -0.040096959420045097, -0.88755403503924624, 0.45895541039497495, -0.91605075551438231, 0.2160955500506645,
      0.3378664330320939, -0.3990529377999828, -0.40687903378504692, -0.82170931885877385;
  cases[6].R << 0.87349428909177795, 0.36442896530707947, -0.32279909567602716, 0.11935120103754435, 0.48252154142997372,
      0.8677143843840196, 0.47197777250093587, -0.79647001908499604, 0.37798477610057424;
  for (const Case& c : cases) {
    double alpha[2] = {0.0, 0.0};
    for (int order = 0; order < 2; ++order) {
      const Shape& a = order == 0 ? c.a : c.b;
      const Shape& b = order == 0 ? c.b : c.a;
      const Pose X = order == 0 ? Pose{c.R, c.p} : Pose{c.R, c.p}.inverse();
      const std::string what = std::string(c.what) + (order == 0 ? "" : ", swapped");
      // From the ray guess, as when these poses were found, every start and
      // continuation fails and the barrier path solves them; the test keeps
      // that path covered. The default (the support guess) solves them before
      // the barrier, to the same alpha*.
      SolverOptions ray;
      ray.support_guess = false;
      const SolveResult d = solve(a, b, X);
      ASSERT_EQ(d.status, SolveStatus::Converged) << what << " (support guess): " << to_string(d.status);
      const SolveResult r = solve(a, b, X, ray);
      ASSERT_EQ(r.status, SolveStatus::Converged) << what << ": " << to_string(r.status);
      EXPECT_TRUE(r.used_barrier) << what;
      EXPECT_NEAR(d.alpha, r.alpha, 1e-8 * r.alpha) << what;
      EXPECT_GT(r.lambda1, 0.0) << what;
      EXPECT_GT(r.lambda2, 0.0) << what;
      alpha[order] = r.alpha;
      const Witnesses w = expect_witnesses_on_surfaces(a, b, X, r, what);
      const Vec3 &p1 = w.p1, &p2 = w.p2;
      const Vec3 n1 = w.e1.grad.normalized(), n2 = (X.R * w.e2.grad).normalized();
      // Forming p2 from x in body 1's frame rounds it by a few ulps of |x| +
      // |p|, which alone turns the small rim's normal by ~1e-7 (the solver
      // works in coordinates centred at the small body and does not see
      // this): allow the largest turn of each normal over that rounding box,
      // as the stress scenes' checks do.
      auto spread = [](const Shape& s, const Vec3& y, double delta) {
        ShapeEval e0, e;
        eval(s, y, e0);
        double m = 0.0;
        for (int j = 0; j < 3; ++j)
          for (const double sgn : {-1.0, 1.0}) {
            eval(s, Vec3(y + sgn * delta * Vec3::Unit(j)), e);
            m = std::max(m, (e.grad.normalized() - e0.grad.normalized()).norm());
          }
        return std::sqrt(3.0) * m;
      };
      const double ulps = 4.0 * std::numeric_limits<double>::epsilon() / r.alpha;
      const double allowance = spread(a, p1, ulps * r.x_1.norm()) + spread(b, p2, ulps * (r.x_1.norm() + X.p.norm()));
      EXPECT_LT((n1 + n2).norm(), 1e-7 + allowance) << what;
      EXPECT_LE(r.residual_norm, SolverOptions{}.tolerance) << what;
      for (const Vec3& u : {n1, Vec3(X.p.normalized())}) {
        EXPECT_GE(r.alpha, (1.0 - 1e-12) * support_lower_bound(a, b, X, u)) << what;
      }
    }
    EXPECT_NEAR(alpha[0], alpha[1], 1e-9 * alpha[0]) << c.what;
  }
}

// Needle cones (Rt / Rb = 0.01, 1000:1, beta = 10^4) beside spheres 10^4 to
// 10^5 times their size, from the wide random-body range (seed 11: sphere-cone
// pose 448, cone-sphere pose 1391 and its nearby pose). The cone touches at
// its tip, whose rounding radius (2e-9) is 10^8 times shorter than its
// distance from the cone's origin: one unit in the last place of the witness
// point turns the normal by 7e-8, so no iteration in doubles aligns the
// normals to 1e-8. Every run ended at 1.1-1.5e-8 and the solve at
// line_search_failed, while the same pose with the bodies swapped happened to
// end at 4-9e-9 and converged. Now both orders converge, to the same alpha*,
// from the second tier of rounding-floor candidates (solver_impl.hpp,
// kSharpFloorCeiling). harness/tests/test_random_bodies.cpp checks the same
// poses against the independent geometry and the support-function bracket.
TEST(Solver, NeedleConeTipBesideAHugeSphereConverges) {
  struct Case {
    const char* what;
    Shape a, b;
    Mat3 R;
    Vec3 p;
  };
  const Shape sphere448 = Sphere(27.144324316210341);
  const Shape cone448 =
      SmoothTruncatedCone(0.0014156838538206286, 1.5158395178837327e-05, 0.68798323207487855, 0.099743577675115741, 10000);
  const Shape cone1391 =
      SmoothTruncatedCone(0.0020260163461932722, 4.3101568665168089e-05, 0.98290533903104294, 0.6704712330560979, 10000);
  const Shape sphere1391 = Sphere(247.84328568389884);
  std::vector<Case> cases = {
      {"sphere 27 / cone of 0.79", sphere448, cone448, Mat3::Zero(), Vec3(-1.2834905175651308, 1.0369178880445289, -6.8030717975585588)},
      {"cone of 1.65 / sphere 248", cone1391, sphere1391, Mat3::Zero(), Vec3(1.4136842785669039, 4.2362047239724188, -2.6891740218837357)},
      {"cone of 1.65 / sphere 248, nearby pose", cone1391, sphere1391, Mat3::Zero(),
       Vec3(1.4278211213525729, 4.2785667712121427, -2.716065762102573)},
  };
  cases[0].R << 0.92043948667150044, 0.38899297637197677, -0.038413743753707513, -0.38238400984382809, 0.91644701283128649,
      0.11792939280928663, 0.081077866225376133, -0.093858068411205559, 0.99227871215826124;
  cases[1].R << -0.23641622459000144, 0.9699050027867544, 0.058237911362240657, -0.75075557799513026, -0.22039000787926799,
      0.62273132772984408, 0.61682528390120994, 0.10350135262982041, 0.78026536456771511;
  cases[2].R << -0.21697213604624199, 0.97443903752861583, 0.058237911362240657, -0.75501293819462023, -0.205331820774454,
      0.62273132772984408, 0.61877181201009634, 0.091144969788533411, 0.78026536456771511;
  for (const Case& c : cases) {
    double alpha[2] = {0.0, 0.0};
    for (int order = 0; order < 2; ++order) {
      const Shape& a = order == 0 ? c.a : c.b;
      const Shape& b = order == 0 ? c.b : c.a;
      const Pose X = order == 0 ? Pose{c.R, c.p} : Pose{c.R, c.p}.inverse();
      const std::string what = std::string(c.what) + (order == 0 ? "" : ", swapped");
      const SolveResult r = solve(a, b, X);
      ASSERT_EQ(r.status, SolveStatus::Converged) << what << ": " << to_string(r.status) << ", residual " << r.residual_norm;
      EXPECT_GT(r.lambda1, 0.0) << what;
      EXPECT_GT(r.lambda2, 0.0) << what;
      // At the rounding floor, not at the tolerance, and under the second tier's ceiling.
      EXPECT_LE(r.residual_norm, 1e-6) << what;
      alpha[order] = r.alpha;
      (void)expect_witnesses_on_surfaces(a, b, X, r, what);
      // Above the certified lower bound from the exact supports (along the
      // line of centres), which shares nothing with the iteration.
      EXPECT_GE(r.alpha, (1.0 - 1e-12) * support_lower_bound(a, b, X, X.p.normalized())) << what;
    }
    // alpha* does not depend on the order of the bodies.
    EXPECT_NEAR(alpha[0], alpha[1], 1e-12 * alpha[0]) << c.what;
  }
}

TEST(Solver, ConcentricAndNearConcentric) {
  const Shape a = Superellipsoid(0.5, 1.0, 1.5, 8.0), b = test::paper_poly();
  const SolveResult r = solve(a, b, Pose{});
  EXPECT_EQ(r.status, SolveStatus::Concentric);
  EXPECT_EQ(r.alpha, 0.0);
  EXPECT_TRUE(r.x_1.allFinite());
  // alpha* is proportional to |r| along a fixed direction, down to subnormal |r|.
  const Vec3 u = Vec3(0.3, -0.4, 0.5).normalized();
  const SolveResult ref = solve(a, b, Pose{Mat3::Identity(), u});
  ASSERT_TRUE(ref.converged());
  for (double d : {1e-3, 1e-12, 1e-100, 1e-300}) {
    const SolveResult s = solve(a, b, Pose{Mat3::Identity(), d * u});
    ASSERT_TRUE(s.converged()) << d;
    EXPECT_NEAR(s.alpha / d, ref.alpha, 1e-9 * ref.alpha) << d;
    EXPECT_TRUE(s.x_1.allFinite());
  }
  // A subnormal alpha* (|r| = 4e-320) would carry only ~4 significant digits.
  const SolveResult s = solve(a, b, Pose{Mat3::Identity(), 4e-320 * u});
  EXPECT_EQ(s.status, SolveStatus::NumericalFailure) << to_string(s.status);
  EXPECT_TRUE(s.x_1.allFinite());
}

TEST(Solver, BadPosesAreReportedNotSolved) {
  const Shape a = Sphere(1.0), b = Superellipsoid(1, 2, 3, 2);
  Pose X{Mat3::Identity(), Vec3(1, 2, 3)};
  X.p.x() = NAN;
  EXPECT_EQ(solve(a, b, X).status, SolveStatus::InvalidInput);
  X.p.x() = INFINITY;
  EXPECT_EQ(solve(a, b, X).status, SolveStatus::InvalidInput);
  X.p.x() = 1.0;
  X.R(0, 1) = 0.1;  // not orthonormal
  EXPECT_EQ(solve(a, b, X).status, SolveStatus::InvalidInput);
  X.R = Mat3::Identity();
  X.R(2, 2) = -1.0;  // reflection
  EXPECT_EQ(solve(a, b, X).status, SolveStatus::InvalidInput);
  EXPECT_EQ(check_pose(X), PoseCheck::Reflection);
}

TEST(Solver, BadOptionsAreRejectedAtConstruction) {
  SolverOptions o;
  o.tolerance = -1;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o = SolverOptions{};
  o.surrogate_factor = 0.5;
  try {
    ContactPair p(Sphere(1), Sphere(1), o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("surrogate_factor"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("0.5"), std::string::npos);
  }
  o = SolverOptions{};
  o.max_iterations = 0;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o = SolverOptions{};
  o.backtrack_factor = NAN;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  for (const int order : {-1, 3}) {
    o = SolverOptions{};
    o.warm_predictor_order = order;
    try {
      o.validate();
      ADD_FAILURE() << "warm_predictor_order = " << order << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("warm_predictor_order"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(std::to_string(order)), std::string::npos) << e.what();
    }
  }
}

TEST(Solver, ResultCarriesFactorisedJacobianOnlyWhenAsked) {
  const Shape a = Superellipsoid(0.5, 1, 1.5, 8), b = test::paper_poly();
  const Pose X{Mat3::Identity(), Vec3(0.9, 0.8, -0.4)};
  SolverOptions o;
  o.derivatives = true;
  const SolveResult r = solve(a, b, X, o);
  ASSERT_TRUE(r.converged());
  EXPECT_TRUE(r.internal.factorised);
  EXPECT_GT(r.internal.lu.pivot_ratio(), 1e-8);
  EXPECT_LE(r.residual_norm, SolverOptions{}.tolerance);
  EXPECT_GT(r.iterations, 0);
  // By default the solve keeps no factorisation, and the answer is the same
  // to the last bit: the factorisation is made after the iteration.
  const SolveResult plain = solve(a, b, X);
  ASSERT_TRUE(plain.converged());
  EXPECT_FALSE(plain.internal.factorised);
  EXPECT_EQ(plain.alpha, r.alpha);
  EXPECT_EQ(plain.x_1, r.x_1);
  EXPECT_EQ(plain.iterations, r.iterations);
}

// kSolveStatuses (result.hpp) lists every SolveStatus once, in declaration
// order, and nothing past its end has a name: a value added to the enum but
// not to the list fails here.
TEST(SolveStatusList, ListsEveryNamedValueOnce) {
  ASSERT_GE(kNumSolveStatuses, 7);
  for (int i = 0; i < kNumSolveStatuses; ++i) {
    EXPECT_EQ(static_cast<int>(kSolveStatuses[i]), i);
    EXPECT_STRNE(to_string(kSolveStatuses[i]), "unknown") << i;
  }
  for (int i = kNumSolveStatuses; i < kNumSolveStatuses + 4; ++i)
    EXPECT_STREQ(to_string(static_cast<SolveStatus>(i)), "unknown") << "SolveStatus " << i << " is named but not in kSolveStatuses";
}

// The verdict on a root of the KKT residual (detail::genuine_root): the
// contact only with both multipliers positive and s = log alpha within its
// certified bounds. Newton's fraction-to-boundary rule keeps the multipliers
// positive, so no pose of a sweep has been seen to reach another root (none
// in 3000 random poses of every catalogue pair); the verdict is the safety
// net behind it, and is tested here on the roots it must reject.
TEST(Solver, SpuriousRootsAreNotGenuine) {
  using detail::genuine_root;
  const detail::SBounds B{-1.0, 2.0};
  Vec6 z;
  z << 0.1, -0.2, 0.3, 0.5, 0.7, 1.3;  // a contact: both multipliers positive, s inside
  EXPECT_TRUE(genuine_root(z, B));
  // Two nested spheres touching inside: multipliers of opposite signs.
  Vec6 inner = z;
  inner[5] = -1.3;
  EXPECT_FALSE(genuine_root(inner, B));
  inner = z;
  inner[4] = -0.7;
  EXPECT_FALSE(genuine_root(inner, B));
  Vec6 zero = z;
  zero[4] = 0.0;
  EXPECT_FALSE(genuine_root(zero, B));
  // alpha outside the certified bounds, either side.
  Vec6 out = z;
  out[3] = 2.5;
  EXPECT_FALSE(genuine_root(out, B));
  out[3] = -1.5;
  EXPECT_FALSE(genuine_root(out, B));
  Vec6 nan = z;
  nan[3] = std::nan("");
  EXPECT_FALSE(genuine_root(nan, B));
}

// The Newton run itself refuses a root that is not the contact: started
// exactly on the inner tangency of two nested spheres (multipliers of
// opposite signs, alpha = |r| / (R1 - R2) outside the certified bounds), it
// ends SpuriousRoot at its first residual test; started on the contact
// (alpha = |r| / (R1 + R2)), Converged. The surrogate point is built from the
// closed form in kkt.hpp's coordinates; the multipliers from the two
// gradients there (F2..4 = 0 and F5 = 0 are linear in them).
TEST(Solver, NewtonRunRefusesARootThatIsNotTheContact) {
  const double R1 = 1.0, R2 = 0.5;
  const Sphere S1(R1), S2(R2);
  const SolverOptions o;
  const double fS = o.surrogate_factor, L = R1 + R2;
  const Pose X{Mat3::Identity(), Vec3(0.2, 0.0, 0.0)};
  const Vec3 u(1.0, 0.0, 0.0);
  // In the surrogate, r_S = fS L u; witness points along u at y1 = R1 u and
  // y2 = -+R2 u: alpha_S = |r_S| / (R1 -+ R2).
  for (const bool inner : {true, false}) {
    SCOPED_TRACE(inner ? "inner tangency" : "contact");
    const double aS = fS * L / (inner ? R1 - R2 : R1 + R2);
    const Vec3 y1 = R1 * u, y2 = (inner ? R2 : -R2) * u;
    ShapeEval e1, e2;
    S1.eval(y1, 1.0, e1);
    S2.eval(y2, 1.0, e2);
    // lambda1 g1 + lambda2 g2 = 0 along u, and lambda1 y1.g1 + lambda2 y2.g2 = alpha_S.
    const double g1 = e1.grad.dot(u), g2 = e2.grad.dot(u);
    const double l1 = aS / (y1.dot(e1.grad) - (g1 / g2) * y2.dot(e2.grad)), l2 = -l1 * g1 / g2;
    Vec6 z0;
    z0.head<3>() = (aS / L) * y1 - (fS * R1 / L) * u;  // xi = x_S / L - c1, x_S = alpha_S y1
    z0[3] = std::log(aS);
    z0[4] = l1;
    z0[5] = l2;
    EXPECT_EQ(inner, l2 < 0.0);  // the inner tangency's multipliers have opposite signs
    detail::PairSolver<Sphere, Sphere> ps(S1, S2, o);
    int iters = 0;
    const detail::RunStatus st = ps.newton_run_from(X, z0, iters);
    EXPECT_EQ(iters, 0);  // decided at the start: z0 is a root to rounding
    EXPECT_EQ(st, inner ? detail::RunStatus::SpuriousRoot : detail::RunStatus::Converged);
  }
}

// Every converged answer is a genuine root: positive multipliers (the
// invariant the status Converged promises, result.hpp), on sphere pairs
// whose alpha has a closed form, at poses from far apart to nested.
TEST(Solver, ConvergedAnswersHavePositiveMultipliersAndTheClosedFormAlpha) {
  const Sphere S1(1.0), S2(2.0);
  std::mt19937_64 rng(8);
  for (int t = 0; t < 200; ++t) {
    const Pose X = test::random_pose(rng, 0.01, 10.0);
    const SolveResult r = solve(S1, S2, X);
    ASSERT_TRUE(r.converged()) << t;
    EXPECT_GT(r.lambda1, 0.0) << t;
    EXPECT_GT(r.lambda2, 0.0) << t;
    EXPECT_NEAR(r.alpha, X.p.norm() / 3.0, 1e-12 * (1.0 + X.p.norm())) << t;  // sphere-sphere: |r| / (R1 + R2), never |r| / |R1 - R2|
  }
}

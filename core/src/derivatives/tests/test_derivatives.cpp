// Derivatives of the contact solution, kinematics and wrench against
// (a) central finite differences in the tangent space of SE(3), perturbing
//     poses only through test::se3_exp (never matrix entries), and
// (b) the Perram-Wertheim closed form for two exact ellipsoids, which shares
//     no code with the solver.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>

#include <Eigen/LU>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "fd_values.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

// Finite-difference tolerance. With a solver residual tolerance of 1e-13 the
// solution is accurate to ~cond * 1e-13 ~ 1e-12 (dimensionless), so a
// central difference with step h has rounding error O(1e-12 / h). Its
// truncation error O(h^2 |d^3 z|) is not negligible for the sharp shapes
// (beta = 20, n = 8) at deep penetration, where the scaled bodies are small:
// at h = 1e-5 it was measured at 7e-5 relative, and it vanished at h = 3e-6.
// So every difference here is Richardson-extrapolated,
//   D = (4 D(h/2) - D(h)) / 3,  truncation O(h^4) ~ 1e-20 |d^5 z|,
// and with h = 1e-5 (rad, or units of the pair length L) the error is
// dominated by rounding, ~1e-7. A relative tolerance of 1e-5 (on quantities
// made dimensionless by L) leaves two orders of margin without hiding any
// O(1) or O(h) mistake in a formula.
const double kH = std::getenv("IDCOL_FD_H") ? std::atof(std::getenv("IDCOL_FD_H")) : 1e-5;
constexpr double kTol = 1e-5;

using test::kHertz, test::kN, test::pair_length, test::tight, test::Vals, test::values;
using Jac = Eigen::Matrix<double, kN, 6>;

/// Richardson-extrapolated central differences along body twists (w, v),
/// steps h rad and h L.
bool fd_jacobian(const Shape& a, const Shape& b, const Pose& X, double L, Jac& J) {
  for (int j = 0; j < 6; ++j) {
    Vals d[2];
    for (int k = 0; k < 2; ++k) {
      const double hj = (j < 3 ? kH : kH * L) / (1 + k);
      Vec3 w = Vec3::Zero(), u = Vec3::Zero();
      (j < 3 ? w : u)[j % 3] = hj;
      Vals vp, vm;
      if (!values(a, b, X * test::se3_exp(w, u), vp) || !values(a, b, X * test::se3_exp(-w, -u), vm)) return false;
      d[k] = (vp - vm) / (2.0 * hj);
    }
    J.col(j) = (4.0 * d[1] - d[0]) / 3.0;
  }
  return true;
}

Jac analytic_jacobian(const SolveResult& r) {
  const SolutionSensitivity s = solution_sensitivity(r);
  const ContactKinematicsDerivatives d = contact_kinematics_derivatives(r, s);
  const ContactWrenchDerivatives wd = contact_wrench_derivatives(r, s, kHertz);
  Jac J;
  J << s.dz_dxi, d.dp1_1_dxi, d.dp2_1_dxi, d.dnhat_1_dxi, d.dgap_dxi, wd.dF1_1_dxi, wd.dF2_2_dxi;
  return J;
}

/// Relative error of each block, made dimensionless by L (rows in length
/// divided by L, v columns times L) and relative to max(1, |FD block|).
struct BlockError {
  const char* name;
  int row, rows;
  double length_power;  // rows scale like L^length_power
};
const BlockError kBlocks[] = {{"x", 0, 3, 1}, {"alpha", 3, 1, 0}, {"lambda", 4, 2, 1}, {"p1", 6, 3, 1},
                              {"p2", 9, 3, 1}, {"nhat", 12, 3, 0}, {"gap", 15, 1, 1}, {"F1", 16, 6, 0},
                              {"F2", 22, 6, 0}};

void compare(const Jac& A, const Jac& B, double L, double force_scale, bool with_wrench, const std::string& what) {
  for (const BlockError& blk : kBlocks) {
    if (blk.row >= 16 && !with_wrench) continue;
    Eigen::MatrixXd a = A.middleRows(blk.row, blk.rows), b = B.middleRows(blk.row, blk.rows);
    double s = std::pow(L, -blk.length_power);
    if (blk.row >= 16) s = 1.0 / force_scale;  // wrench: relative to the force magnitude
    a *= s;
    b *= s;
    a.rightCols(3) *= L;
    b.rightCols(3) *= L;
    const double err = (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
    EXPECT_LT(err, kTol) << what << " block " << blk.name << "\nIFT\n" << a << "\nFD\n" << b;
  }
}

/// Poses of three kinds from a random one: solve it, then scale r so that
/// alpha* becomes `target` (alpha* is linear in r at fixed R).
Pose with_alpha(const Shape& a, const Shape& b, const Pose& X, double target) {
  const SolveResult r = solve(a, b, X, tight());
  if (!r.converged()) return X;
  return Pose{X.R, X.p * (target / r.alpha)};
}

}  // namespace

// The stored LU factorises J_int = D_r J_c D_c^{-1}. Build the paper's J_c
// (eq:kkt_jacobian, in (x, s = log alpha, lambda1, lambda2)) here from the
// shape evaluations and check that solving with the stored LU through the
// scalings gives J_c^{-1} b.
TEST(Derivatives, StoredFactorisationMapsToPaperJacobian) {
  const auto cat = test::catalogue();
  std::mt19937_64 rng(31);
  for (const auto& A : cat)
    for (const auto& B : cat)
      for (int t = 0; t < 5; ++t) {
        const Pose X = test::random_pose(rng, 0.3, 6.0);
        const SolveResult r = solve(A.shape, B.shape, X, tight());
        ASSERT_TRUE(r.converged());
        const double a = r.alpha, l1 = r.lambda1, l2 = r.lambda2;
        const Vec3 y1 = r.x_1 / a, y2 = X.R.transpose() * (r.x_1 - X.p) / a;
        ShapeEval e1, e2;
        eval(A.shape, y1, e1);
        eval(B.shape, y2, e2);
        // eq:phi_partials, then d/ds = alpha d/dalpha.
        const Vec3 p1x = e1.grad / a, p2x = X.R * e2.grad / a;
        const double p1s = -y1.dot(e1.grad), p2s = -y2.dot(e2.grad);
        const Mat3 p1xx = e1.hess / (a * a), p2xx = X.R * e2.hess * X.R.transpose() / (a * a);
        const Vec3 p1xs = -(e1.grad + e1.hess * y1) / a, p2xs = -X.R * (e2.grad + e2.hess * y2) / a;
        const double p1ss = 2 * y1.dot(e1.grad) + y1.dot(e1.hess * y1) - y1.dot(e1.grad);
        const double p2ss = 2 * y2.dot(e2.grad) + y2.dot(e2.hess * y2) - y2.dot(e2.grad);
        // Residual f = (phi1, phi2, l1 phi1x + l2 phi2x, 1 + l1 phi1a + l2 phi2a);
        // with s: phi_a = phi_s / alpha, so the last row is 1 + (l1 phi1s + l2 phi2s)/alpha.
        Mat6 Jc = Mat6::Zero();
        Jc.block<1, 3>(0, 0) = p1x.transpose();
        Jc(0, 3) = p1s;
        Jc.block<1, 3>(1, 0) = p2x.transpose();
        Jc(1, 3) = p2s;
        Jc.block<3, 3>(2, 0) = l1 * p1xx + l2 * p2xx;
        Jc.block<3, 1>(2, 3) = l1 * p1xs + l2 * p2xs;
        Jc.block<3, 1>(2, 4) = p1x;
        Jc.block<3, 1>(2, 5) = p2x;
        const double ls = l1 * p1s + l2 * p2s;
        Jc.block<1, 3>(5, 0) = (l1 * p1xs + l2 * p2xs).transpose() / a;
        Jc(5, 3) = (l1 * p1ss + l2 * p2ss) / a - ls / a;
        Jc(5, 4) = p1s / a;
        Jc(5, 5) = p2s / a;
        const SolveResult::Internal& in = r.internal;
        Vec6 Dc_inv;
        Dc_inv << Vec3::Constant(in.k * in.length), 1.0, in.k, in.k;
        for (int j = 0; j < 6; ++j) {
          const Vec6 b = Vec6::Unit(j);
          const Vec6 ref = Jc.fullPivLu().solve(b);
          const Vec6 got = Dc_inv.cwiseProduct(in.lu.solve(in.row_scale.cwiseProduct(b)));
          EXPECT_LT((got - ref).norm(), 1e-8 * ref.norm()) << A.name << "-" << B.name << " col " << j;
        }
      }
}

// T_c, witness points, gap, normal and both wrenches against central
// differences, for every catalogue pair at separated, touching and
// penetrating poses.
TEST(Derivatives, AgreeWithFiniteDifferencesForEveryPair) {
  const auto cat = test::catalogue();
  std::mt19937_64 rng(7);
  int checked = 0, skipped = 0;
  for (const auto& A : cat)
    for (const auto& B : cat) {
      const double L = pair_length(A.shape, B.shape);
      for (double target : {2.0, 1.3, 1.0 + 1e-9, 1.0, 0.95, 0.6}) {
        for (int t = 0; t < 2; ++t) {
          const Pose X = with_alpha(A.shape, B.shape, test::random_pose(rng, 0.3, 6.0), target);
          const SolveResult r = solve(A.shape, B.shape, X, tight());
          ASSERT_TRUE(r.converged()) << A.name << "-" << B.name;
          if (!conditioning(r).reliable) {
            ++skipped;
            continue;
          }
          Jac fd;
          ASSERT_TRUE(fd_jacobian(A.shape, B.shape, X, L, fd));
          const ContactWrench w = contact_wrench(r, kHertz);
          const double fscale = std::max(w.f_n, kHertz.stiffness * std::pow(1e-3 * L, kHertz.exponent));
          // f_n = k delta^1.5 is not C^2 at delta = 0: central differences
          // straddling it are meaningless, so the wrench is compared only
          // when the poses stay on one side of contact (|gap| >> h L).
          const bool with_wrench = std::abs(contact_kinematics(r).gap) > 1e3 * kH * L;
          compare(analytic_jacobian(r), fd, L, fscale, with_wrench,
                  A.name + "-" + B.name + " alpha=" + std::to_string(r.alpha));
          ++checked;
        }
      }
    }
  EXPECT_GE(checked, 1150);
  EXPECT_LE(skipped, 10);
}

TEST(Derivatives, CheapGradientsMatchTheFullSensitivity) {
  const auto cat = test::catalogue();
  std::mt19937_64 rng(11);
  for (const auto& A : cat)
    for (const auto& B : cat)
      for (int t = 0; t < 4; ++t) {
        const Pose X = test::random_pose(rng, 0.2, 8.0);
        const SolveResult r = solve(A.shape, B.shape, X, test::with_derivatives());
        ASSERT_TRUE(r.converged());
        const SolutionSensitivity s = solution_sensitivity(r);
        const ContactKinematicsDerivatives d = contact_kinematics_derivatives(r, s);
        const double sa = s.dalpha_dxi().norm(), sg = d.dgap_dxi.norm();
        EXPECT_LT((alpha_gradient(r) - s.dalpha_dxi()).norm(), 1e-10 * sa) << A.name << "-" << B.name;
        EXPECT_LT((gap_gradient(r) - d.dgap_dxi).norm(), 1e-10 * sg) << A.name << "-" << B.name;
        // dz/dq = T_c J for a fixed-size user Jacobian.
        Eigen::Matrix<double, 6, 2> J = Eigen::Matrix<double, 6, 2>::Random();
        EXPECT_LT((map_through_jacobian(s.dz_dxi, J) - s.dz_dxi * J).norm(), 1e-14 * (1 + (s.dz_dxi * J).norm()));
      }
}

// World-pose inputs: perturb X_W1 and X_W2 by their own body twists, re-solve
// at X_W1^{-1} X_W2, and compare with world_pose_sensitivity and the world
// contact kinematics.
TEST(Derivatives, WorldPoseDerivativesAgreeWithFiniteDifferences) {
  const auto cat = test::catalogue();
  int poses = 0, unreliable = 0;
  std::mt19937_64 rng(5);
  for (const auto& A : cat)
    for (const auto& B : cat)
      for (int t = 0; t < 2; ++t) {
        const double L = pair_length(A.shape, B.shape);
        const Pose X_W1 = test::random_pose(rng, 0.5, 3.0);
        Pose X_12 = test::random_pose(rng, 0.3, 6.0);
        X_12 = with_alpha(A.shape, B.shape, X_12, t == 0 ? 1.4 : 0.8);
        const Pose X_W2 = X_W1 * X_12;
        const SolveResult r = solve_world(A.shape, X_W1, B.shape, X_W2, tight());
        ASSERT_TRUE(r.converged());
        ++poses;
        if (!conditioning(r).reliable) {
          ++unreliable;
          continue;
        }
        const SolutionSensitivity s = solution_sensitivity(r);
        const Pose X_12r = X_W1.inverse() * X_W2;
        const Mat6x12 dz = world_pose_sensitivity(s, X_12r);
        const ContactKinematicsDerivatives d = contact_kinematics_derivatives(r, s);
        const ContactKinematicsWorld cw = contact_kinematics_world(contact_kinematics(r), &d, X_W1, X_12r);
        ASSERT_TRUE(cw.has_derivatives);
        // Values: x(3), alpha, p1_W, p2_W, nhat_W, gap = 14 rows.
        using V = Eigen::Matrix<double, 14, 1>;
        auto val = [&](const Pose& P1, const Pose& P2, V& v) {
          const SolveResult q = solve_world(A.shape, P1, B.shape, P2, tight());
          if (!q.converged()) return false;
          const ContactKinematicsWorld c = contact_kinematics_world(contact_kinematics(q), nullptr, P1, P1.inverse() * P2);
          v << q.x_1, q.alpha, c.p1_W, c.p2_W, c.nhat_W, c.gap;
          return true;
        };
        Eigen::Matrix<double, 14, 12> fd, an;
        an << dz.topRows<4>(), cw.dp1_W, cw.dp2_W, cw.dnhat_W, cw.dgap;
        for (int j = 0; j < 12; ++j) {
          const int k = j % 6;
          Eigen::Matrix<double, 14, 1> d[2];
          for (int m = 0; m < 2; ++m) {
            const double hj = (k < 3 ? kH : kH * L) / (1 + m);
            Vec3 w = Vec3::Zero(), u = Vec3::Zero();
            (k < 3 ? w : u)[k % 3] = hj;
            V vp, vm;
            const bool first = j < 6;
            ASSERT_TRUE(val(first ? X_W1 * test::se3_exp(w, u) : X_W1, first ? X_W2 : X_W2 * test::se3_exp(w, u), vp));
            ASSERT_TRUE(
                val(first ? X_W1 * test::se3_exp(-w, -u) : X_W1, first ? X_W2 : X_W2 * test::se3_exp(-w, -u), vm));
            d[m] = (vp - vm) / (2.0 * hj);
          }
          fd.col(j) = (4.0 * d[1] - d[0]) / 3.0;  // Richardson, see kTol
        }
        // Dimensionless: lengths / L, v columns * L.
        Eigen::Matrix<double, 14, 1> rs;
        rs << Vec3::Constant(1 / L), 1.0, Vec3::Constant(1 / L), Vec3::Constant(1 / L), Vec3::Ones(), 1 / L;
        Eigen::Matrix<double, 1, 12> cs;
        cs << 1, 1, 1, L, L, L, 1, 1, 1, L, L, L;
        const Eigen::Matrix<double, 14, 12> a = rs.asDiagonal() * an * cs.asDiagonal();
        const Eigen::Matrix<double, 14, 12> b = rs.asDiagonal() * fd * cs.asDiagonal();
        const double err = (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
        EXPECT_LT(err, kTol) << A.name << "-" << B.name << "\nIFT\n" << a << "\nFD\n" << b;
      }
  // Poses flagged unreliable are skipped; bound them so the test cannot pass vacuously.
  EXPECT_EQ(poses, 2 * static_cast<int>(cat.size() * cat.size()));
  EXPECT_LE(unreliable, poses / 20) << unreliable << " of " << poses << " poses skipped as unreliable";
}

// ---------------------------------------------------------------------------
// Perram-Wertheim oracle for two exact ellipsoids (test-only; no solver code):
//   alpha*^2 = max_{lambda in [0,1]} lambda (1 - lambda) r^T M(lambda)^{-1} r,
//   M(lambda) = (1 - lambda) S1 + lambda S2, S_i = R_i diag(axes_i^2) R_i^T,
// and by the envelope theorem d(alpha*^2)/dr = 2 lambda*(1-lambda*) M^{-1} r.
namespace {
struct PwResult {
  double alpha;
  Vec3 dalpha_dr;
};

PwResult perram_wertheim(const Mat3& S1, const Mat3& S2, const Vec3& r) {
  // f(lambda) is concave on [0, 1]: bisect on the sign of f'.
  auto dfdl = [&](double l) {
    const Mat3 M = (1 - l) * S1 + l * S2;
    const Vec3 u = M.inverse() * r;
    return (1 - 2 * l) * r.dot(u) - l * (1 - l) * u.dot((S2 - S1) * u);
  };
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    (dfdl(mid) > 0 ? lo : hi) = mid;
  }
  const double l = 0.5 * (lo + hi);
  const Vec3 u = ((1 - l) * S1 + l * S2).inverse() * r;
  const double a2 = l * (1 - l) * r.dot(u);
  PwResult out;
  out.alpha = std::sqrt(a2);
  out.dalpha_dr = (2 * l * (1 - l) * u) / (2 * out.alpha);
  return out;
}
}  // namespace

TEST(Derivatives, AlphaAndItsGradientMatchPerramWertheim) {
  const Vec3 ax1(0.5, 1.0, 1.5), ax2(1.2, 0.7, 0.9);
  const Superellipsoid E1(ax1.x(), ax1.y(), ax1.z(), 1.0), E2(ax2.x(), ax2.y(), ax2.z(), 1.0);
  const Mat3 S1 = ax1.cwiseAbs2().asDiagonal();
  std::mt19937_64 rng(2024);
  double worst_a = 0, worst_g = 0;
  for (int t = 0; t < 300; ++t) {
    Pose X = test::random_pose(rng, 0.2, 10.0);
    const Mat3 S2 = X.R * ax2.cwiseAbs2().asDiagonal() * X.R.transpose();
    const SolveResult r = solve(E1, E2, X, tight());
    ASSERT_TRUE(r.converged());
    const PwResult pw = perram_wertheim(S1, S2, X.p);
    // The twist's v moves r by R v (body-frame twist), so d alpha/dv = (d alpha/dr)^T R.
    const Vec3 ref = X.R.transpose() * pw.dalpha_dr;
    const Row6 g = alpha_gradient(r);
    const Row6 gs = solution_sensitivity(r).dalpha_dxi();
    const double ea = std::abs(r.alpha - pw.alpha) / pw.alpha;
    const double eg = (g.tail<3>().transpose() - ref).norm() / ref.norm();
    const double egs = (gs.tail<3>().transpose() - ref).norm() / ref.norm();
    worst_a = std::max(worst_a, ea);
    worst_g = std::max({worst_g, eg, egs});
    EXPECT_LT(ea, 1e-12) << t;
    EXPECT_LT(eg, 1e-9) << t;
    EXPECT_LT(egs, 1e-9) << t;
  }
  RecordProperty("worst_alpha_rel", std::to_string(worst_a));
  RecordProperty("worst_grad_rel", std::to_string(worst_g));
}

// Sign conventions of the wrench: equal and opposite, force along -nhat on
// body 1, and both wrenches transported to the world sum to zero.
TEST(Derivatives, WrenchIsEqualAndOpposite) {
  const auto cat = test::catalogue();
  std::mt19937_64 rng(3);
  for (const auto& A : cat)
    for (const auto& B : cat) {
      const Pose X = with_alpha(A.shape, B.shape, test::random_pose(rng, 0.3, 6.0), 0.8);
      const SolveResult r = solve(A.shape, B.shape, X, tight());
      ASSERT_TRUE(r.converged());
      const ContactWrench w = contact_wrench(r, HertzModel{2.0, 1.0});
      ASSERT_TRUE(w.active);
      const ContactKinematics c = contact_kinematics(r);
      EXPECT_NEAR(w.f_n, 2.0 * (-c.gap), 1e-12 * (1 + w.f_n));
      EXPECT_LT((w.F1_1.tail<3>() + w.f_n * c.nhat_1).norm(), 1e-12 * (1 + w.f_n));
      // Body 2's wrench back in frame 1 (moment about frame-1 origin).
      const Vec3 f2_1 = X.R * w.F2_2.tail<3>();
      const Vec3 m2_1 = X.R * w.F2_2.head<3>() + X.p.cross(f2_1);
      EXPECT_LT((f2_1 + w.F1_1.tail<3>()).norm(), 1e-12 * (1 + w.f_n));
      EXPECT_LT((m2_1 + w.F1_1.head<3>()).norm(), 1e-10 * (1 + w.F1_1.norm()));
      // Separated: no force.
      const Pose Xs = with_alpha(A.shape, B.shape, X, 1.5);
      EXPECT_FALSE(contact_wrench(solve(A.shape, B.shape, Xs), HertzModel{}).active);
    }
}

TEST(Derivatives, InvalidHertzModelIsRejected) {
  EXPECT_THROW((HertzModel{0.0, 1.5}.validate()), std::invalid_argument);
  EXPECT_THROW((HertzModel{1.0, 0.5}.validate()), std::invalid_argument);
  EXPECT_NO_THROW((HertzModel{1.0, 1.0}.validate()));
}

// A caller who wants alpha* alone solves without the factorisation; asking
// a derivative of such a result is a usage error with a message that names
// the fix, never a silent zero. The values need no factorisation.
TEST(Derivatives, ResultWithoutFactorisationIsRejectedNamingTheOption) {
  const SolveResult r = solve(Superellipsoid(0.5, 1, 1.5, 1), Sphere(0.7), Pose{Mat3::Identity(), Vec3(1.0, 0.5, -0.3)});
  ASSERT_TRUE(r.converged());
  ASSERT_FALSE(r.internal.factorised);
  for (const auto& [name, call] : std::vector<std::pair<std::string, std::function<void()>>>{
           {"solution_sensitivity", [&] { (void)solution_sensitivity(r); }},
           {"alpha_gradient", [&] { (void)alpha_gradient(r); }},
           {"gap_gradient", [&] { (void)gap_gradient(r); }},
           {"conditioning", [&] { (void)conditioning(r); }}}) {
    try {
      call();
      ADD_FAILURE() << name << " accepted a result without factorisation";
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(name), std::string::npos) << msg;
      EXPECT_NE(msg.find("SolverOptions::derivatives"), std::string::npos) << msg;
    }
  }
  EXPECT_TRUE(contact_kinematics(r).valid);
  EXPECT_TRUE(contact_wrench(r, HertzModel{}).valid);
}

TEST(Derivatives, NotConvergedGivesNoDerivatives) {
  SolveResult r;  // InvalidInput
  EXPECT_FALSE(solution_sensitivity(r).valid);
  EXPECT_FALSE(conditioning(r).reliable);
  EXPECT_FALSE(contact_kinematics(r).valid);
  EXPECT_EQ(alpha_gradient(r), Row6::Zero());
}

// A small sweep through the library's check: every pose agrees, or is
// flagged by the conditioning estimate. The 10^4-pose figures come from
// idcol_check_derivatives (examples/check_derivatives.cpp).
TEST(Derivatives, SweepCheckOverPaperShapes) {
  const auto shapes = test::paper_shapes();
  std::mt19937_64 rng(99);
  for (const auto& A : shapes)
    for (const auto& B : shapes) {
      std::vector<Pose> poses;
      for (int i = 0; i < 100; ++i) poses.push_back(test::random_pose(rng, 0.2, 8.0));
      const DerivativeCheckReport rep = check_derivatives(A.shape, B.shape, poses);
      EXPECT_EQ(rep.converged, 100) << A.name << "-" << B.name;
      EXPECT_EQ(rep.disagree_unflagged, 0) << A.name << "-" << B.name << " worst " << rep.worst_error
                                           << (rep.failures.empty() ? "" : "\n" + rep.failures.front());
      // The verdict and the error agree: every unflagged pose agreeing means
      // the worst unflagged error is within the tolerance (a checker that
      // says "agree" whatever the error fails here).
      EXPECT_LE(rep.worst_error, DerivativeCheckOptions{}.tolerance) << A.name << "-" << B.name;
      EXPECT_EQ(rep.agree + rep.disagree_flagged + rep.disagree_unflagged, rep.converged - rep.fd_failed) << A.name << "-" << B.name;
    }
}

// The checker can say "disagree": asked for an agreement finite differences
// cannot reach (1e-15), every pose disagrees; and the error it measures on
// two ellipsoids sits in a two-sided band (above rounding, far below the
// 1e-3 of a derivative off by 0.1%).
TEST(Derivatives, CheckerSaysDisagreeWhereTheErrorExceedsTheTolerance) {
  const Superellipsoid E1(0.5, 1.0, 1.5, 1.0), E2(1.2, 0.7, 0.9, 1.0);
  std::mt19937_64 rng(4);
  std::vector<Pose> poses;
  for (int i = 0; i < 20; ++i) poses.push_back(test::random_pose(rng, 0.3, 6.0));
  const DerivativeCheckReport ok = check_derivatives(E1, E2, poses);
  ASSERT_EQ(ok.converged, 20);
  EXPECT_EQ(ok.disagree_unflagged, 0) << ok.worst_error;
  EXPECT_LT(ok.worst_error, 1e-6);
  EXPECT_GT(ok.worst_error, 1e-14);
  DerivativeCheckOptions strict;
  strict.tolerance = 1e-15;
  const DerivativeCheckReport no = check_derivatives(E1, E2, poses, strict);
  EXPECT_EQ(no.agree, 0);
  EXPECT_EQ(no.disagree_flagged + no.disagree_unflagged, no.converged - no.fd_failed);
  EXPECT_EQ(no.failures.size(), static_cast<std::size_t>(no.disagree_flagged + no.disagree_unflagged));
  EXPECT_EQ(no.agreement(), 0.0);
}

// The stiff integrator (stiff_ode.hpp) against closed forms and a
// published reference solution:
//  - a linear system y' = A y with eigenvalues -1, -100, -10^4, whose
//    solution is V exp(Lambda t) V^{-1} y0;
//  - the Prothero-Robinson problem y' = lambda (y - sin t) + cos t,
//    lambda = -10^6, solution sin t;
//  - Robertson's chemical kinetics to t = 40, against the reference values
//    of Hairer and Wanner (Solving ODEs II, Sec. IV.1), and its linear
//    invariant y1 + y2 + y3 = 1, which a linear multistep method keeps to
//    the rounding of its Newton iterations.
// The step counts show that the stiffness is handled: an explicit method
// would need about 10^4 |lambda| t steps for stability alone.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "idcol/stiff_ode.hpp"

using namespace idcol;

namespace {

using V = Eigen::VectorXd;
using M = Eigen::MatrixXd;

struct Linear {
  M A, Vm, Vinv;
  Eigen::Vector3d lambda{-1.0, -100.0, -1e4};
  Linear() {
    Vm.resize(3, 3);
    Vm << 1.0, 0.2, -0.3, 0.1, 1.0, 0.4, -0.2, 0.3, 1.0;
    Vinv = Vm.inverse();
    A = Vm * lambda.asDiagonal() * Vinv;
  }
  V exact(double t, const V& y0) const {
    const Eigen::Vector3d e(std::exp(lambda[0] * t), std::exp(lambda[1] * t), std::exp(lambda[2] * t));
    return Vm * e.asDiagonal() * Vinv * y0;
  }
};

class LinearStiff : public ::testing::TestWithParam<bool> {};  // analytic Jacobian or differences

TEST_P(LinearStiff, MatchesTheClosedFormWithFewSteps) {
  const Linear L;
  const V y0 = (V(3) << 1.0, -2.0, 0.5).finished();
  StiffOdeSolver::Jacobian jac;
  if (GetParam()) jac = [&](double, const V&, M& J) { J = L.A; return true; };
  for (double rtol : {1e-4, 1e-6, 1e-8}) {
    StiffOdeOptions o;
    o.rtol = rtol;
    o.atol = rtol * 1e-2;
    StiffOdeSolver ode([&](double, const V& y, V& f) { f = L.A * y; return true; }, jac, o);
    V y = y0;
    double worst = 0.0;
    const std::vector<double> outs = {0.01, 0.1, 0.5, 1.0, 2.0, 5.0};
    ASSERT_EQ(ode.integrate(0.0, 5.0, y, outs,
                            [&](double t, const V& yt) {
                              worst = std::max(worst, (yt - L.exact(t, y0)).cwiseAbs().maxCoeff());
                            }),
              StiffOdeStatus::Success);
    worst = std::max(worst, (y - L.exact(5.0, y0)).cwiseAbs().maxCoeff());
    // The global error stays within a small multiple of the tolerance (|y0| ~ 2).
    EXPECT_LT(worst, 50.0 * rtol) << "rtol " << rtol;
    // Stability alone would cost an explicit method ~5 * 10^4 steps.
    EXPECT_LT(ode.stats().steps, rtol >= 1e-6 ? 400 : 1500) << "rtol " << rtol;
    EXPECT_GE(ode.stats().max_order_used, 3) << "rtol " << rtol;
  }
}

INSTANTIATE_TEST_SUITE_P(Jacobian, LinearStiff, ::testing::Values(true, false),
                         [](const auto& info) { return std::string(info.param ? "Analytic" : "FiniteDifferences"); });

TEST(StiffOde, ProtheroRobinsonFollowsTheSmoothSolution) {
  const double lambda = -1e6;
  auto f = [&](double t, const V& y, V& out) {
    out.resize(1);
    out[0] = lambda * (y[0] - std::sin(t)) + std::cos(t);
    return true;
  };
  auto jac = [&](double, const V&, M& J) {
    J.resize(1, 1);
    J(0, 0) = lambda;
    return true;
  };
  StiffOdeOptions o;
  o.rtol = 1e-7;
  o.atol = 1e-9;
  StiffOdeSolver ode(f, jac, o);
  V y = V::Zero(1);
  double worst = 0.0;
  std::vector<double> outs;
  for (int k = 1; k <= 100; ++k) outs.push_back(0.1 * k);
  ASSERT_EQ(ode.integrate(0.0, 10.0, y, outs, [&](double t, const V& yt) { worst = std::max(worst, std::abs(yt[0] - std::sin(t))); }),
            StiffOdeStatus::Success);
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(ode.stats().steps, 2000);  // explicit: ~10^7
}

TEST(StiffOde, RobertsonMatchesTheReferenceAndKeepsItsInvariant) {
  auto f = [](double, const V& y, V& out) {
    out.resize(3);
    out[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
    out[2] = 3e7 * y[1] * y[1];
    out[1] = -out[0] - out[2];
    return true;
  };
  auto jac = [](double, const V& y, M& J) {
    J.resize(3, 3);
    J << -0.04, 1e4 * y[2], 1e4 * y[1],  //
        0.04, -1e4 * y[2] - 6e7 * y[1], -1e4 * y[1],  //
        0.0, 6e7 * y[1], 0.0;
    return true;
  };
  StiffOdeOptions o;
  o.rtol = 1e-8;
  o.atol = 1e-14;
  StiffOdeSolver ode(f, jac, o);
  V y = (V(3) << 1.0, 0.0, 0.0).finished();
  double invariant = 0.0;
  ASSERT_EQ(ode.integrate(0.0, 40.0, y, {}, {}, [&](double, const V& yt) { invariant = std::max(invariant, std::abs(yt.sum() - 1.0)); }),
            StiffOdeStatus::Success);
  // Hairer and Wanner, Solving ODEs II, Sec. IV.1: y(40).
  EXPECT_NEAR(y[0], 0.7158270687193772, 1e-6);
  EXPECT_NEAR(y[1] / 9.185534764557e-06, 1.0, 1e-5);
  EXPECT_NEAR(y[2], 0.2841637457458577, 1e-6);
  EXPECT_LT(invariant, 1e-13);
  EXPECT_LT(ode.stats().steps, 1000);
}

TEST(StiffOde, ARightHandSideThatFailsShrinksTheStep) {
  // f refuses t > 0.5 once: the step that reaches past it is retried smaller.
  int refusals = 0;
  auto f = [&](double t, const V& y, V& out) {
    out = -y;
    if (t > 0.5 && refusals < 3) {
      ++refusals;
      return false;
    }
    return true;
  };
  StiffOdeSolver ode(f, {}, StiffOdeOptions{});
  V y = V::Ones(2);
  ASSERT_EQ(ode.integrate(0.0, 2.0, y), StiffOdeStatus::Success);
  EXPECT_EQ(ode.stats().function_failures, 3);
  EXPECT_NEAR(y[0], std::exp(-2.0), 1e-4);
}

TEST(StiffOde, BadInputIsRejectedByName) {
  auto f = [](double, const V& y, V& out) { out = -y; return true; };
  StiffOdeOptions o;
  o.rtol = 0.0;
  try {
    StiffOdeSolver(f, {}, o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'rtol'"), std::string::npos) << e.what();
  }
  o = StiffOdeOptions{};
  o.max_order = 6;
  EXPECT_THROW(StiffOdeSolver(f, {}, o), std::invalid_argument);
  StiffOdeSolver ode(f, {}, StiffOdeOptions{});
  V y = V::Ones(1);
  EXPECT_THROW(ode.integrate(1.0, 1.0, y), std::invalid_argument);
  EXPECT_THROW(ode.integrate(0.0, 1.0, y, {0.5, 0.4}), std::invalid_argument);
  y[0] = NAN;
  EXPECT_THROW(ode.integrate(0.0, 1.0, y), std::invalid_argument);
}

}  // namespace

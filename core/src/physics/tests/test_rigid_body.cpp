// The rigid-body layer (rigid_body.hpp): the SO(3) chart's Jacobians and
// mass properties against closed forms and finite differences, the
// equations of motion's Jacobian against central differences of the
// right-hand side, and the conservation of momentum through a collision.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/multibody_scenes.hpp"
#include "idcol/rigid_body.hpp"
#include "idcol/stiff_ode.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// The rotation vector of R (|theta| <= pi), by Eigen's angle-axis (an
/// independent logarithm).
Vec3 so3_log(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

std::vector<Vec3> test_thetas() {
  std::vector<Vec3> out;
  const Vec3 dir = Vec3(0.3, -0.5, 0.81).normalized();
  for (double t : {0.0, 1e-5, 1e-3, 0.05, 0.19, 0.21, 0.7, 1.5, 2.6, 3.1}) out.push_back(t * dir);
  return out;
}

TEST(So3, ExpIsEigensAngleAxis) {
  for (const Vec3& th : test_thetas()) {
    const double t = th.norm();
    const Mat3 want = t > 0 ? Eigen::AngleAxisd(t, th / t).toRotationMatrix() : Mat3::Identity();
    EXPECT_LT((so3_exp(th) - want).norm(), 1e-15) << th.transpose();
  }
}

TEST(So3, RightJacobianAgainstDifferencesOfTheExponential) {
  // exp((theta + eps e_k)~) = exp(theta~) exp((eps J_r e_k)~) + O(eps^2).
  const double h = 1e-6;
  for (const Vec3& th : test_thetas()) {
    Mat3 fd;
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = Vec3::Unit(k);
      const Mat3 R0 = so3_exp(th).transpose();
      fd.col(k) = (so3_log(R0 * so3_exp(th + h * e)) - so3_log(R0 * so3_exp(th - h * e))) / (2 * h);
    }
    EXPECT_LT((so3_right_jacobian(th) - fd).norm(), 1e-8) << th.transpose();
    EXPECT_LT((so3_right_jacobian_inverse(th) * so3_right_jacobian(th) - Mat3::Identity()).norm(), 1e-13)
        << th.transpose();
  }
}

TEST(So3, DerivativeOfTheInverseRightJacobianAgainstDifferences) {
  const Vec3 w(0.7, -1.3, 0.4);
  const double h = 1e-6;
  for (const Vec3& th : test_thetas()) {
    Mat3 fd;
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = Vec3::Unit(k);
      fd.col(k) = (so3_right_jacobian_inverse(th + h * e) * w - so3_right_jacobian_inverse(th - h * e) * w) / (2 * h);
    }
    EXPECT_LT((so3_right_jacobian_inverse_derivative(th, w) - fd).norm(), 1e-8) << th.transpose();
  }
}

TEST(MassProperties, SphereAndEllipsoidAgainstClosedForms) {
  const MassProperties s = mass_properties(Sphere(0.5), 2.0, 64);
  const double m = 2.0 * 4.0 / 3.0 * kPi * 0.125;
  EXPECT_NEAR(s.mass / m, 1.0, 3e-3);
  EXPECT_LT(s.com_B.norm(), 1e-12);
  EXPECT_NEAR(s.inertia_com_B(0, 0) / (0.4 * m * 0.25), 1.0, 6e-3);
  const double a = 0.8, b = 0.5, c = 0.4;
  const MassProperties e = mass_properties(Superellipsoid(a, b, c, 1.0), 1.0, 64);
  const double me = 4.0 / 3.0 * kPi * a * b * c;
  EXPECT_NEAR(e.mass / me, 1.0, 5e-3);
  EXPECT_NEAR(e.inertia_com_B(0, 0) / (me * (b * b + c * c) / 5), 1.0, 1e-2);
  EXPECT_NEAR(e.inertia_com_B(1, 1) / (me * (a * a + c * c) / 5), 1.0, 1e-2);
  EXPECT_NEAR(e.inertia_com_B(2, 2) / (me * (a * a + b * b) / 5), 1.0, 1e-2);
  EXPECT_LT(std::abs(e.inertia_com_B(0, 1)), 1e-3 * e.inertia_com_B(0, 0));
}

TEST(MassProperties, BadInputIsRejectedByName) {
  MassProperties p;
  p.mass = -1.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = MassProperties{};
  p.inertia_com_B(0, 0) = -1.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  EXPECT_THROW(mass_properties(Sphere(1.0), 0.0), std::invalid_argument);
  EXPECT_THROW(MultibodySystem({Sphere(1.0)}, {}), std::invalid_argument);
}

/// Three bodies pressed into each other, spinning and moving: every
/// contact active, every block of the Jacobian exercised.
struct Pile {
  std::vector<Shape> shapes{Sphere(0.6), test::box(0.5, 0.4, 0.3, 20.0), Superellipsoid(0.7, 0.5, 0.4, 1.0)};
  std::vector<MassProperties> masses;
  std::vector<Pose> X;
  std::vector<Vec6> eta;
  Pile() {
    std::mt19937_64 rng(5);
    for (const Shape& s : shapes) masses.push_back(mass_properties(s, 1.0, 32));
    masses[1].com_B = Vec3(0.05, -0.03, 0.02);  // a frame origin off the centre of mass
    X = {Pose{test::random_rotation(rng), Vec3(0.0, 0.0, 0.0)}, Pose{test::random_rotation(rng), Vec3(0.9, 0.1, 0.0)},
         Pose{test::random_rotation(rng), Vec3(-0.2, 1.0, 0.1)}};
    for (int i = 0; i < 3; ++i) {
      Vec6 e;
      for (int k = 0; k < 6; ++k) e[k] = std::normal_distribution<double>(0.0, 1.0)(rng);
      eta.push_back(e);
    }
  }
  SceneOptions options(double tolerance = 1e-13) const {
    SceneOptions o;
    o.solver.tolerance = tolerance;
    o.contact.stiffness = 1e3;
    return o;
  }
};

TEST(MultibodySystem, JacobianAgainstCentralDifferencesOfTheRightHandSide) {
  const Pile p;
  MultibodySystem sys(p.shapes, p.masses, p.options());
  Eigen::VectorXd y = sys.state(p.X, p.eta);
  y.segment<3>(0) *= 2.9 / y.segment<3>(0).norm();  // a rotation vector near pi: the chart's far side
  Eigen::MatrixXd J;
  ASSERT_TRUE(sys.jacobian(y, J));
  int active = 0;
  for (const Contact& c : sys.scene().contacts()) active += c.active ? 1 : 0;
  ASSERT_EQ(active, 2) << "the pile should press body 0 against both others";
  const double h = 1e-6;
  Eigen::MatrixXd fd(J.rows(), J.cols());
  Eigen::VectorXd fp, fm;
  for (int k = 0; k < y.size(); ++k) {
    Eigen::VectorXd yp = y, ym = y;
    yp[k] += h;
    ym[k] -= h;
    ASSERT_TRUE(sys.rhs(yp, fp));
    ASSERT_TRUE(sys.rhs(ym, fm));
    fd.col(k) = (fp - fm) / (2 * h);
  }
  const double err = (J - fd).cwiseAbs().maxCoeff() / fd.cwiseAbs().maxCoeff();
  EXPECT_LT(err, 1e-6) << "worst entry " << (J - fd).cwiseAbs().maxCoeff() << " of " << fd.cwiseAbs().maxCoeff();
}

TEST(MultibodySystem, RechartKeepsTheRotation) {
  const Pile p;
  MultibodySystem sys(p.shapes, p.masses, p.options());
  Eigen::VectorXd y = sys.state(p.X, p.eta);
  y.segment<3>(6) = Vec3(0.3, 2.0, -3.5);  // |theta| > pi
  const Mat3 R = sys.pose(y, 1).R;
  EXPECT_TRUE(sys.rechart(y));
  EXPECT_LE(y.segment<3>(6).norm(), kPi);
  EXPECT_LT((sys.pose(y, 1).R - R).norm(), 1e-14);
  EXPECT_FALSE(sys.rechart(y));
}

/// Four spinning bodies of the paper's kinds thrown at each other: the
/// momentum of the whole is constant through their collisions (no gravity,
/// no friction, every contact's wrenches equal and opposite), to the
/// integrator's tolerance; and the integration saw contacts.
TEST(MultibodySystem, MomentumIsConservedThroughCollisions) {
  // Cone, cube, cylinder and tetrahedron at the corners of a tetrahedron
  // 1.8 from the origin, heading for it at 3 units/s, spinning.
  const BodyScene all = paper_ten_bodies(2);
  BodyScene b;
  const Vec3 corners[4] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  int c = 0;
  for (std::size_t i : {0, 1, 3, 9}) {
    b.shapes.push_back(all.shapes[i]);
    b.masses.push_back(all.masses[i]);
    const Vec3 p = 1.8 * corners[c++].normalized();
    b.X_W.push_back(Pose{all.X_W[i].R, p});
    Vec6 eta;
    eta << 1.0, -2.0, 0.5, all.X_W[i].R.transpose() * (-3.0 * p.normalized());
    b.eta.push_back(eta);
  }
  SceneOptions so;
  so.contact.stiffness = 1e4;
  MultibodySystem sys(b.shapes, b.masses, so);
  Eigen::VectorXd y = sys.state(b.X_W, b.eta);
  const Vec6 h0 = sys.momentum(y);
  double scale_v = 0.0, scale_w = 0.0;
  for (int i = 0; i < sys.num_bodies(); ++i) {
    const Vec6 mu = sys.mass(i).spatial_inertia() * sys.twist(y, i);
    scale_v += mu.tail<3>().norm();
    scale_w += mu.head<3>().norm() + sys.pose(y, i).p.norm() * mu.tail<3>().norm();
  }
  StiffOdeOptions oo;
  oo.rtol = 1e-7;
  oo.atol = 1e-9;
  StiffOdeSolver ode([&](double, const Eigen::VectorXd& x, Eigen::VectorXd& f) { return sys.rhs(x, f); },
                     [&](double, const Eigen::VectorXd& x, Eigen::MatrixXd& J) { return sys.jacobian(x, J); }, oo);
  MultibodyNewtonSolver newton(sys.num_bodies());
  ode.set_newton_solver(&newton);
  double drift_v = 0.0, drift_w = 0.0;
  long contacts = 0;
  auto each_step = [&](double, const Eigen::VectorXd& x) {
    const Vec6 dh = sys.momentum(x) - h0;
    drift_w = std::max(drift_w, dh.head<3>().norm() / scale_w);
    drift_v = std::max(drift_v, dh.tail<3>().norm() / scale_v);
    contacts += static_cast<long>(sys.scene().last_stats().active);
  };
  ASSERT_EQ(ode.integrate(0.0, 0.8, y, {}, {}, each_step, [&](double, Eigen::VectorXd& x) { return sys.rechart(x); }),
            StiffOdeStatus::Success);
  EXPECT_GT(contacts, 20) << "the bodies should collide";
  EXPECT_LT(drift_v, 50 * oo.rtol);
  EXPECT_LT(drift_w, 50 * oo.rtol);
  std::printf("%ld steps, %ld contacts over them, momentum drift %.2e (linear) %.2e (angular)\n", ode.stats().steps,
              contacts, drift_v, drift_w);
}

TEST(MultibodyNewtonSolver, SolvesAsTheDenseLU) {
  const Pile p;
  MultibodySystem sys(p.shapes, p.masses, p.options());
  const Eigen::VectorXd y = sys.state(p.X, p.eta);
  Eigen::MatrixXd J;
  ASSERT_TRUE(sys.jacobian(y, J));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(y.size(), -1.0, 2.0);
  for (double c : {1e-4, 1e-2, 0.3}) {
    MultibodyNewtonSolver blocks(sys.num_bodies());
    DenseNewtonSolver dense;
    blocks.factorise(c, J);
    dense.factorise(c, J);
    Eigen::VectorXd x1, x2;
    blocks.solve(b, x1);
    dense.solve(b, x2);
    EXPECT_LT((x1 - x2).norm(), 1e-12 * x2.norm()) << c;
  }
}

}  // namespace

// Lu6 against Eigen's full-pivoting LU, which shares no code with it. The
// matrices are built so that partial pivoting has to reorder rows at every
// step (small leading entries), and include KKT-like indefinite matrices.
#include <array>
#include <cstring>
#include <random>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "idcol/lu6.hpp"

namespace {

using idcol::Lu6;
using idcol::Mat6;
using idcol::Vec6;

Mat6 pivot_hungry(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat6 A;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = u(rng);
  // Tiny entries on and above the diagonal of the first rows force row swaps.
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) A(i, j) *= 1e-3;
  A.row(5) *= 1e2;  // rows of very different scale, as in the KKT matrix
  return A;
}

double rel_err(const Eigen::MatrixXd& x, const Eigen::MatrixXd& ref) {
  return (x - ref).norm() / ref.norm();
}

TEST(Lu6, SolvesAgreeWithEigenFullPivLu) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 500; ++trial) {
    const Mat6 A = pivot_hungry(rng);
    const Eigen::FullPivLU<Mat6> ref(A);
    ASSERT_TRUE(ref.isInvertible());
    const double tol = 1e-9;  // condition numbers here stay below ~1e5
    const Lu6 lu(A);
    Vec6 b = Vec6::NullaryExpr([&](Eigen::Index) { return std::uniform_real_distribution<double>(-1, 1)(rng); });
    EXPECT_LT(rel_err(lu.solve(b), ref.solve(b)), tol) << "trial " << trial;
    EXPECT_LT(rel_err(lu.solve_transpose(b), Eigen::FullPivLU<Mat6>(A.transpose()).solve(b)), tol)
        << "trial " << trial;
    Mat6 B = Mat6::Random();
    EXPECT_LT(rel_err(lu.solve_many<6>(B), ref.solve(B)), tol) << "trial " << trial;
    Eigen::Matrix<double, 6, 2> B2 = B.leftCols<2>();
    EXPECT_LT(rel_err(lu.solve_many<2>(B2), ref.solve(B2)), tol) << "trial " << trial;
    EXPECT_GT(lu.pivot_ratio(), 0.0);
  }
}

TEST(Lu6, RowMajorInputFactorsTheSameMatrix) {
  std::mt19937_64 rng(11);
  const Mat6 A = pivot_hungry(rng);
  const idcol::Mat6r Ar = A;
  const Vec6 b = Vec6::LinSpaced(1.0, 6.0);
  EXPECT_LT(rel_err(Lu6(Ar).solve(b), Lu6(A).solve(b)), 1e-15);
}

TEST(Lu6, SingularMatrixReportsZeroPivotRatio) {
  Mat6 A = Mat6::Identity();
  A.row(3) = A.row(1);
  Lu6 lu(A);
  EXPECT_EQ(lu.pivot_ratio(), 0.0);
}

// assign() rebuilds a stored factorisation (Python's pickle of a result):
// every solve and the pivot ratio bit for bit, a singular one included; a
// row order that is not a permutation of 0..5 is refused.
TEST(Lu6, AssignRebuildsTheFactorisationBitForBit) {
  std::mt19937_64 rng(13);
  Mat6 singular = Mat6::Identity();
  singular.row(4) = singular.row(2);
  for (int trial = 0; trial < 50; ++trial) {
    const Lu6 lu(trial == 0 ? singular : pivot_hungry(rng));
    Lu6 copy;
    ASSERT_TRUE(copy.assign(lu.factors(), lu.rows()));
    EXPECT_EQ(std::memcmp(copy.factors(), lu.factors(), 36 * sizeof(double)), 0);
    const double r0 = lu.pivot_ratio(), r1 = copy.pivot_ratio();
    EXPECT_EQ(std::memcmp(&r0, &r1, sizeof r0), 0);
    const Vec6 b = Vec6::LinSpaced(-2.0, 3.0);
    const Vec6 x = lu.solve(b), y = copy.solve(b), xt = lu.solve_transpose(b), yt = copy.solve_transpose(b);
    EXPECT_EQ(std::memcmp(x.data(), y.data(), sizeof(x)), 0);
    EXPECT_EQ(std::memcmp(xt.data(), yt.data(), sizeof(xt)), 0);
  }
  const Lu6 lu(pivot_hungry(rng));
  const Vec6 b = Vec6::Ones(), before = lu.solve(b);
  for (const auto& bad : {std::array<int, 6>{0, 1, 2, 3, 4, 4}, std::array<int, 6>{0, 1, 2, 3, 4, 6},
                          std::array<int, 6>{-1, 1, 2, 3, 4, 5}, std::array<int, 6>{0, 1, 2, 3, 4, 2147483647}}) {
    Lu6 copy(lu);
    EXPECT_FALSE(copy.assign(lu.factors(), bad.data()));
    EXPECT_EQ(copy.solve(b), before);  // unchanged
  }
}

}  // namespace

namespace {
/// A matrix with the KKT Jacobian's structure: rows 0-1 zero in columns 4-5.
Mat6 kkt_like(std::mt19937_64& rng) {
  Mat6 A = pivot_hungry(rng);
  A.block<2, 2>(0, 4).setZero();
  return A;
}
}  // namespace

TEST(KktLu6, SolvesAgreeWithEigenFullPivLu) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 500; ++trial) {
    const Mat6 A = kkt_like(rng);
    const Eigen::FullPivLU<Mat6> ref(A);
    ASSERT_TRUE(ref.isInvertible());
    idcol::KktLu6 lu;
    EXPECT_GT(lu.compute(idcol::Mat6r(A)), 0.0);
    const Vec6 b = Vec6::NullaryExpr([&](Eigen::Index) { return std::uniform_real_distribution<double>(-1, 1)(rng); });
    EXPECT_LT(rel_err(lu.solve(b), ref.solve(b)), 1e-9) << "trial " << trial;
  }
}

TEST(KktLu6, PivotRatioFlagsSingularAndNeverPassesWhatLu6Fails) {
  // newton_direction takes KktLu6's step only when its pivot ratio exceeds
  // 1e5 times min_pivot_ratio (1e-13), and otherwise runs Lu6's test as
  // before: that must never accept a matrix Lu6 would reject. Near-singular
  // matrices at every distance from singular, unscaled and equilibrated.
  std::mt19937_64 rng(17);
  idcol::KktLu6 lu;
  int fast = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Mat6 A = kkt_like(rng);
    A.col(3) = 0.5 * A.col(0) - 2.0 * A.col(1);  // exactly singular
    EXPECT_LT(lu.compute(idcol::Mat6r(A)), 1e-13) << "trial " << trial;
    for (double eps : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12}) {
      Mat6 B = A;
      B(2 + trial % 4, 3) += eps;
      for (int equil = 0; equil < 2; ++equil) {
        if (equil) {
          for (int i = 0; i < 6; ++i) B.row(i) /= B.row(i).cwiseAbs().maxCoeff();
          for (int j = 0; j < 6; ++j) B.col(j) /= B.col(j).cwiseAbs().maxCoeff();
        }
        if (lu.compute(idcol::Mat6r(B)) > 1e5 * 1e-13) {
          ++fast;
          EXPECT_GT(Lu6(B).pivot_ratio(), 1e-13) << "trial " << trial << " eps " << eps << " equilibrated " << equil;
        }
      }
    }
  }
  EXPECT_GT(fast, 1000);  // the fast path is the usual one
}

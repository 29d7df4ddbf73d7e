// LU factorisation with partial pivoting of a fixed 6x6 matrix. Eigen's
// PartialPivLU<Matrix6d> runs its generic blocked loop; this one keeps the
// factors row-major, selects pivots without branches, stores the pivot
// reciprocals so that solves do no division, and never allocates. It is the
// solver's hot path: one factorisation per Newton step.
#pragma once

#include <cmath>

#include "idcol/types.hpp"

namespace idcol {

class Lu6 {
 public:
  Lu6() = default;
  explicit Lu6(const Mat6& A) { compute(A); }

  /// Factorises P A = L U. Returns min|U_ii| / max|U_ii| (0 if singular),
  /// also kept in pivot_ratio().
  double compute(const Mat6& A) {
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) a_[i][j] = A(i, j);
      perm_[i] = i;
    }
    double mn = INFINITY, mx = 0.0;
    step<0>(mn, mx);
    step<1>(mn, mx);
    step<2>(mn, mx);
    step<3>(mn, mx);
    step<4>(mn, mx);
    step<5>(mn, mx);
    ratio_ = mx > 0.0 ? mn / mx : 0.0;
    return ratio_;
  }

  /// x with A x = b.
  Vec6 solve(const Vec6& b) const {
    double x[6];
    for (int i = 0; i < 6; ++i) {
      double v = b[perm_[i]];
      for (int j = 0; j < i; ++j) v -= a_[i][j] * x[j];
      x[i] = v;
    }
    for (int i = 5; i >= 0; --i) {
      double v = x[i];
      for (int j = i + 1; j < 6; ++j) v -= a_[i][j] * x[j];
      x[i] = v * inv_[i];
    }
    return Vec6(x[0], x[1], x[2], x[3], x[4], x[5]);
  }

  /// X with A X = B, for C right-hand sides at once. Row operations act on
  /// all C columns together, so the columns' chains run side by side.
  template <int C>
  Eigen::Matrix<double, 6, C> solve_many(const Eigen::Matrix<double, 6, C>& B) const {
    Eigen::Matrix<double, C, 6> X;  // X.col(i) is row i of the solution
    for (int i = 0; i < 6; ++i) {
      Eigen::Matrix<double, C, 1> v = B.row(perm_[i]).transpose();
      for (int j = 0; j < i; ++j) v -= a_[i][j] * X.col(j);
      X.col(i) = v;
    }
    for (int i = 5; i >= 0; --i) {
      Eigen::Matrix<double, C, 1> v = X.col(i);
      for (int j = i + 1; j < 6; ++j) v -= a_[i][j] * X.col(j);
      X.col(i) = v * inv_[i];
    }
    return X.transpose();
  }

  /// x with A^T x = b.
  Vec6 solve_transpose(const Vec6& b) const {
    double y[6];
    for (int i = 0; i < 6; ++i) {  // U^T y = b
      double v = b[i];
      for (int j = 0; j < i; ++j) v -= a_[j][i] * y[j];
      y[i] = v * inv_[i];
    }
    for (int i = 5; i >= 0; --i)  // L^T w = y
      for (int j = i + 1; j < 6; ++j) y[i] -= a_[j][i] * y[j];
    Vec6 x;
    for (int i = 0; i < 6; ++i) x[perm_[i]] = y[i];
    return x;
  }

  double pivot_ratio() const { return ratio_; }

 private:
  /// Elimination step K with compile-time bounds, so every loop unrolls.
  template <int K>
  void step(double& mn, double& mx) {
    int p = K;
    double best = std::abs(a_[K][K]);
    for (int i = K + 1; i < 6; ++i) {
      const double v = std::abs(a_[i][K]);
      const bool bigger = v > best;
      best = bigger ? v : best;
      p = bigger ? i : p;
    }
    for (int j = 0; j < 6; ++j) {  // unconditional swap: no branch to mispredict
      const double t = a_[K][j];
      a_[K][j] = a_[p][j];
      a_[p][j] = t;
    }
    const int tp = perm_[K];
    perm_[K] = perm_[p];
    perm_[p] = tp;
    mn = best < mn ? best : mn;
    mx = best > mx ? best : mx;
    const double inv = best > 0.0 ? 1.0 / a_[K][K] : 0.0;
    inv_[K] = inv;
    for (int i = K + 1; i < 6; ++i) {
      const double f = a_[i][K] * inv;
      a_[i][K] = f;
      for (int j = K + 1; j < 6; ++j) a_[i][j] -= f * a_[K][j];
    }
  }

  // Left uninitialised until compute(): zeroing them costs more than a solve step.
  double a_[6][6];  // L (unit diagonal, below) and U (on and above), row-major
  double inv_[6];   // 1 / U_ii (0 where U_ii = 0)
  int perm_[6] = {0, 1, 2, 3, 4, 5};
  double ratio_ = 0.0;
};

}  // namespace idcol


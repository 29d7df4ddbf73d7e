// LU factorisation with partial pivoting of a fixed 6x6 matrix, unrolled by
// the compiler. Eigen's PartialPivLU<Matrix6d> runs its generic blocked
// loop; this one is several times faster for the solver's hot path and never
// allocates.
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
    // Row-major working copy: row swaps and row updates touch contiguous memory.
    double a[6][6];
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) a[i][j] = A(i, j);
    for (int i = 0; i < 6; ++i) perm_[i] = i;
    for (int k = 0; k < 6; ++k) {
      int p = k;
      double best = std::abs(a[k][k]);
      for (int i = k + 1; i < 6; ++i) {
        const double v = std::abs(a[i][k]);
        if (v > best) best = v, p = i;
      }
      if (p != k) {
        for (int j = 0; j < 6; ++j) std::swap(a[k][j], a[p][j]);
        std::swap(perm_[k], perm_[p]);
      }
      if (a[k][k] == 0.0) continue;
      const double inv = 1.0 / a[k][k];
      for (int i = k + 1; i < 6; ++i) {
        const double f = a[i][k] * inv;
        a[i][k] = f;
#pragma GCC unroll 6
        for (int j = k + 1; j < 6; ++j) a[i][j] -= f * a[k][j];
      }
    }
    double mn = std::abs(a[0][0]), mx = mn;
    for (int i = 1; i < 6; ++i) {
      const double v = std::abs(a[i][i]);
      mn = std::min(mn, v);
      mx = std::max(mx, v);
    }
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) lu_(i, j) = a[i][j];
    ratio_ = mx > 0.0 ? mn / mx : 0.0;
    return ratio_;
  }

  /// x with A x = b.
  template <int C>
  Eigen::Matrix<double, 6, C> solve_many(const Eigen::Matrix<double, 6, C>& b) const {
    Eigen::Matrix<double, 6, C> x;
    for (int i = 0; i < 6; ++i) x.row(i) = b.row(perm_[i]);
    for (int i = 1; i < 6; ++i)
      for (int j = 0; j < i; ++j) x.row(i) -= lu_(i, j) * x.row(j);
    for (int i = 5; i >= 0; --i) {
      for (int j = i + 1; j < 6; ++j) x.row(i) -= lu_(i, j) * x.row(j);
      x.row(i) /= lu_(i, i);
    }
    return x;
  }

  /// x with A x = b for one right-hand side.
  Vec6 solve(const Vec6& b) const {
    double x[6];
    for (int i = 0; i < 6; ++i) {
      double v = b[perm_[i]];
      for (int j = 0; j < i; ++j) v -= lu_(i, j) * x[j];
      x[i] = v;
    }
    for (int i = 5; i >= 0; --i) {
      double v = x[i];
      for (int j = i + 1; j < 6; ++j) v -= lu_(i, j) * x[j];
      x[i] = v / lu_(i, i);
    }
    return Vec6(x[0], x[1], x[2], x[3], x[4], x[5]);
  }

  /// x with A^T x = b.
  Vec6 solve_transpose(const Vec6& b) const {
    Vec6 y = b;
    for (int i = 0; i < 6; ++i) {  // U^T y = b
      for (int j = 0; j < i; ++j) y[i] -= lu_(j, i) * y[j];
      y[i] /= lu_(i, i);
    }
    for (int i = 5; i >= 0; --i)  // L^T w = y
      for (int j = i + 1; j < 6; ++j) y[i] -= lu_(j, i) * y[j];
    Vec6 x;
    for (int i = 0; i < 6; ++i) x[perm_[i]] = y[i];
    return x;
  }

  double pivot_ratio() const { return ratio_; }
  const Mat6& packed() const { return lu_; }

 private:
  Mat6 lu_ = Mat6::Zero();
  int perm_[6] = {0, 1, 2, 3, 4, 5};
  double ratio_ = 0.0;
};

}  // namespace idcol

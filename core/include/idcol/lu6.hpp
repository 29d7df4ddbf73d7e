// LU factorisation with partial pivoting of a fixed 6x6 matrix. Eigen's
// PartialPivLU<Matrix6d> runs its generic blocked loop; this one keeps the
// factors row-major, selects pivots without branches, pivots by swapping row
// pointers instead of moving rows, stores the pivot reciprocals so that
// solves do no division, and never allocates. It is the
// solver's hot path: one factorisation per Newton step. The factorisation
// and the solve are written once for the loop and the batch lanes
// (detail/formulas/lu6.hpp); the classes here hold the scalar storage.
#pragma once

#include <cmath>
#include <cstring>

#include "idcol/detail/formulas/lu6.hpp"
#include "idcol/detail/scalar_num.hpp"
#include "idcol/types.hpp"

namespace idcol {

namespace detail {
/// The scalar rows of the LU written once (formulas/lu6.hpp) while it
/// factorises: rows are never moved, pivoting swaps the row pointers r, and
/// p[i] is the stored row (J's row) of factor row i.
struct PointerRows {
  double* r[6];
  int p[6];
  double& at(int i, int j) { return r[i][j]; }
  template <int K, int Nr>
  void swap(int q) {
    double* t = r[K];
    r[K] = r[q];
    r[q] = t;
    const int pt = p[K];
    p[K] = p[q];
    p[q] = pt;
  }
};
/// The rows of a finished factorisation: factor row i is stored row perm[i]
/// of the row-major storage a.
struct StoredRows {
  const double* a;
  const int* perm;
  double at(int i, int j) const { return a[6 * perm[i] + j]; }
  template <class B>
  double rhs(const B& b, int i) const { return b[perm[i]]; }
  template <class X>
  void put(X& x, int i, double v) const { x[perm[i]] = v; }
};
}  // namespace detail

class Lu6 {
 public:
  Lu6() = default;
  explicit Lu6(const Mat6& A) { compute(A); }

  /// Factorises P A = L U. Returns min|U_ii| / max|U_ii| (0 if singular),
  /// also kept in pivot_ratio().
  double compute(const Mat6& A) {
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) a_[i][j] = A(i, j);
    return factor();
  }
  /// The same for a row-major matrix: a straight copy, no transpose.
  double compute(const Mat6r& A) {
    const double* s = A.data();
    for (int k = 0; k < 36; ++k) (&a_[0][0])[k] = s[k];
    return factor();
  }

  /// x with A x = b.
  Vec6 solve(const Vec6& b) const {
    Vec6 x;
    detail::formulas::lu6_solve<detail::ScalarNum, false>(detail::StoredRows{&a_[0][0], perm_}, inv_, b, x);
    return x;
  }

  /// X with A X = B, for C right-hand sides at once. Row operations act on
  /// all C columns together, so the columns' chains run side by side.
  template <int C>
  Eigen::Matrix<double, 6, C> solve_many(const Eigen::Matrix<double, 6, C>& B) const {
    Eigen::Matrix<double, C, 6> X;  // X.col(i) is row i of the solution
    solve_rows<C>(B, X);
    return X.transpose();
  }
  /// x with A^T x = b.
  Vec6 solve_transpose(const Vec6& b) const {
    Vec6 x;
    detail::formulas::lu6_solve_transpose<detail::ScalarNum>(detail::StoredRows{&a_[0][0], perm_}, inv_, b, x);
    return x;
  }
  /// The same on arrays (the derivatives' formulas: formulas/derivatives.hpp):
  /// X with A X = B as solve_many forms it (each column's sums those of
  /// solve(), and of the lanes' column by column), row-major, in place.
  void solve_columns(const double (&B)[6][6], double (&X)[6][6]) const {
    Eigen::Map<Eigen::Matrix<double, 6, 6>> rows(&X[0][0]);  // its column i is X's row i
    solve_rows<6>(Eigen::Map<const Mat6r>(&B[0][0]), rows);
  }
  void solve_transpose(const double (&b)[6], double (&x)[6]) const {
    detail::formulas::lu6_solve_transpose<detail::ScalarNum>(detail::StoredRows{&a_[0][0], perm_}, inv_, b, x);
  }

  double pivot_ratio() const { return ratio_; }

  /// The factorisation as data, for storing a result (Python's pickle):
  /// the 36 entries of L and U in stored-row order, row-major, and the row
  /// order (factor row i is stored row rows()[i]). Defined after compute().
  const double* factors() const { return &a_[0][0]; }
  const int* rows() const { return perm_; }
  /// Rebuilds a factorisation from what factors() and rows() gave: the
  /// pivot reciprocals and the ratio are recomputed as compute() forms them,
  /// so solves and pivot_ratio() are those of the original bit for bit.
  /// Returns false, leaving *this unchanged, unless `rows` is a permutation
  /// of 0..5 (every solve indexes rows through it).
  bool assign(const double* factors, const int* rows) {
    bool seen[6] = {false, false, false, false, false, false};
    for (int i = 0; i < 6; ++i) {
      if (rows[i] < 0 || rows[i] > 5 || seen[rows[i]]) return false;
      seen[rows[i]] = true;
    }
    for (int k = 0; k < 36; ++k) (&a_[0][0])[k] = factors[k];
    double mn = INFINITY, mx = 0.0;
    for (int i = 0; i < 6; ++i) {
      perm_[i] = rows[i];
      // As step(): the pivot of step i is U_ii, kept in stored row perm_[i].
      const double u = a_[perm_[i]][i], best = std::abs(u);
      mn = best < mn ? best : mn;
      mx = best > mx ? best : mx;
      inv_[i] = best > 0.0 ? 1.0 / u : 0.0;
    }
    ratio_ = mx > 0.0 ? mn / mx : 0.0;
    return true;
  }

 private:
  /// X.col(i) = row i of the solution of A X = B (B 6 x C, any Eigen
  /// expression), the C columns side by side: solve_many's and
  /// solve_columns' one body.
  template <int C, class B, class X>
  void solve_rows(const B& b, X& x) const {
    for (int i = 0; i < 6; ++i) {
      const double* r = a_[perm_[i]];
      Eigen::Matrix<double, C, 1> v = b.row(perm_[i]).transpose();
      for (int j = 0; j < i; ++j) v -= r[j] * x.col(j);
      x.col(i) = v;
    }
    for (int i = 5; i >= 0; --i) {
      const double* r = a_[perm_[i]];
      Eigen::Matrix<double, C, 1> v = x.col(i);
      for (int j = i + 1; j < 6; ++j) v -= r[j] * x.col(j);
      x.col(i) = v * inv_[i];
    }
  }

  double factor() {
    detail::PointerRows r{{a_[0], a_[1], a_[2], a_[3], a_[4], a_[5]}, {0, 1, 2, 3, 4, 5}};
    ratio_ = detail::formulas::lu6_factor<detail::ScalarNum, false>(r, inv_);
    for (int i = 0; i < 6; ++i) perm_[i] = r.p[i];
    return ratio_;
  }

  // Left uninitialised until compute(): zeroing them costs more than a solve step.
  double a_[6][6];  // rows of L (unit diagonal, below) and U (on and above), in A's row order
  double inv_[6];   // 1 / U_ii (0 where U_ii = 0)
  int perm_[6] = {0, 1, 2, 3, 4, 5};  // factor row i is stored row perm_[i]
  double ratio_ = 0.0;
};

/// LU with partial pivoting of the KKT Jacobian of kkt.hpp, which has a
/// zero 2x2 block: rows 0-1 (the constraints) are zero in columns 4-5 (the
/// multipliers). The multiplier columns are eliminated first: their pivots
/// can only come from rows 2-5, which alone are updated in those two steps,
/// and what is left is a dense 4x4 block. This is exactly partial pivoting
/// applied to J with its columns in the order (4, 5, 0, 1, 2, 3), so it is
/// as stable as Lu6, with 37 multiply-subtracts instead of 55. pivot_ratio()
/// is min |U_ii| / max |U_ii| as in Lu6: zero for a singular J, and for a
/// near-singular one within two orders of 1/cond(J), where Lu6's ratio can
/// overstate it by four when rows and columns differ in scale; on an
/// equilibrated J (newton_direction's retry) the two agree within two orders
/// (test_lu6).
/// Any matrix can be given; the zero block is assumed, never read.
///
/// The solver writes its Jacobian straight into the factor's storage
/// (matrix()) and factorises it there (factor()): no copy of 36 entries per
/// Newton step. The row updates act on the column pairs (0, 1) and (2, 3)
/// as two-lane vectors (formulas/lu6.hpp), one subtraction of one product
/// per entry as in any order, so the factors are those of the entry-by-entry
/// loop to the bit.
class KktLu6 {
 public:
  /// Factorises P J Q = L U with Q the column order above. Returns the
  /// pivot ratio (0 if singular).
  double compute(const Mat6r& J) {
    a_ = J;
    return factor();
  }

  /// The storage factor() factorises in place: write J here first. After
  /// factor() it holds the factors, not J.
  Mat6r& matrix() { return a_; }

  /// compute() of the matrix written into matrix(), in place.
  double factor() {
    double* const a = a_.data();
    detail::PointerRows r{{a + 12, a + 18, a + 24, a + 30, a, a + 6}, {2, 3, 4, 5, 0, 1}};
    ratio_ = detail::formulas::lu6_factor<detail::ScalarNum, true>(r, inv_);
    for (int i = 0; i < 6; ++i) perm_[i] = r.p[i];
    return ratio_;
  }

  /// x with J x = b.
  Vec6 solve(const Vec6& b) const {
    Vec6 x;
    detail::formulas::lu6_solve<detail::ScalarNum, true>(detail::StoredRows{a_.data(), perm_}, inv_, b, x);
    return x;
  }

  double pivot_ratio() const { return ratio_; }

 private:
  Mat6r a_;         // J's rows, in place; left uninitialised until compute(), as in Lu6
  double inv_[6];   // 1 / U_ii
  int perm_[6] = {2, 3, 4, 5, 0, 1};  // factor row i is J's row perm_[i]
  double ratio_ = 0.0;
};

}  // namespace idcol


// The 6x6 LU factorisation with partial pivoting of a Newton step, and its
// solve, written once over a number layer N (elementary.hpp): the scalar
// solver's Lu6 and KktLu6 (lu6.hpp) instantiate them with double, the batch
// lanes (newton_lanes_kernel.hpp, LaneLu) with a vector of W doubles, so
// that a lane's factors and step are the loop's, bit for bit.
//
// kKkt = false is the dense LU (Lu6): column K is eliminated at step K over
// every row left. kKkt = true is the KKT Jacobian's (KktLu6, lu6.hpp says
// why): J's columns in the order 4, 5, 0, 1, 2, 3, the factor rows starting
// as J's rows 2, 3, 4, 5, 0, 1, and the two multiplier columns' pivots
// sought in rows 2-5 of J only, past J's zero block (rows 0-1, columns 4-5),
// which is written as zeros and never read otherwise.
//
// The rows r are the layer's, for the one thing the layers do differently:
// moving a pivot row. r.at(i, j) is factor row i's entry in J's column j;
// r.swap<K, Nr>(q) exchanges factor row K with row q (an int where one
// pivot is chosen, a mask of row numbers where each lane chose its own),
// r.rhs(b, i) is b's entry in the row of J that factor row i came from. The
// scalar rows swap pointers; the lanes' rows swap entries by selects.
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/elementary.hpp"

namespace idcol::detail::formulas {

/// The order of the elimination: J's column of step K, J's row of factor
/// row i at the start, and the rows the first two steps search.
template <bool kKkt>
struct Lu6Order {
  static constexpr int col[6] = {kKkt ? 4 : 0, kKkt ? 5 : 1, kKkt ? 0 : 2, kKkt ? 1 : 3, kKkt ? 2 : 4, kKkt ? 3 : 5};
  static constexpr int row[6] = {kKkt ? 2 : 0, kKkt ? 3 : 1, kKkt ? 4 : 2, kKkt ? 5 : 3, kKkt ? 0 : 4, kKkt ? 1 : 5};
  static constexpr int rows01 = kKkt ? 4 : 6;
};

/// Row i -= f times factor row K over the columns col[J..5]: J's columns
/// (2k, 2k + 1) as one N::T2 where both are left (one subtraction of one
/// product per entry either way, so the bits are the entry-by-entry loop's).
template <class N, bool kKkt, int K, int J, class Rows>
[[gnu::always_inline]] inline void lu6_update(Rows& r, int i, typename N::T f) {
  using O = Lu6Order<kKkt>;
  if constexpr (J < 6) {
    constexpr int cj = O::col[J];
    if constexpr (cj % 2 == 0 && J + 1 < 6 && O::col[J + 1 < 6 ? J + 1 : 0] == cj + 1) {
      const auto v = N::pair(r.at(i, cj), r.at(i, cj + 1)) - f * N::pair(r.at(K, cj), r.at(K, cj + 1));
      r.at(i, cj) = N::lo(v);
      r.at(i, cj + 1) = N::hi(v);
      lu6_update<N, kKkt, K, J + 2>(r, i, f);
    } else {
      r.at(i, cj) = r.at(i, cj) - f * r.at(K, cj);
      lu6_update<N, kKkt, K, J + 1>(r, i, f);
    }
  }
}

/// Elimination step K (J's column col[K]) over the factor rows K..Nr-1:
/// the first largest |entry| is the pivot (branch-free), the multipliers
/// stored in place, 1 / U_KK in inv[K] (0 where the pivot is 0), and the
/// smallest and largest |U_KK| so far in mn, mx.
template <class N, bool kKkt, int K, int Nr, class Rows>
[[gnu::always_inline]] inline void lu6_step(Rows& r, typename N::T (&inv)[6], typename N::T& mn, typename N::T& mx) {
  using T = typename N::T;
  using O = Lu6Order<kKkt>;
  constexpr int c = O::col[K];
  T best = N::abs(r.at(K, c));
  auto q = N::index(K);
  for (int i = K + 1; i < Nr; ++i) {
    const T v = N::abs(r.at(i, c));
    const auto bigger = v > best;
    best = N::sel(bigger, v, best);
    q = N::sel_index(bigger, i, q);
  }
  r.template swap<K, Nr>(q);
  mn = N::sel(best < mn, best, mn);
  mx = N::sel(best > mx, best, mx);
  const T iv = N::lazy(best > 0.0, [&] { return T(1.0 / r.at(K, c)); }, [] { return N::splat(0.0); });
  inv[K] = iv;
  for (int i = K + 1; i < Nr; ++i) {
    const T f = r.at(i, c) * iv;
    r.at(i, c) = f;
    lu6_update<N, kKkt, K, K + 1>(r, i, f);
  }
}

/// Factorises the rows in place (P J Q = L U, Q the column order); returns
/// the pivot ratio min |U_ii| / max |U_ii|, 0 where J is singular.
template <class N, bool kKkt, class Rows>
[[gnu::always_inline]] inline typename N::T lu6_factor(Rows& r, typename N::T (&inv)[6]) {
  using T = typename N::T;
  constexpr int n01 = Lu6Order<kKkt>::rows01;
  if constexpr (kKkt)
    for (int i = 4; i < 6; ++i) r.at(i, 4) = r.at(i, 5) = N::splat(0.0);  // J's zero block, read by the solve
  T mn = N::splat(__builtin_inf()), mx = N::splat(0.0);
  lu6_step<N, kKkt, 0, n01>(r, inv, mn, mx);
  lu6_step<N, kKkt, 1, n01>(r, inv, mn, mx);
  lu6_step<N, kKkt, 2, 6>(r, inv, mn, mx);
  lu6_step<N, kKkt, 3, 6>(r, inv, mn, mx);
  lu6_step<N, kKkt, 4, 6>(r, inv, mn, mx);
  lu6_step<N, kKkt, 5, 6>(r, inv, mn, mx);
  return N::sel(mx > 0.0, mn / mx, N::splat(0.0));
}

/// x with J x = b from the factors: forward through L, back through U.
template <class N, bool kKkt, class Rows, class B, class X>
[[gnu::always_inline]] inline void lu6_solve(const Rows& r, const typename N::T (&inv)[6], const B& b, X& x) {
  using T = typename N::T;
  using O = Lu6Order<kKkt>;
  T w[6];
  for (int i = 0; i < 6; ++i) {
    T v = r.rhs(b, i);
    for (int j = 0; j < i; ++j) v = v - r.at(i, O::col[j]) * w[j];
    w[i] = v;
  }
  for (int i = 5; i >= 0; --i) {
    T v = w[i];
    for (int j = i + 1; j < 6; ++j) v = v - r.at(i, O::col[j]) * w[j];
    w[i] = v * inv[i];
  }
  for (int i = 0; i < 6; ++i) x[O::col[i]] = w[i];
}

/// x with J^T x = b from the factors of the dense LU (kKkt = false):
/// back through U^T, then L^T; r.put(x, i, v) sets x's entry in J's row of
/// factor row i.
template <class N, class Rows, class B, class X>
[[gnu::always_inline]] inline void lu6_solve_transpose(const Rows& r, const typename N::T (&inv)[6], const B& b, X& x) {
  using T = typename N::T;
  T y[6];
  for (int i = 0; i < 6; ++i) {
    T v = b[i];
    for (int j = 0; j < i; ++j) v = v - r.at(j, i) * y[j];
    y[i] = v * inv[i];
  }
  for (int i = 5; i >= 0; --i)
    for (int j = i + 1; j < 6; ++j) y[i] = y[i] - r.at(j, i) * y[j];
  for (int i = 0; i < 6; ++i) r.put(x, i, y[i]);
}

}  // namespace idcol::detail::formulas

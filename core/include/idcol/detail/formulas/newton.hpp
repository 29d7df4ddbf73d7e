// Pieces of the Newton method on the KKT system written once over a number
// layer N (elementary.hpp), as kkt.hpp's residual and Jacobian are: the
// scalar solver (solver_impl.hpp) instantiates them with double, the Newton
// lanes (newton_lanes_kernel.hpp) with a vector of W doubles.
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/kkt.hpp"

namespace idcol::detail::formulas {

/// Shrinks or projects a step dz from the point (z, alpha = e^z[3]) so that
/// s stays in [lo, hi], |ds| <= max_step_s, the witness point moves at most
/// max_step_x alpha and the multipliers stay positive (a fraction tau of
/// the way to zero at most); returns the step length t in (0, 1].
///
/// t is min(t, max_step_s / |ds|, max_step_x alpha / |dx|, tau z_i / -dz_i)
/// over the bounds that apply, formed as t = min(t, bound); a step with a
/// NaN takes t = 1. Where the layer prescreens (N::kPrescreen: the lanes,
/// for which a division or square root of W lanes costs more than a test),
/// the |dx| and multiplier bounds are first tested by multiplication, with
/// the relative margin `band`, and formed only in a group where some lane
/// may bind: outside the margin a bound cannot be below t, so every lane's t
/// is the scalar layer's, to the bit.
template <class N, class Z, class DZ>
[[gnu::always_inline]] inline typename N::T limit_step(const Z& z, typename N::T alpha, DZ& dz, double lo, double hi,
                                                       double max_step_s, double max_step_x, typename N::T tau,
                                                       double band) {
  using T = typename N::T;
  const T s_new = z[3] + dz[3];
  dz[3] = N::sel(s_new > hi, hi - z[3], dz[3]);
  dz[3] = N::sel(s_new < lo, lo - z[3], dz[3]);
  T t = N::splat(1.0);
  const T ads = N::abs(dz[3]);
  const auto ms = ads > max_step_s;
  if (N::any(ms)) t = N::sel(ms, max_step_s / ads, t);
  const T dx[3] = {dz[0], dz[1], dz[2]};
  const T nx2 = dot3<N>(dx, dx);
  const T xmax = max_step_x * alpha;
  // (|dx| t)^2 against xmax^2, with the margin.
  const auto mx = [&] {
    if constexpr (N::kPrescreen) {
      const T lhs = nx2 * (t * t), rhs = xmax * xmax;
      return lhs >= rhs - band * rhs;
    } else {
      return N::mask(true);
    }
  }();
  if (N::any(mx)) {
    const T nx = N::sqrt(nx2);
    t = N::sel(mx & (nx * t > xmax), xmax / nx, t);
  }
  for (int i = 4; i < 6; ++i) {
    // tau z_i / (-dz_i) < t multiplied out, with the margin.
    const T a = tau * z[i];
    const auto may = [&] {
      if constexpr (N::kPrescreen) {
        const T b = t * (-dz[i]);
        return (dz[i] < 0.0) & (a <= b + band * b);
      } else {
        return dz[i] < 0.0;
      }
    }();
    if (N::any(may)) {
      const T bound = a / (-dz[i]);
      t = N::sel(may & (bound < t), bound, t);
    }
  }
  return t;
}

}  // namespace idcol::detail::formulas

// The smooth truncated cone in the Newton lanes (LaneShape family 2):
// SmoothTruncatedCone::eval (shapes.cpp) per lane, at the cone's own beta
// (the warm path evaluates each body at its own sharpness). Included by
// newton_lanes_kernel.hpp inside its translation unit (internal linkage,
// plain data only).
//
// LaneShape::cone, as lane_shape_cone (batch_simd.cpp) fills it:
//   [0] Rb   [1] kappa = (Rt - Rb) / (a + b)   [2] a   [3] b
//   [4] Rfloor = 0.5 min(Rb, Rt)   [5] beta   [6] -1 / a   [7] 1 / b
//
// The arithmetic is shapes.cpp's operation for operation. shapes.cpp is
// built for baseline x86-64 (no FMA to contract into) with
// -fno-trapping-math, which changes no value; this header's translation
// units add -ffp-contract=off. C++ evaluates a * b * c as (a * b) * c, and
// Eigen forms the Hessian's outer products column by column, entry (i, j)
// = (w d_i) d_j, and the sum of the three elementwise, left to right.
namespace {

inline void eval_cone(const idcol::detail::LaneShape& s, const V3& y, Eval& e, M&) {
  const double Rb = s.cone[0], kappa = s.cone[1], a = s.cone[2], b = s.cone[3], Rfloor = s.cone[4], sharp = s.cone[5],
               gbx = s.cone[6], gtx = s.cone[7];
  const V R0 = Rb + kappa * (y.x + a);
  const M floor = R0 < Rfloor;  // only beyond the body's axial range
  const V R = sel(floor, splat(Rfloor), R0);
  const V kap = sel(floor, V{}, splat(kappa));
  const V iR = 1.0 / R, iR2 = iR * iR;
  const V r2 = y.y * y.y + y.z * y.z;
  const V cs = r2 * iR2 - 1.0;
  const V cb = -y.x / a - 1.0;
  const V ct = y.x / b - 1.0;
  // std::max({cs, cb, ct}): the first of equal maxima.
  V cmax = cs;
  cmax = sel(cmax < cb, cb, cmax);
  cmax = sel(cmax < ct, ct, cmax);
  const V es = lane_exp_nonpositive<false>(sharp * (cs - cmax)), eb = lane_exp_nonpositive<false>(sharp * (cb - cmax)),
          et = lane_exp_nonpositive<false>(sharp * (ct - cmax));
  const V S = es + eb + et;
  const V ws = es / S, wb = eb / S, wt = et / S;
  const V gs[3] = {-2.0 * kap * r2 * iR2 * iR, 2.0 * y.y * iR2, 2.0 * y.z * iR2};
  V lS;
  for (int i = 0; i < W; ++i) lS[i] = __builtin_log(S[i]);
  e.phi = cmax + lS / sharp;
  V g[3] = {ws * gs[0], ws * gs[1], ws * gs[2]};
  g[0] = g[0] + (wb * gbx + wt * gtx);
  e.g = {g[0], g[1], g[2]};
  const V ds[3] = {gs[0] - g[0], gs[1] - g[1], gs[2] - g[2]};
  const V db[3] = {gbx - g[0], -g[1], -g[2]};
  const V dt[3] = {gtx - g[0], -g[1], -g[2]};
  const V h01 = -4.0 * kap * y.y * iR2 * iR, h02 = -4.0 * kap * y.z * iR2 * iR;
  const V z = V{};
  const V Hs[9] = {6.0 * kap * kap * r2 * iR2 * iR2, h01, h02, h01, 2.0 * iR2, z, h02, z, 2.0 * iR2};
  V wds[3], wdb[3], wdt[3];
  for (int i = 0; i < 3; ++i) wds[i] = ws * ds[i], wdb[i] = wb * db[i], wdt[i] = wt * dt[i];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      e.h[3 * i + j] = ws * Hs[3 * i + j] + sharp * ((wds[i] * ds[j] + wdb[i] * db[j]) + wdt[i] * dt[j]);
}

}  // namespace

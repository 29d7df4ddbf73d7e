// The smooth polytope in the Newton lanes (LaneFamily::Polytope):
// SmoothPolytope::eval per lane, as the face kernel the scalar solver runs
// (polytope_kernel.hpp) computes it. Included by newton_lanes_kernel.hpp
// inside its translation unit (internal linkage, plain data only).
//
// The face kernel holds one pose and runs its faces four at a time; here
// each lane holds a pose and the faces run one at a time. Both make each
// face's arithmetic by the same formulas (formulas/shape_eval.hpp): the
// face value c_i = a_i.y - b_i (polytope_face_value), and its weight
// w_i = exp(k (c_i - c_max)) and moments added to the partial sums of its
// residue i mod 4 (PolytopeFaceSums::add; the kernel's four residues are
// the lanes of one vector, here four sums of W poses), so that every lane
// makes the kernel's operations on its pose in the kernel's order. What
// differs is only the layout: the maximum is taken face by face (the
// first face that reaches it gives a*, as the kernel's first index with
// c_i == c_max; its value, as any order's, is exact). From the sums on,
// the lanes and the kernel run one formula (formulas::polytope_from_sums,
// with its log_ge1).
//
// The kernel that the scalar solver runs (detail::polytope_kernel_isa())
// fuses where it says mul_add ("avx2": the exp's argument reduction and
// polynomial, the face values, the second moments) or nowhere ("sse2").
// LanePolytope::fused says which; the lanes fuse at the same
// places with a vector FMA, which only a translation unit compiled with FMA
// has (AVX2 with -mfma, AVX-512F): one without (SSE2) flags every lane of a fused polytope (the dispatcher does
// not send it one: lane_shape_polytope, narrow_for in batch_simd.cpp).
//
// LanePolytope (LaneShape::poly): faces (SmoothPolytope's face block [a_x |
// a_y | a_z | b], four columns of m4 entries, padding faces a = 0, b =
// +inf), m4, beta (the sharpness the warm path evaluates it at: its own), L
// (the rounding length), k = beta / L (the kernel's), and whether the
// scalar kernel fuses.
namespace {

/// The face kernel's eval<true, any> per lane, at the polytope's own
/// sharpness. Lanes whose point or face maximum is not finite are flagged.
template <bool kFused>
inline void eval_polytope_impl(const idcol::detail::LaneShape& s, const V3& y, Eval& e, M& bad) {
  const int m = s.poly.m4;
  const double* ax = s.poly.faces;
  const double* ay = ax + m;
  const double* az = ay + m;
  const double* b = az + m;
  const double sharp = s.poly.beta, L = s.poly.L;
  const V vk = splat(s.poly.k);
  bad |= ~(finite(y.x) & finite(y.y) & finite(y.z));
  constexpr int kKeep = 64;  // face values kept between the two passes (more: computed again)
  V cb[kKeep];
  auto face = [&](int i) {
    return idcol::detail::formulas::polytope_face_value<LaneNum, kFused>(splat(ax[i]), splat(ay[i]), splat(az[i]),
                                                                          splat(b[i]), y.x, y.y, y.z);
  };
  V cmax = splat(-__builtin_inf());
  V sx = V{}, sy = V{}, sz = V{};
  M nan = M{};
  for (int i = 0; i < m; ++i) {
    const V c = face(i);
    if (i < kKeep) cb[i] = c;
    nan |= c != c;
    const M up = c > cmax;  // the first face that reaches the maximum
    cmax = sel(up, c, cmax);
    sx = sel(up, splat(ax[i]), sx);
    sy = sel(up, splat(ay[i]), sy);
    sz = sel(up, splat(az[i]), sz);
  }
  bad |= nan | ~finite(cmax);
  // The partial sums of one residue i mod 4 at a time (each adds its own
  // faces in increasing i, as the kernel's): ten accumulators live, not forty.
  // Each residue's sums leave the struct field by field: copied whole into
  // an array of structs, the struct stayed in memory through the face loop
  // (+4% of the batch's instructions per Poly-Poly solve under callgrind).
  V S0[4], S1x[4], S1y[4], S1z[4], Sxx[4], Sxy[4], Sxz[4], Syy[4], Syz[4], Szz[4];
  for (int j = 0; j < 4; ++j) {
    idcol::detail::formulas::PolytopeFaceSums<LaneNum, kFused, true> r;
    for (int i = j; i < m; i += 4)
      r.add(vk, i < kKeep ? cb[i] : face(i), cmax, splat(ax[i]), splat(ay[i]), splat(az[i]), sx, sy, sz);
    S0[j] = r.s0, S1x[j] = r.s1x, S1y[j] = r.s1y, S1z[j] = r.s1z;
    Sxx[j] = r.sxx, Sxy[j] = r.sxy, Sxz[j] = r.sxz, Syy[j] = r.syy, Syz[j] = r.syz, Szz[j] = r.szz;
  }
  // phi, grad and hess from the sums: the face kernel's own formula, each
  // sum's four partial sums as (s0 + s1) + (s2 + s3).
  auto sum4 = [](const V (&a)[4]) { return (a[0] + a[1]) + (a[2] + a[3]); };
  const V m1[3] = {sum4(S1x), sum4(S1y), sum4(S1z)};
  const V m2[6] = {sum4(Sxx), sum4(Sxy), sum4(Sxz), sum4(Syy), sum4(Syz), sum4(Szz)};
  const V astar[3] = {sx, sy, sz};
  idcol::detail::formulas::polytope_from_sums<LaneNum, true>(sum4(S0), m1, m2, cmax, astar, L, sharp, e, bad);
}

inline void eval_polytope(const idcol::detail::LaneShape& s, const V3& y, Eval& e, M& bad) {
  if (!s.poly.fused) return eval_polytope_impl<false>(s, y, e, bad);
#if (defined(__FMA__) && IDCOL_LANES == 4) || (defined(__AVX512F__) && IDCOL_LANES == 8)
  return eval_polytope_impl<true>(s, y, e, bad);
#else
  e = Eval{};  // no FMA in this translation unit: the scalar solver's
  bad = ~M{};
#endif
}

}  // namespace

// (a) Highway glue, inside study::HWY_NAMESPACE (re-included per target).
using D = hn::ScalableTag<double>;
using DU = hn::RebindToUnsigned<D>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;
template <class T> HWY_INLINE T splat(double c);
template <> HWY_INLINE V splat<V>(double c) { return hn::Set(D(), c); }
HWY_INLINE V select(M m, V a, V b) { return hn::IfThenElse(m, a, b); }
HWY_INLINE V fused_mul_add(V a, V b, V c) { return hn::MulAdd(a, b, c); }
HWY_INLINE V pow2_from_shifter(V t) {
  const auto u = hn::BitCast(DU(), t);
  return hn::BitCast(D(), hn::ShiftLeft<52>(hn::Add(u, hn::Set(DU(), 1023))));
}
HWY_INLINE bool any(M m) { return !hn::AllFalse(D(), m); }
HWY_INLINE M mask_and(M a, M b) { return hn::And(a, b); }
template <class T> HWY_INLINE T loadu(const double* p);
template <> HWY_INLINE V loadu<V>(const double* p) { return hn::LoadU(D(), p); }
HWY_INLINE void storeu(V v, double* p) { hn::StoreU(v, D(), p); }

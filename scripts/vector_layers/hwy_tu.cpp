// (a) Highway: one file, compiled once per target by foreach_target.h.
#include "api.hpp"
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "hwy_tu.cpp"
#include <hwy/foreach_target.h>  // re-includes this file per target
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace study {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
#include "glue_hwy.hpp"
#include "kernel.inc"
Kernels GetKernels() {
  return Kernels{&exp_array<false, V>, &exp_array<true, V>, &matvec_array<V>, &sqrt_array<V>,
                 int(hn::Lanes(D()))};
}
}  // namespace HWY_NAMESPACE
}  // namespace study
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace study {
HWY_EXPORT(GetKernels);
}
Kernels hwy_dynamic() { return HWY_DYNAMIC_DISPATCH(study::GetKernels)(); }
// Explicit per-target entry points for measurement.
#if HWY_TARGETS & HWY_SCALAR  // GCC < 12.3: EMU128 is marked broken, the fallback is 1 lane
Kernels hwy_baseline() { return study::N_SCALAR::GetKernels(); }
#else
Kernels hwy_baseline() { return study::N_EMU128::GetKernels(); }
#endif
Kernels hwy_ssse3() { return study::N_SSSE3::GetKernels(); }
Kernels hwy_sse4() { return study::N_SSE4::GetKernels(); }
Kernels hwy_avx2() { return study::N_AVX2::GetKernels(); }
long long hwy_chosen_target() { return hwy::SupportedTargets(); }
#endif

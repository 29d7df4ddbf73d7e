#include <xsimd/xsimd.hpp>
#include <cstring>
#include "api.hpp"
#include "xsimd_dispatch.hpp"
namespace {
#include "glue_xsimd.hpp"
#include "kernel.inc"
}
DEFINE_KERNELS(KNAME, V)
#ifdef XS_DISPATCH
template <> Kernels XsGet::operator()(XS_ARCH) const { return KNAME(); }
#endif

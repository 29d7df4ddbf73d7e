#include <cmath>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <immintrin.h>
#endif
#include "api.hpp"
namespace { 
#include "glue_scalar.hpp"
#include "kernel.inc"
}
DEFINE_KERNELS(KNAME, double)

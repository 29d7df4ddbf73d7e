// The lane kernel (batch_simd_kernel.hpp) with 8 lanes, for CPUs with AVX512;
// compiled with that instruction set's flags (core/CMakeLists.txt).
#define IDCOL_LANES 8
#define IDCOL_LANE_FN ellipsoid_lanes_avx512
#include "batch_simd_kernel.hpp"
#define IDCOL_NEWTON_FN newton_lanes_avx512
#define IDCOL_NEWTON_FINISH_FN newton_finish_lanes_avx512
#include "newton_lanes_kernel.hpp"
#define IDCOL_NEWTON_COLD_FN newton_cold_lanes_avx512
#include "newton_lanes_cold.hpp"
#define IDCOL_SEPARATED_FN separated_lanes_avx512
#include "separated_lanes.hpp"

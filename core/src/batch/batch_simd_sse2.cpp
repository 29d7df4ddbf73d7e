// The lane kernel (batch_simd_kernel.hpp) with 2 lanes, for CPUs with SSE2;
// compiled with that instruction set's flags (core/CMakeLists.txt).
#define IDCOL_LANES 2
#define IDCOL_LANE_FN ellipsoid_lanes_sse2
#include "batch_simd_kernel.hpp"
#define IDCOL_NEWTON_FN newton_lanes_sse2
#define IDCOL_NEWTON_FINISH_FN newton_finish_lanes_sse2
#include "newton_lanes_kernel.hpp"
#define IDCOL_NEWTON_COLD_FN newton_cold_lanes_sse2
#include "newton_lanes_cold.hpp"
#define IDCOL_SEPARATED_FN separated_lanes_sse2
#include "separated_lanes.hpp"

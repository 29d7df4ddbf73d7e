// The smooth polytope's face loop for SSE2 (see polytope_kernel.hpp).
#define IDCOL_POLYTOPE_PAIRS 1  // four lanes as two SSE2 registers
#include "polytope_kernel.hpp"

namespace idcol::detail {

PolytopeKernels polytope_kernels_sse2() {
  return {&polytope_kernel::eval<true>, &polytope_kernel::eval<false>, "sse2"};
}

}  // namespace idcol::detail

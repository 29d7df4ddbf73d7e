// The smooth polytope's face loop for AVX2 (see polytope_kernel.hpp).
#include "polytope_kernel.hpp"

namespace idcol::detail {

PolytopeKernels polytope_kernels_avx2() {
  return {&polytope_kernel::moments<true>, &polytope_kernel::moments<false>, "avx2"};
}

}  // namespace idcol::detail

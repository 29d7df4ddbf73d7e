// The smooth polytope's face loop for AVX2 with FMA (see polytope_kernel.hpp).
#include "polytope_kernel.hpp"

namespace idcol::detail {

PolytopeKernels polytope_kernels_avx2() {
  return {&polytope_kernel::eval<true>, &polytope_kernel::eval<false>, "avx2"};
}

}  // namespace idcol::detail

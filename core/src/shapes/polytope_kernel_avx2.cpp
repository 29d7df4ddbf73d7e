// The smooth polytope's face loop for AVX2 with FMA (see polytope_kernel.hpp).
#include "polytope_kernel.hpp"

namespace idcol::detail {

PolytopeKernels polytope_kernels_avx2() {
  using namespace polytope_kernel;
  return {{&eval<true, 0>, &eval<true, 1>, &eval<true, 2>, &eval<true, 3>, &eval<true, 4>},
          {&eval<false, 0>, &eval<false, 1>, &eval<false, 2>, &eval<false, 3>, &eval<false, 4>},
          "avx2"};
}

}  // namespace idcol::detail

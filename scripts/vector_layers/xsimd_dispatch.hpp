#pragma once
#include <xsimd/xsimd.hpp>
#include "api.hpp"
// xsimd's dispatch calls functor(Arch{}) for the best Arch of the list that the CPU has;
// each specialization lives in a TU compiled with that arch's flags.
struct XsGet { template <class Arch> Kernels operator()(Arch) const; };
template <> Kernels XsGet::operator()(xsimd::sse2) const;
template <> Kernels XsGet::operator()(xsimd::fma3<xsimd::avx2>) const;

// std::visit with one lambda per alternative:
//   std::visit(Overloaded{[](const SphereDesc& s) { ... }, [](const ConeDesc& c) { ... }}, d)
// An alternative without its lambda (a new shape family) is a compile error
// there, not a std::bad_variant_access at run time.
#pragma once

namespace idcol::baselines {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

}  // namespace idcol::baselines

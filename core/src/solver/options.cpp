#include "idcol/options.hpp"

#include <cmath>
#include <cstddef>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "idcol/options_fields.hpp"

namespace idcol {

// ---------------------------------------------------------------------------
// The list of options_fields.hpp is SolverOptions, member for member.
//
// (1) Every listed field is a member of that type, at the place the list
// gives it: a struct with the listed members in the listed order has them at
// the same offsets (a name missing from SolverOptions does not compile).
// (2) SolverOptions has no member the list lacks: the number of initialisers
// its aggregate initialisation takes is the number of listed fields.
namespace {
namespace field_check {
struct Listed {
#define IDCOL_LISTED_MEMBER(T, name, range) T name;
  IDCOL_SOLVER_OPTION_FIELDS(IDCOL_LISTED_MEMBER)
#undef IDCOL_LISTED_MEMBER
};
#define IDCOL_SAME_PLACE(T, name, range)                                                       \
  static_assert(std::is_same_v<decltype(SolverOptions::name), T>,                                \
                "options_fields.hpp lists SolverOptions::" #name " with another type");          \
  static_assert(offsetof(SolverOptions, name) == offsetof(Listed, name),                        \
                "options_fields.hpp lists SolverOptions::" #name " out of the order of options.hpp " \
                "(or a member before it is missing from the list)");
IDCOL_SOLVER_OPTION_FIELDS(IDCOL_SAME_PLACE)
#undef IDCOL_SAME_PLACE

/// Converts to any member type, so SolverOptions{AnyValue{}, ...} compiles
/// for as many initialisers as it has members and no more.
struct AnyValue {
  template <class T>
  constexpr operator T() const noexcept {
    return T{};
  }
};
template <class T, class Seq, class = void>
struct TakesInitialisers : std::false_type {};
template <class T, std::size_t... I>
struct TakesInitialisers<T, std::index_sequence<I...>, std::void_t<decltype(T{(void(I), AnyValue{})...})>>
    : std::true_type {};
template <class T, std::size_t N = 0>
constexpr std::size_t member_count() {
  if constexpr (TakesInitialisers<T, std::make_index_sequence<N + 1>>::value) return member_count<T, N + 1>();
  else return N;
}
static_assert(std::is_aggregate_v<SolverOptions> && std::is_standard_layout_v<SolverOptions>,
              "the checks below count SolverOptions' members by aggregate initialisation");
static_assert(member_count<SolverOptions>() == kSolverOptionFieldCount,
              "a member of SolverOptions is missing from IDCOL_SOLVER_OPTION_FIELDS (options_fields.hpp)");
static_assert(sizeof(Listed) == sizeof(SolverOptions), "options_fields.hpp and SolverOptions differ in size");
}  // namespace field_check

std::string number(double v) {
  std::ostringstream os;
  os << v;  // 6 significant digits: the bounds are round numbers
  return os.str();
}
}  // namespace

std::string SolverOptionField::expected(const SolverOptions& o) const {
  const OptionRange& r = range;
  std::string s;
  if (flag) {
    s = "true or false";
  } else if (integer) {
    const std::string lo = r.lo_option ? std::string(r.lo_option_name) + " = " + std::to_string(o.*r.lo_option)
                                       : std::to_string(static_cast<int>(r.lo));
    s = "an integer in [" + lo + ", " + std::to_string(static_cast<int>(r.hi)) + "]";
  } else if (std::isinf(r.hi)) {
    s = std::string(r.infinity_ok ? "" : "finite and ") + (r.lo_open ? "> " : ">= ") + number(r.lo);
  } else {
    s = std::string("in ") + (r.lo_open ? "(" : "[") + number(r.lo) + ", " + number(r.hi) + (r.hi_open ? ")" : "]");
  }
  if (r.note) s += std::string(" (") + r.note + ")";
  return s;
}

bool SolverOptionField::accepts(const SolverOptions& o) const {
  const OptionRange& r = range;
  if (flag) return true;
  if (integer) {
    const int v = o.*integer;
    return v >= (r.lo_option ? o.*r.lo_option : static_cast<int>(r.lo)) && v <= static_cast<int>(r.hi);
  }
  const double v = o.*real;
  if (std::isnan(v)) return false;
  if (std::isinf(v) && !(r.infinity_ok && v > 0.0)) return false;
  return (r.lo_open ? v > r.lo : v >= r.lo) && (r.hi_open ? v < r.hi : v <= r.hi);
}

void SolverOptions::validate() const {
  for (const SolverOptionField& f : solver_option_fields()) {
    if (f.accepts(*this)) continue;
    std::ostringstream os;
    os << std::setprecision(17) << "SolverOptions: field '" << f.name << "' must be " << f.expected(*this) << ", got ";
    if (f.integer) os << this->*f.integer;
    else os << this->*f.real;
    throw std::invalid_argument(os.str());
  }
}

}  // namespace idcol

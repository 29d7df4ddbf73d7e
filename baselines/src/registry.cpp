#include "idcol_baselines/registry.hpp"

#include <atomic>

#include <stdexcept>

#include "idcol_baselines/core_adapter.hpp"

namespace idcol::baselines {

namespace detail {
// Defined in the table CMake generates from the adapters it compiled
// (competitor_table.cpp.in).
std::vector<const Competitor*> compiled_competitors();
}  // namespace detail

const std::vector<const Competitor*>& competitors() {
  static const std::vector<const Competitor*> table = [] {
    std::vector<const Competitor*> t = detail::compiled_competitors();
    for (std::size_t i = 0; i < t.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (std::string_view(t[i]->name) == t[j]->name)
          throw std::logic_error(std::string("two competitors are called \"") + t[i]->name + "\"");
    return t;
  }();
  return table;
}

const Competitor* find_competitor(std::string_view name) {
  for (const Competitor* c : competitors())
    if (name == c->name) return c;
  return nullptr;
}

std::string competitor_names() {
  std::string s;
  for (const Competitor* c : competitors()) s += (s.empty() ? "" : ", ") + std::string(c->name);
  return s.empty() ? "none in this build" : s;
}

const Competitor& competitor(std::string_view name) {
  if (const Competitor* c = find_competitor(name)) return *c;
  throw std::invalid_argument("unknown baseline \"" + std::string(name) + "\" (known: " + competitor_names() + ")");
}

bool serves_exact_bodies(const Shape& body1, const Shape& body2, std::string* why) {
  std::string w1, w2;
  const bool r1 = representable(body1, &w1), r2 = representable(body2, &w2);
  if (r1 && r2) return true;
  if (why)
    *why = "the pair " + describe_pair(body1, body2) + ": " + (r1 ? "" : "body 1: " + w1 + (r2 ? "" : "; ")) +
           (r2 ? "" : "body 2: " + w2);
  return false;
}

namespace {
std::atomic<std::uint64_t> g_trapped_aborts{0};
}
std::uint64_t trapped_aborts() { return g_trapped_aborts.load(); }
void note_trapped_abort() { g_trapped_aborts.fetch_add(1); }

}  // namespace idcol::baselines

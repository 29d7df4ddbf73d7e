// The competitors, as one table. Each adapter file declares its own entries
// (baselines/src/fcl_adapter.cpp, baselines/src/ccd_adapter.cpp): the name a
// scene uses, what it answers, which pairs it serves and how it runs. CMake
// compiles an adapter only where its library is found
// (idcol_add_competitor in baselines/CMakeLists.txt) and generates the table
// from the adapters it compiled, so a build without FCL has no FCL rows and
// every name list (scene validation, messages, tables, replay) is this one.
//
//   const Competitor& c = competitor("ccd_mpr");   // throws naming the known ones
//   if (c.serves(body1, body2, &why)) { auto p = c.prepare(e1, e2); p->run(X_12); }
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "idcol/shapes.hpp"
#include "idcol_baselines/answer.hpp"
#include "idcol_baselines/exact_shape.hpp"

namespace idcol::baselines {

/// What a competitor's answer holds besides `intersect`, which every
/// competitor gives (the harness compares it with iDCOL's alpha* < 1).
struct Answers {
  bool signed_distance = false;  // BaselineAnswer::signed_distance when not intersecting (a gap)
  bool penetration = false;      // signed_distance, normal_1 and points when intersecting
  bool normal = false;           // normal_1 when separated as well
  bool alpha = false;            // BaselineAnswer::alpha and iterations (a method that solves for alpha*)
};

/// A competitor's state for one pair (its library's geometry), built once per
/// pair; a query is const and never throws (library errors come back as
/// BaselineAnswer::failed / threw).
class PreparedPair {
 public:
  virtual ~PreparedPair() = default;
  virtual BaselineAnswer run(const Pose& X_12) const = 0;
};

/// The PreparedPair of an adapter class `State` (constructed from both exact
/// bodies) and one of its queries: `&Prepared<FclPair, query>::make` is a
/// Competitor::prepare.
template <class State, BaselineAnswer (*Query)(const State&, const Pose&)>
class Prepared final : public PreparedPair {
 public:
  Prepared(const ExactShape& body1, const ExactShape& body2) : state_(body1, body2) {}
  BaselineAnswer run(const Pose& X_12) const override { return Query(state_, X_12); }
  static std::unique_ptr<PreparedPair> make(const ExactShape& body1, const ExactShape& body2) {
    return std::make_unique<Prepared>(body1, body2);
  }

 private:
  State state_;
};

/// One row of the table.
struct Competitor {
  const char* name;     // what a scene's [baselines] methods names; unique
  const char* label;    // row label in the results tables
  const char* library;  // the library and call, for messages and the README
  Answers answers;
  /// Which pairs it serves; if not, `why` names the body and the reason.
  bool (*serves)(const Shape& body1, const Shape& body2, std::string* why);
  /// How it runs: its per-pair state, from both exact bodies (exact_shape.hpp).
  std::unique_ptr<PreparedPair> (*prepare)(const ExactShape& body1, const ExactShape& body2);
};

/// Every competitor compiled into this build, in table order (the order of
/// idcol_add_competitor calls, then of each file's list).
const std::vector<const Competitor*>& competitors();
/// The competitor called `name`, or nullptr.
const Competitor* find_competitor(std::string_view name);
/// The competitor called `name`; throws std::invalid_argument
/// `unknown baseline "x" (known: a, b, ...)` otherwise.
const Competitor& competitor(std::string_view name);
/// "fcl_collide, fcl_distance, ..." in table order; "none in this build" if empty.
std::string competitor_names();

/// `serves` for the libraries that take exact bodies (FCL, libccd): both
/// bodies representable exactly (core_adapter.hpp), else why not.
bool serves_exact_bodies(const Shape& body1, const Shape& body2, std::string* why);

/// Library calls that aborted (an assertion inside the library, which prints
/// its own message on stderr before abort) and were trapped by an adapter
/// and counted as failed queries, since the process started.
std::uint64_t trapped_aborts();
/// Counts one (adapters call it from their trap).
void note_trapped_abort();

}  // namespace idcol::baselines

// The keys of results files, each spelled once. A figure's key is what its
// writer puts in the JSON, what its reader and merge look up, what the
// Markdown and the terminal summary print, and what its declared metric
// (studies/<kind>/<kind>_metrics.cpp) names: all of them use the constant,
// so a misspelt key is a compile error, not a missing number at run time.
// Keys written by more than one study kind, or by a layer below the study
// kinds (stats/, io/), live here; a key only one kind writes lives in that
// kind's folder (studies/<kind>/<kind>_keys.hpp). The test
// harness.metric_names checks that the key of every declared metric appears
// in one source file only (`idcol_harness metrics --keys` lists them).
#pragma once

#include <array>
#include <cstddef>
#include <string>

namespace idcol::harness::key {

// Summary statistics of a distribution or a count (mean, worst, tail, sum
// over the kinds of a failure).
inline constexpr char mean[] = "mean";
inline constexpr char max[] = "max";
inline constexpr char p99[] = "p99";
inline constexpr char total[] = "total";

// A pass's statistics (stats/stats.hpp), in sweeps and stress suites.
inline constexpr char convergence_rate[] = "convergence_rate";  // converged solves / solves
inline constexpr char failures[] = "failures";      // solves that did not converge (and the failure records' array, and the record)
inline constexpr char iterations[] = "iterations";  // Newton iterations per solve (and the record that keeps them)
inline constexpr char time[] = "time";              // per-solve times
inline constexpr char all[] = "all";                // ... of every solve
inline constexpr char median_ns[] = "median_ns";
inline constexpr char p99_ns[] = "p99_ns";
inline constexpr char checks[] = "checks";          // the answer checks (referee/checks.hpp)
inline constexpr char false_convergence[] = "false_convergence";  // converged solves a check refutes
inline constexpr char oracle_failed[] = "oracle_failed";          // an oracle that gave no answer
inline constexpr char worst_surface_error[] = "worst_surface_error";
inline constexpr char worst_normal_error[] = "worst_normal_error";
inline constexpr char worst_alpha_error[] = "worst_alpha_error";
inline constexpr char checked[] = "checked";        // answers a check or an oracle judged (fixed by the scene)
inline constexpr char solves[] = "solves";          // solves of a pass (fixed by the scene)
inline constexpr char poses[] = "poses";            // poses a pass or check covers (fixed by the scene)
inline constexpr char queries[] = "queries";        // queries a method was asked (fixed by the scene)
inline constexpr char genuine[] = "genuine";        // answers every check accepts
inline constexpr char wrong[] = "wrong";            // answers known to be wrong

// Derivatives against finite differences, in sweeps and stress suites.
inline constexpr char agreement[] = "agreement";
inline constexpr char disagree_unflagged[] = "disagree_unflagged";

/// The summary statistics: a metric whose key is one of these is named by
/// the key it summarises ("iterations" for "iterations.mean").
inline constexpr std::array<const char*, 4> kStatistics = {mean, max, p99, total};

/// Counts of work a scene fixes (solves of a pass, poses a check covers,
/// queries a method was asked, answers checked): guarded by compare (a change
/// either way fails), written through the constants above, but common words
/// that scene fields, scripts and examples use in their own senses, so
/// `idcol_harness metrics --keys` (and the test harness.metric_names that
/// reads it) leaves them out.
inline constexpr std::array<const char*, 4> kCountsOfWork = {solves, poses, checked, queries};

namespace detail {
constexpr std::size_t length(const char* s) { return *s ? 1 + length(s + 1) : 0; }
template <const char*... Parts>
struct Dotted {
  static constexpr std::size_t size = ((length(Parts) + 1) + ... + 0);  // with the dots and the terminating NUL
  static constexpr std::array<char, size> make() {
    std::array<char, size> out{};
    std::size_t i = 0;
    for (const char* p : {Parts...}) {
      if (i) out[i++] = '.';
      for (const char* c = p; *c; ++c) out[i++] = *c;
    }
    return out;
  }
  static constexpr std::array<char, size> value = make();
};
}  // namespace detail

/// The dotted path of nested keys, as a string of static storage (a metric's
/// name or path): dotted<iterations, mean> is "iterations.mean".
template <const char*... Parts>
inline constexpr const char* dotted = detail::Dotted<Parts...>::value.data();

}  // namespace idcol::harness::key

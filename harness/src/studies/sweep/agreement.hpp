// Agreement of iDCOL with the baselines and exact oracles, and of its
// derivatives with finite differences: the "baselines" and "derivatives"
// records of a scene. Statistics are counts, maxima and fixed-binned
// histograms, so shards merge like PassStats (the histogram sums, used only
// for means, depend on the order of addition in their last bits).
//
// Classification of a collision-status disagreement (iDCOL says alpha* < 1,
// a baseline says the other): the baselines answer for the *exact* geometry,
// iDCOL for the smoothed one, whose alpha* lies in the smoothing bracket
// [lo, hi] = [alpha_exact, alpha_exact / (1 - delta_max)] (oracles.hpp;
// lo = hi for exact ellipsoids). A disagreement is "band" (explained by
// smoothing or a tolerance) iff
//     lo (1 - tol) <= 1 <= hi (1 + tol),   tol = [baselines].band_tolerance,
// alpha_exact from the pair's oracle; otherwise it is "genuine" and becomes a
// failure record with a replay command.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/shapes.hpp"
#include "referee/methods.hpp"
#include "scene/scene.hpp"
#include "stats/stats.hpp"
#include "studies/sweep/sweep_spec.hpp"

namespace idcol::harness {

/// How one boolean answer compares with iDCOL's alpha* < 1 (the
/// classification above). The declaration order is the order of the counts.
enum class AgreementVerdict { Agree, Band, Genuine, Failed };
/// baseline_failed wins; then agreement; then "band" iff the oracle answered
/// and lo (1 - tol) - own <= 1 <= hi (1 + tol) + own; else (a NaN bracket
/// too) "genuine". `own` is the method's own bound on its alpha* where it
/// solves for alpha* to a tolerance (DCOL: BaselineAnswer::alpha_bound),
/// else 0.
AgreementVerdict classify_answer(bool idcol_collide, bool baseline_collide, bool baseline_failed, bool oracle_ok, double lo,
                                 double hi, double tol, double own = 0.0);
/// lo (1 - tol) <= alpha <= hi (1 + tol): iDCOL's alpha* inside the widened
/// smoothing bracket (false for NaN).
bool in_widened_bracket(double alpha, double lo, double hi, double tol);

/// Counts of one boolean method against iDCOL.
struct StatusAgreement {
  std::uint64_t queries = 0, agree = 0, band = 0, genuine = 0, failed = 0;
  /// The count of verdict v (agree, band, genuine or failed).
  std::uint64_t& of(AgreementVerdict v);
  void merge(const StatusAgreement& o);
  nlohmann::json to_json() const;
  static StatusAgreement from_json(const nlohmann::json& j);
};

/// What one method answers besides its boolean, compared at every pose
/// where it answered: its normal near contact (a method that gives one when
/// separated, registry.hpp's Answers::normal) against iDCOL's; its alpha* (a
/// method that solves for it, Answers::alpha: DCOL) against the exact
/// oracle's bracket and against iDCOL's smooth alpha*, with its iteration
/// count.
struct MethodAnswerStats {
  // Angle (rad) between iDCOL's nhat_1 and the method's normal, |alpha* - 1| <= near_contact.
  LogHistogram normal_angle{-12, 13, 20, true};
  std::uint64_t normal_poses = 0;
  // alpha: poses compared with the oracle; those off it by more than the
  // method's own bound (genuine); its distance from the oracle's bracket,
  // relative; its difference from iDCOL's alpha* (converged), relative.
  std::uint64_t alpha_poses = 0, alpha_outside_bound = 0;
  LogHistogram alpha_rel_err{-17, 17, 20, true}, alpha_rel_diff_idcol{-17, 17, 20, true};
  LogHistogram iterations{0, 2, 200, true};  // the method's own iterations (sums of integers: exact)
  bool empty() const { return normal_poses == 0 && alpha_poses == 0 && iterations.count() == 0; }
  void merge(const MethodAnswerStats& o);
  nlohmann::json to_json() const;
  static MethodAnswerStats from_json(const nlohmann::json& j);
};

struct AgreementStats {
  std::uint64_t poses = 0;
  std::uint64_t idcol_not_converged = 0;    // cold solves that did not converge (no comparison made)
  std::uint64_t oracle_failed = 0;          // oracle not ok (comparisons at that pose unclassified -> genuine)
  std::uint64_t idcol_outside_bracket = 0;  // iDCOL alpha* outside the widened smoothing bracket
  std::map<std::string, StatusAgreement> status;  // per boolean method; fcl_distance: sign of its distance
  // alpha* error against the oracle (converged iDCOL, ok oracle).
  LogHistogram alpha_abs_err{-17, 17, 20, true}, alpha_rel_err{-17, 17, 20, true};
  // Per method that answers more than a boolean (normals, alpha*).
  std::map<std::string, MethodAnswerStats> answers;
  // Timing subset: per method, time per query (ns) and the number of timed
  // poses on which the method's answer was wrong (checked before timing).
  std::uint64_t timed_poses = 0;
  std::map<std::string, LogHistogram> time;
  std::map<std::string, std::uint64_t> timed_wrong;
  double timing_cpu_seconds = 0.0, timing_wall_seconds = 0.0;

  void merge(const AgreementStats& o);
  nlohmann::json to_json() const;
  static AgreementStats from_json(const nlohmann::json& j);
};

struct DerivativeStats {
  std::uint64_t poses = 0, converged = 0, fd_failed = 0, agree = 0, disagree_flagged = 0, disagree_unflagged = 0,
                flagged = 0;
  double worst_error = 0.0;  // over unflagged poses
  std::uint64_t worst_k = 0;
  double agreement() const;  // agree / (converged - fd_failed)
  void merge(const DerivativeStats& o);
  nlohmann::json to_json() const;
  static DerivativeStats from_json(const nlohmann::json& j);
};

/// Runs the agreement pass of pair (i1, i2) over poses [lo, hi) of the shard
/// (threads > 1 splits the correctness part; timing runs on one thread after
/// it). Genuine disagreements are appended to `failures` (without index and
/// replay, which the runner adds).
AgreementStats run_agreement(const Scene& scene, int i1, int i2, std::uint64_t lo, std::uint64_t hi, int threads,
                             double timer_overhead_ns, nlohmann::json& failures);

/// check_derivatives on poses k in [lo, hi) with k % every == 0; unflagged
/// disagreements go to `failures`.
DerivativeStats run_derivatives(const Scene& scene, int i1, int i2, std::uint64_t lo, std::uint64_t hi, int threads,
                                nlohmann::json& failures);

/// Replays a failure record of kind "baseline_disagreement" or
/// "derivative_disagreement": prints what each side says now; 0 if the
/// disagreement is reproduced.
int replay_agreement_record(const nlohmann::json& failure, const Shape& b1, const Shape& b2, const SolverOptions& opt);

namespace detail {
/// The head of an agreement failure record (pair, pose, kind, time).
nlohmann::json failure_head(const Scene& scene, int i1, int i2, std::uint64_t k, const Pose& X, const char* kind);
/// The replay of a "baseline_disagreement" record: agreement_baselines.cpp,
/// or agreement_none.cpp in a build without baselines.
int replay_baseline_disagreement(const Pose& X, const Shape& b1, const Shape& b2, const SolverOptions& opt);
}  // namespace detail

}  // namespace idcol::harness

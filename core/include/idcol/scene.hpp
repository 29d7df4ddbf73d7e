// A scene of many bodies: world poses in, contacts out, each with its
// wrench and, on request, the wrench's Jacobians with respect to both
// bodies' poses (Sec. "Differentiable Contact Physics", eq:contactmodel,
// eq:contact_wrench, eq:dFc1_dq, eq:dFc2_dq).
//
// One call of Scene::update is one evaluation of the contact forces of a
// simulation's state:
//
//  1. the broad phase (broad_phase.hpp) finds the pairs i < j whose outer
//     spheres overlap at the given poses;
//  2. the narrow phase solves them all in one solve_batch call (batch.hpp),
//     one row per pair, each row warm-started from that pair's state of the
//     previous call (the scene keeps one WarmStart per pair, keyed by (i, j);
//     a pair that leaves the broad phase's list loses its state);
//  3. each row's contact is mapped to the world and to the two bodies.
//
// Frames and signs (all of derivatives.hpp's conventions): pair (i, j) is
// solved as body 1 = i, body 2 = j at X_12 = X_Wi^{-1} X_Wj. The force
// f_n = k delta^p, delta = -gap (HertzModel), acts at x* against body i's
// outward normal: F1_1 is the wrench on body i in body-i coordinates about
// body i's origin, F2_2 = -Ad_{X_12}^T F1_1 the equal and opposite one on
// body j in body-j coordinates about j's origin, both ordered (moment,
// force). Their sum in world coordinates is zero (test_scene.cpp).
//
// The Jacobians are with respect to the body twists xi_i, xi_j of the world
// poses, perturbed on the right (X_Wi -> X_Wi exp(xi_i^), xi = (w, v), as in
// derivatives.hpp): d F / d(xi_i, xi_j), 6 x 12, columns (w_i, v_i, w_j,
// v_j), from dF/dxi of the relative pose by dxi = -Ad_{X_12^{-1}} xi_i + xi_j
// (relative_twist_jacobians).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "idcol/batch.hpp"
#include "idcol/broad_phase.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/options.hpp"
#include "idcol/shapes.hpp"

namespace idcol {

struct SceneOptions {
  /// The narrow phase's options. The default differs from SolverOptions'
  /// in one field: alpha_max = 1, so that a pair whose certified lower
  /// bound on alpha* exceeds 1 (apart, though the outer spheres overlap)
  /// stops before any Newton step, with status Separated and no force: the
  /// contact law needs nothing of a separated pair. (+inf: every candidate
  /// is solved and its gap reported.)
  SolverOptions solver = [] {
    SolverOptions o;
    o.alpha_max = 1.0;
    return o;
  }();
  /// The contact law (eq:contactmodel).
  HertzModel contact;
  BroadPhaseMethod broad_phase = BroadPhaseMethod::Auto;
  /// Warm-start each pair from its previous call.
  bool warm_start = true;
  /// Threads of the narrow phase's batch (BatchOptions::threads; 0 = all).
  int threads = 1;
  /// The narrow phase's batch in SIMD lanes (BatchOptions::simd): the rows
  /// of bodies of the same two kinds (equal shapes, which the scene solves
  /// with one shape object) W at a time. The same contacts to the bit. Off
  /// by default: a scene's warm steps take a Newton step or two a pair, and
  /// with alpha_max = 1 most candidates stop at once, whose outputs cost
  /// the same writes whichever path answers them, so on the box scene the
  /// lanes run the narrow phase at 1.2-1.45x the loop's speed at 1,000 and
  /// 10,000 bodies and lose a little at 100, where a pair of kinds has
  /// about five rows (results/multibody_scaling.json, both ways side by
  /// side); they pay most on cold rows (core/bench/bench_sim_batch.cpp).
  bool simd = false;
  /// Throws std::invalid_argument naming the field and the value.
  void validate() const;
};

/// The contact of one candidate pair at the poses of the last update.
/// Invariants (status Converged): gap = (1 - 1/alpha)|r|, active iff gap <
/// 0; f_n = k (-gap)^p when active, else 0; F1_1 = -[x_1~ n_1; n_1] f_n with
/// x_1, n_1 the body-1 (body i) coordinates of x_W, normal_W; and
/// Ad_{X_Wi^{-1}}^T F1_1 + Ad_{X_Wj^{-1}}^T F2_2 = 0 (the world wrenches).
struct Contact {
  std::int32_t body1 = 0;  // i
  std::int32_t body2 = 0;  // j > i
  SolveStatus status = SolveStatus::InvalidInput;
  int iterations = 0;
  bool warm_started = false;  // the pair had a warm state from the last update
  /// Converged with gap < 0: a force acts.
  bool active = false;
  double alpha = 0.0;        // alpha* (Separated: the certified bound); NaN for a failed solve
  double gap = 0.0;          // (1 - 1/alpha*)|r|; NaN unless Converged
  Vec3 x_W = Vec3::Zero();   // x*, where the force acts (world); NaN unless Converged
  Vec3 normal_W = Vec3::Zero();  // body i's outward unit normal at the contact (world); NaN unless Converged
  double f_n = 0.0;
  Vec6 F1_1 = Vec6::Zero();  // on body i, body-i frame, about its origin: (moment, force)
  Vec6 F2_2 = Vec6::Zero();  // on body j, body-j frame, about its origin
  /// Where this contact's wrench Jacobians are in Scene::jacobians(): set
  /// when the update asked for derivatives and the contact is active, else
  /// -1 (the wrench does not change: zero).
  std::int32_t jacobian = -1;
  /// Whether the solve answered: Converged, or Separated with
  /// SolverOptions::alpha_max >= 1 (certainly apart). Otherwise the force
  /// is unknown and f_n, F1_1, F2_2 hold NaN.
  bool ok = false;
};

/// The Jacobians of an active contact's wrenches w.r.t. both bodies'
/// poses: d F1_1 / d(xi_i, xi_j) and d F2_2 / d(xi_i, xi_j), 6 x 12, columns
/// (w_i, v_i, w_j, v_j). Kept apart from Contact, for the active contacts
/// only: they are a kilobyte each, and most candidates of a large scene are
/// not touching.
struct ContactJacobian {
  Mat6x12 dF1 = Mat6x12::Zero();
  Mat6x12 dF2 = Mat6x12::Zero();
};

/// What the last update cost and found.
struct SceneUpdateStats {
  std::size_t candidates = 0;  // pairs from the broad phase (= narrow-phase rows)
  std::size_t active = 0;      // contacts with a force
  std::size_t failed = 0;      // rows whose force is unknown (!Contact::ok)
  std::size_t separated = 0;   // rows stopped by alpha_max before any Newton step
  long newton_iterations = 0;  // over every row
  double broad_seconds = 0.0;
  double narrow_seconds = 0.0;  // the batch call and the mapping to the world
};

class Scene {
 public:
  explicit Scene(SceneOptions options = {});

  /// Adds a body; returns its index (0, 1, ...).
  int add_body(Shape shape);
  int num_bodies() const { return static_cast<int>(shapes_.size()); }
  const Shape& shape(int i) const { return shapes_.at(static_cast<std::size_t>(i)); }
  /// radii(shape).outer: the bounding sphere's radius about the frame origin.
  double outer_radius(int i) const { return outer_.at(static_cast<std::size_t>(i)); }
  const SceneOptions& options() const { return options_; }

  /// Broad phase and narrow phase at the world poses X_W (one per body,
  /// body i at X_W[i]); with `derivatives`, each active contact's wrench
  /// Jacobians (jacobians()).
  /// Throws std::invalid_argument if X_W.size() != num_bodies() or a pose
  /// is not a rigid transform (naming the body and why). Returns contacts(),
  /// every candidate pair, sorted by (body1, body2).
  const std::vector<Contact>& update(const std::vector<Pose>& X_W, bool derivatives = false);
  const std::vector<Contact>& contacts() const { return contacts_; }
  /// The wrench Jacobians of the last update's active contacts
  /// (Contact::jacobian indexes them); empty without derivatives.
  const std::vector<ContactJacobian>& jacobians() const { return jacobians_; }
  const SceneUpdateStats& last_stats() const { return stats_; }

  /// The total wrench on each body from the contacts of the last update, in
  /// its own frame about its origin (moment, force): F[i] = sum of F1_1 over
  /// the contacts with body1 = i and of F2_2 over those with body2 = i.
  void body_wrenches(std::vector<Vec6>& F) const;

  /// Forgets every pair's warm start (the next update is cold).
  void reset_warm_starts() { warm_.clear(); }

 private:
  struct WarmEntry {
    BodyPair pair;
    WarmStart warm;
  };
  void solve_rows(const std::vector<BodyPair>& pairs, const std::vector<Pose>& X_W, bool derivatives);
  void to_contact(std::size_t k, const BodyPair& pr, const std::vector<Pose>& X_W, bool derivatives, Contact& c);

  SceneOptions options_;
  std::vector<Shape> shapes_;
  // Body i's rows are solved with shapes_[same_[i]], the first body whose
  // shape equals its own (same_shape): rows of bodies of one kind are then
  // rows of one pair, which solve_batch runs in SIMD lanes.
  std::vector<std::size_t> same_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> kinds_;  // first bodies of each kind, by shape hash
  std::vector<double> outer_;
  BroadPhase broad_;
  std::vector<BoundingSphere> spheres_;
  std::vector<WarmEntry> warm_;  // sorted by pair: the candidates of the last update
  std::vector<Contact> contacts_;
  std::vector<ContactJacobian> jacobians_;
  SceneUpdateStats stats_;
  // Narrow-phase rows, sized to the candidates (kept between updates).
  std::vector<const Shape*> b1_, b2_;
  std::vector<Pose> X12_;
  std::vector<WarmStart> row_warm_;
  std::vector<unsigned char> warm_in_;  // row k had a valid warm state
  std::vector<double> alpha_, x_, dalpha_, gap_, normal_, f_n_, F1_, F2_, dF1_, dF2_;
  std::vector<std::int32_t> status_, iterations_;
};

}  // namespace idcol

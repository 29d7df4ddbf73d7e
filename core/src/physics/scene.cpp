#include "idcol/scene.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "idcol/shape_params.hpp"

namespace idcol {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Row k's 6 x 6 row-major block of a batch output, as a matrix.
Mat6 block6(const std::vector<double>& v, std::size_t k) {
  return Eigen::Map<const Mat6r>(v.data() + 36 * k);
}

/// Whether two shapes are the same body: the same family, and every
/// parameter (shape_params) the same to the bit; a smooth polytope's
/// rounding length and vertices too. Such shapes give every query the
/// same answer.
bool same_shape(const Shape& a, const Shape& b) {
  if (a.index() != b.index()) return false;
  auto bits = [](const double* x, const double* y, std::size_t n) { return n == 0 || std::memcmp(x, y, n * sizeof(double)) == 0; };
  const VecX pa = shape_params(a), pb = shape_params(b);
  if (pa.size() != pb.size() || !bits(pa.data(), pb.data(), static_cast<std::size_t>(pa.size()))) return false;
  const SmoothPolytope* qa = std::get_if<SmoothPolytope>(&a);
  if (!qa) return true;
  const SmoothPolytope& qb = std::get<SmoothPolytope>(b);
  const double la = qa->L(), lb = qb.L();
  return qa->vertices().size() == qb.vertices().size() && bits(&la, &lb, 1) &&
         bits(qa->vertices().data()->data(), qb.vertices().data()->data(), 3 * qa->vertices().size());
}

/// A hash of what same_shape compares first: the family and the
/// parameters' bits (FNV-1a).
std::uint64_t shape_hash(const Shape& s) {
  std::uint64_t h = 1469598103934665603ull ^ s.index();
  const VecX p = shape_params(s);
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    std::uint64_t b;
    std::memcpy(&b, &p[i], sizeof b);
    h = (h ^ b) * 1099511628211ull;
  }
  return h;
}

}  // namespace

void SceneOptions::validate() const {
  solver.validate();
  contact.validate();
  if (threads < 0)
    throw std::invalid_argument("SceneOptions: field 'threads' must be >= 0 (0 = all CPUs), got " +
                                std::to_string(threads));
}

Scene::Scene(SceneOptions options) : options_(options), broad_(options.broad_phase) { options_.validate(); }

int Scene::add_body(Shape shape) {
  if (shapes_.size() >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument("Scene::add_body: the scene is full (2^31 - 1 bodies)");
  outer_.push_back(radii(shape).outer);
  std::size_t same = shapes_.size();
  std::vector<std::size_t>& kin = kinds_[shape_hash(shape)];  // the kinds of this hash
  for (const std::size_t k : kin)
    if (same_shape(shapes_[k], shape)) {
      same = k;
      break;
    }
  if (same == shapes_.size()) kin.push_back(same);
  same_.push_back(same);
  shapes_.push_back(std::move(shape));
  return static_cast<int>(shapes_.size()) - 1;
}

const std::vector<Contact>& Scene::update(const std::vector<Pose>& X_W, bool derivatives) {
  if (X_W.size() != shapes_.size())
    throw std::invalid_argument("Scene::update: " + std::to_string(X_W.size()) + " poses for " +
                                std::to_string(shapes_.size()) + " bodies");
  for (std::size_t i = 0; i < X_W.size(); ++i) {
    const PoseCheck c = check_pose(X_W[i]);
    if (c != PoseCheck::Ok)
      throw std::invalid_argument("Scene::update: the pose of body " + std::to_string(i) + " is bad: " + to_string(c));
  }
  stats_ = SceneUpdateStats{};
  const auto t0 = std::chrono::steady_clock::now();
  spheres_.resize(shapes_.size());
  for (std::size_t i = 0; i < shapes_.size(); ++i) spheres_[i] = {X_W[i].p, outer_[i]};
  const std::vector<BodyPair>& pairs = broad_.find(spheres_);
  stats_.broad_seconds = seconds_since(t0);
  stats_.candidates = pairs.size();

  const auto t1 = std::chrono::steady_clock::now();
  solve_rows(pairs, X_W, derivatives);
  stats_.narrow_seconds = seconds_since(t1);
  return contacts_;
}

/// The narrow phase of the broad phase's pairs: one batch call, then each
/// row to a Contact, and the warm states kept for the next call.
void Scene::solve_rows(const std::vector<BodyPair>& pairs, const std::vector<Pose>& X_W, bool derivatives) {
  const std::size_t n = pairs.size();
  b1_.resize(n);
  b2_.resize(n);
  X12_.resize(n);
  row_warm_.resize(n);
  warm_in_.resize(n);
  // Each row's warm state: the pair's entry of the last call (both lists
  // are sorted by pair, so one merge finds them all).
  std::size_t w = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const BodyPair& pr = pairs[k];
    b1_[k] = &shapes_[same_[pr.i]];
    b2_[k] = &shapes_[same_[pr.j]];
    X12_[k] = X_W[pr.i].inverse() * X_W[pr.j];
    while (w < warm_.size() && warm_[w].pair < pr) ++w;
    if (options_.warm_start && w < warm_.size() && warm_[w].pair == pr) row_warm_[k] = warm_[w].warm;
    else row_warm_[k].reset();
    warm_in_[k] = row_warm_[k].valid ? 1 : 0;
  }
  alpha_.resize(n);
  x_.resize(3 * n);
  status_.resize(n);
  iterations_.resize(n);
  gap_.resize(n);
  normal_.resize(3 * n);
  f_n_.resize(n);
  F1_.resize(6 * n);
  F2_.resize(6 * n);
  dalpha_.resize(derivatives ? 6 * n : 0);  // the batch fills it whenever derivatives are on
  dF1_.resize(derivatives ? 36 * n : 0);
  dF2_.resize(derivatives ? 36 * n : 0);
  BatchOptions o;
  o.solver = options_.solver;
  o.derivatives = derivatives;
  o.contact = options_.contact;
  o.threads = options_.threads;
  o.simd = options_.simd;
  BatchOutput out;
  out.alpha = alpha_;
  out.x_1 = x_;
  out.status = status_;
  out.iterations = iterations_;
  out.dalpha_dxi = dalpha_;
  out.gap = gap_;
  out.normal_1 = normal_;
  out.warm = row_warm_;
  out.f_n = f_n_;
  out.F1_1 = F1_;
  out.F2_2 = F2_;
  out.dF1_dxi = dF1_;
  out.dF2_dxi = dF2_;
  if (n > 0) solve_batch(b1_, b2_, Span<const Pose>(X12_.data(), n), o, out);

  contacts_.resize(n);
  jacobians_.clear();
  warm_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    to_contact(k, pairs[k], X_W, derivatives, contacts_[k]);
    const Contact& c = contacts_[k];
    warm_[k] = {pairs[k], row_warm_[k]};
    stats_.active += c.active ? 1 : 0;
    stats_.failed += c.ok ? 0 : 1;
    stats_.separated += c.status == SolveStatus::Separated ? 1 : 0;
    stats_.newton_iterations += c.iterations;
  }
}

/// Row k of the batch as a Contact of bodies (i, j) = pr.
void Scene::to_contact(std::size_t k, const BodyPair& pr, const std::vector<Pose>& X_W, bool derivatives,
                       Contact& c) {
  const Pose& X_W1 = X_W[pr.i];
  c.body1 = pr.i;
  c.body2 = pr.j;
  c.status = static_cast<SolveStatus>(status_[k]);
  c.iterations = iterations_[k];
  c.warm_started = warm_in_[k] != 0;
  c.alpha = alpha_[k];
  c.gap = gap_[k];
  const Vec3 x_1(x_[3 * k], x_[3 * k + 1], x_[3 * k + 2]);
  const Vec3 n_1(normal_[3 * k], normal_[3 * k + 1], normal_[3 * k + 2]);
  const bool converged = c.status == SolveStatus::Converged;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.x_W = converged ? Vec3(X_W1.R * x_1 + X_W1.p) : Vec3::Constant(nan);
  c.normal_W = converged ? Vec3(X_W1.R * n_1) : Vec3::Constant(nan);
  c.f_n = f_n_[k];
  c.F1_1 = Eigen::Map<const Vec6>(F1_.data() + 6 * k);
  c.F2_2 = Eigen::Map<const Vec6>(F2_.data() + 6 * k);
  c.ok = converged || (c.status == SolveStatus::Separated && options_.solver.alpha_max >= 1.0);
  c.active = converged && c.gap < 0.0;  // contact_wrench's delta > 0
  c.jacobian = -1;
  if (!derivatives || !c.active) return;
  // dxi = -Ad_{X_12^{-1}} xi_i + xi_j (relative_twist_jacobians).
  Mat6 dxi_dxi1, dxi_dxi2;
  relative_twist_jacobians(X12_[k], dxi_dxi1, dxi_dxi2);
  const Mat6 dF1 = block6(dF1_, k), dF2 = block6(dF2_, k);
  c.jacobian = static_cast<std::int32_t>(jacobians_.size());
  ContactJacobian& J = jacobians_.emplace_back();
  J.dF1.leftCols<6>() = dF1 * dxi_dxi1;
  J.dF1.rightCols<6>() = dF1;
  J.dF2.leftCols<6>() = dF2 * dxi_dxi1;
  J.dF2.rightCols<6>() = dF2;
}

void Scene::body_wrenches(std::vector<Vec6>& F) const {
  F.assign(shapes_.size(), Vec6::Zero());
  for (const Contact& c : contacts_) {
    if (!c.active) continue;
    F[c.body1] += c.F1_1;
    F[c.body2] += c.F2_2;
  }
}

}  // namespace idcol

#include "idcol/convex_hull.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

namespace idcol {
namespace {

struct Tri {
  int v[3];
  Vec3 n;
  double d;
  bool alive;
};

Tri make_tri(const std::vector<Vec3>& P, int a, int b, int c, const Vec3& interior) {
  Tri t{{a, b, c}, Vec3::Zero(), 0.0, true};
  Vec3 n = (P[b] - P[a]).cross(P[c] - P[a]);
  const double len = n.norm();
  n = len > 0.0 ? Vec3(n / len) : Vec3::Zero();
  double d = n.dot(P[a]);
  if (n.dot(interior) > d) {  // make it outward
    std::swap(t.v[1], t.v[2]);
    n = -n;
    d = -d;
  }
  t.n = n;
  t.d = d;
  return t;
}

std::uint64_t edge_key(int a, int b) { return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b); }

}  // namespace

ConvexHull convex_hull(const std::vector<Vec3>& P, const char* what, double rel_eps) {
  const int N = static_cast<int>(P.size());
  if (N < 4) {
    std::ostringstream os;
    os << what << ": a convex polytope needs at least 4 points, got " << N;
    throw std::invalid_argument(os.str());
  }
  double scale = 0.0;
  for (int i = 0; i < N; ++i) {
    if (!P[i].allFinite()) {
      std::ostringstream os;
      os.precision(17);
      os << what << "[" << i << "] = (" << P[i].transpose() << ") is not finite";
      throw std::invalid_argument(os.str());
    }
    scale = std::max(scale, P[i].cwiseAbs().maxCoeff());
  }
  const double eps = rel_eps * std::max(scale, 1e-300);
  auto degenerate = [&]() {
    std::ostringstream os;
    os << what << ": all " << N << " points are coplanar (or collinear); the polytope has no interior";
    throw std::invalid_argument(os.str());
  };

  // Initial tetrahedron from extreme points.
  int i0 = 0;
  for (int i = 1; i < N; ++i)
    if (P[i].x() < P[i0].x()) i0 = i;
  int i1 = -1;
  double best = 0.0;
  for (int i = 0; i < N; ++i) {
    const double dd = (P[i] - P[i0]).norm();
    if (dd > best) best = dd, i1 = i;
  }
  if (i1 < 0 || best <= eps) degenerate();
  const Vec3 dir01 = (P[i1] - P[i0]).normalized();
  int i2 = -1;
  best = 0.0;
  for (int i = 0; i < N; ++i) {
    const double dd = (P[i] - P[i0]).cross(dir01).norm();
    if (dd > best) best = dd, i2 = i;
  }
  if (i2 < 0 || best <= eps) degenerate();
  const Vec3 n012 = (P[i1] - P[i0]).cross(P[i2] - P[i0]).normalized();
  int i3 = -1;
  best = 0.0;
  for (int i = 0; i < N; ++i) {
    const double dd = std::abs(n012.dot(P[i] - P[i0]));
    if (dd > best) best = dd, i3 = i;
  }
  if (i3 < 0 || best <= eps) degenerate();

  const Vec3 interior = (P[i0] + P[i1] + P[i2] + P[i3]) / 4.0;
  std::vector<Tri> tris;
  tris.push_back(make_tri(P, i0, i1, i2, interior));
  tris.push_back(make_tri(P, i0, i1, i3, interior));
  tris.push_back(make_tri(P, i0, i2, i3, interior));
  tris.push_back(make_tri(P, i1, i2, i3, interior));

  std::vector<int> visible;
  std::unordered_set<std::uint64_t> edges;
  std::vector<std::pair<int, int>> horizon;
  for (int p = 0; p < N; ++p) {
    if (p == i0 || p == i1 || p == i2 || p == i3) continue;
    visible.clear();
    for (int t = 0; t < static_cast<int>(tris.size()); ++t)
      if (tris[t].alive && tris[t].n.dot(P[p]) - tris[t].d > eps) visible.push_back(t);
    if (visible.empty()) continue;
    edges.clear();
    for (int t : visible)
      for (int k = 0; k < 3; ++k) edges.insert(edge_key(tris[t].v[k], tris[t].v[(k + 1) % 3]));
    horizon.clear();
    for (int t : visible)
      for (int k = 0; k < 3; ++k) {
        const int a = tris[t].v[k], b = tris[t].v[(k + 1) % 3];
        if (!edges.count(edge_key(b, a))) horizon.emplace_back(a, b);
      }
    for (int t : visible) tris[t].alive = false;
    for (auto [a, b] : horizon) tris.push_back(make_tri(P, a, b, p, interior));
  }

  ConvexHull hull;
  std::vector<char> used(N, 0);
  for (const Tri& t : tris) {
    if (!t.alive) continue;
    hull.triangles.push_back({t.v[0], t.v[1], t.v[2]});
    for (int k = 0; k < 3; ++k) used[t.v[k]] = 1;
  }
  for (int i = 0; i < N; ++i)
    if (used[i]) hull.vertex_indices.push_back(i);

  // Merge coplanar triangles: a convex polytope has one face per outward normal.
  const double ntol = 1e-9;
  for (const Tri& t : tris) {
    if (!t.alive) continue;
    HullFace* f = nullptr;
    for (HullFace& g : hull.faces)
      if ((g.normal - t.n).norm() < ntol) f = &g;
    if (!f) {
      hull.faces.push_back(HullFace{t.n, 0.0, {}});
      f = &hull.faces.back();
    }
    for (int k = 0; k < 3; ++k)
      if (std::find(f->vertices.begin(), f->vertices.end(), t.v[k]) == f->vertices.end()) f->vertices.push_back(t.v[k]);
  }
  // Order each face's vertices counter-clockwise about its normal, keeping only
  // the corners of the face polygon (2-D hull in the face plane).
  for (HullFace& f : hull.faces) {
    double off = 0.0;
    for (int v : f.vertices) off += f.normal.dot(P[v]);
    f.offset = off / static_cast<double>(f.vertices.size());
    const Vec3 e1 = (std::abs(f.normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(f.normal).normalized();
    const Vec3 e2 = f.normal.cross(e1);
    std::vector<std::pair<Eigen::Vector2d, int>> pts;
    for (int v : f.vertices) pts.push_back({Eigen::Vector2d(e1.dot(P[v]), e2.dot(P[v])), v});
    std::sort(pts.begin(), pts.end(), [](const auto& A, const auto& B) {
      return A.first.x() < B.first.x() || (A.first.x() == B.first.x() && A.first.y() < B.first.y());
    });
    auto cross2 = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
    };
    const double aeps = eps * std::max(scale, 1e-300);
    std::vector<std::pair<Eigen::Vector2d, int>> H(2 * pts.size());
    int k = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      while (k >= 2 && cross2(H[k - 2].first, H[k - 1].first, pts[i].first) <= aeps) --k;
      H[k++] = pts[i];
    }
    for (int i = static_cast<int>(pts.size()) - 2, t = k + 1; i >= 0; --i) {
      while (k >= t && cross2(H[k - 2].first, H[k - 1].first, pts[i].first) <= aeps) --k;
      H[k++] = pts[i];
    }
    f.vertices.clear();
    for (int i = 0; i < k - 1; ++i) f.vertices.push_back(H[i].second);
  }
  return hull;
}

}  // namespace idcol

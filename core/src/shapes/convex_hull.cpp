#include "idcol/convex_hull.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace idcol {
namespace {

// One triangle of the hull under construction, outward normal n, plane
// n^T x = d, with the input points strictly above it (its outside set).
struct Tri {
  std::array<int, 3> v;
  Vec3 n;
  double d;
  bool alive;
  std::vector<int> outside;
};

Tri make_tri(const std::vector<Vec3>& P, int a, int b, int c) {
  Vec3 n = (P[b] - P[a]).cross(P[c] - P[a]);
  const double len = n.norm();
  n = len > 0.0 ? Vec3(n / len) : Vec3::Zero();
  return Tri{{a, b, c}, n, n.dot(P[a]), true, {}};
}

std::uint64_t edge_key(int a, int b) { return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b); }

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

// Long: its phases (scaling, the first tetrahedron, quickhull, merging coplanar
// triangles, the faces out) run once, in order, over one triangle list and
// its edge owners; split, each would take them all.
ConvexHull convex_hull(const std::vector<Vec3>& P_in, const char* what, double rel_eps) {
  const int N = static_cast<int>(P_in.size());
  const std::vector<Vec3>& P = P_in;
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
  // Points beyond 2^64 or within 2^-64 (in largest coordinate): the hull in
  // units of a power of two near that coordinate (exact, away from
  // subnormals); squared lengths and cross
  // products of points of 1e100 or 1e-160 leave the double range, which made
  // a valid cube "coplanar". Offsets are scaled back at the end.
  const int unit_exp = scale > 0x1p64 || (scale > 0.0 && scale < 0x1p-64) ? std::ilogb(scale) : 0;
  if (unit_exp != 0) {
    std::vector<Vec3> Q(P_in);
    for (Vec3& q : Q) q = Vec3(std::ldexp(q.x(), -unit_exp), std::ldexp(q.y(), -unit_exp), std::ldexp(q.z(), -unit_exp));
    ConvexHull h = convex_hull(Q, what, rel_eps);
    for (HullFace& face : h.faces) face.offset = std::ldexp(face.offset, unit_exp);
    return h;
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

  // Quickhull: every point outside the hull so far belongs to the outside set
  // of one triangle it is above; a triangle with a non-empty set is replaced
  // by the cone from its farthest point over the horizon of the triangles that
  // point sees. Triangles find their neighbours through the owner of each
  // directed edge (edge a->b of one triangle is b->a of its neighbour).
  std::vector<Tri> tris;
  std::unordered_map<std::uint64_t, int> owner;
  auto add_tri = [&](int a, int b, int c) {
    tris.push_back(make_tri(P, a, b, c));
    const int id = static_cast<int>(tris.size()) - 1;
    owner[edge_key(a, b)] = id;
    owner[edge_key(b, c)] = id;
    owner[edge_key(c, a)] = id;
  };
  auto above = [&](const Tri& t, int p) { return t.n.dot(P[p]) - t.d; };
  // The triangle across edge k (from corner k to corner k + 1) of t.
  auto neighbour = [&](int t, int k) { return owner.at(edge_key(tris[t].v[(k + 1) % 3], tris[t].v[k])); };
  // Into the outside set of the triangle among [first, tris.size()) that p is
  // farthest above; dropped if it is above none (it is inside the hull).
  auto assign = [&](int p, std::size_t first) {
    int bt = -1;
    double bd = eps;
    for (std::size_t t = first; t < tris.size(); ++t) {
      const double dd = above(tris[t], p);
      if (dd > bd) bd = dd, bt = static_cast<int>(t);
    }
    if (bt >= 0) tris[bt].outside.push_back(p);
  };

  // The tetrahedron, each face wound outward (counter-clockwise seen from
  // outside): if i3 is above the plane of (i0, i1, i2), that face is reversed.
  if (n012.dot(P[i3] - P[i0]) > 0.0) std::swap(i1, i2);
  add_tri(i0, i1, i2);
  add_tri(i0, i3, i1);
  add_tri(i1, i3, i2);
  add_tri(i2, i3, i0);
  for (int p = 0; p < N; ++p)
    if (p != i0 && p != i1 && p != i2 && p != i3) assign(p, 0);

  std::vector<int> mark;  // mark[t] == round: t is visible in this round
  std::vector<int> visible, stack, pending, starts;
  std::vector<std::pair<int, int>> horizon;
  int round = 0;
  for (std::size_t f = 0; f < tris.size(); ++f) {
    if (!tris[f].alive || tris[f].outside.empty()) continue;
    int eye = tris[f].outside[0];
    for (int p : tris[f].outside)
      if (above(tris[f], p) > above(tris[f], eye)) eye = p;
    ++round;
    mark.resize(tris.size(), 0);
    visible.clear();
    stack.assign(1, static_cast<int>(f));
    mark[f] = round;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      visible.push_back(t);
      for (int k = 0; k < 3; ++k) {
        const int u = neighbour(t, k);
        if (mark[u] != round && above(tris[u], eye) > eps) {
          mark[u] = round;
          stack.push_back(u);
        }
      }
    }
    horizon.clear();
    for (int t : visible)
      for (int k = 0; k < 3; ++k)
        if (mark[neighbour(t, k)] != round) horizon.emplace_back(tris[t].v[k], tris[t].v[(k + 1) % 3]);
    // Each horizon vertex must start one horizon edge only, or two cone
    // triangles would own the same edge from the eye.
    starts.clear();
    for (auto [a, b] : horizon) starts.push_back(a);
    std::sort(starts.begin(), starts.end());
    if (std::adjacent_find(starts.begin(), starts.end()) != starts.end()) {
      std::ostringstream os;
      os << what << ": the hull of these " << N << " points is numerically degenerate (point " << eye
         << " sees a region of the hull that is not a disc)";
      throw std::invalid_argument(os.str());
    }
    pending.clear();
    for (int t : visible) {
      tris[t].alive = false;
      for (int p : tris[t].outside)
        if (p != eye) pending.push_back(p);
      std::vector<int>().swap(tris[t].outside);
    }
    const std::size_t first = tris.size();
    for (auto [a, b] : horizon) add_tri(a, b, eye);
    for (int p : pending) assign(p, first);
  }

  // Merge coplanar triangles (a convex polytope has one face per outward
  // normal): neighbours whose normals agree to 1e-9 share a face.
  const int T = static_cast<int>(tris.size());
  std::vector<int> parent(T);
  std::iota(parent.begin(), parent.end(), 0);
  const double ntol = 1e-9;
  for (int t = 0; t < T; ++t) {
    if (!tris[t].alive) continue;
    for (int k = 0; k < 3; ++k) {
      const int u = neighbour(t, k);
      if ((tris[t].n - tris[u].n).norm() < ntol) parent[find_root(parent, u)] = find_root(parent, t);
    }
  }
  std::vector<int> face_of_root(T, -1);
  std::vector<std::vector<int>> corners;  // each face's points, then its corners
  std::vector<Vec3> approx_normal;
  for (int t = 0; t < T; ++t) {
    if (!tris[t].alive) continue;
    int& face = face_of_root[find_root(parent, t)];
    if (face < 0) {
      face = static_cast<int>(corners.size());
      corners.emplace_back();
      approx_normal.push_back(tris[t].n);
    }
    for (int v : tris[t].v) corners[face].push_back(v);
  }

  // Each face's corners, counter-clockwise about its normal (the 2-D hull in
  // the face plane drops points on its edges), from its smallest index; its
  // normal by Newell's formula over them. The faces are sorted by their
  // corner lists, so that the output depends only on the polytope and the
  // numbering of its points.
  ConvexHull hull;
  const double aeps = eps * std::max(scale, 1e-300);
  auto cross2 = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  for (std::size_t g = 0; g < corners.size(); ++g) {
    std::vector<int>& vs = corners[g];
    std::sort(vs.begin(), vs.end());
    vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    const Vec3& n0 = approx_normal[g];
    const Vec3 e1 = (std::abs(n0.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n0).normalized();
    const Vec3 e2 = n0.cross(e1);
    std::vector<std::pair<Eigen::Vector2d, int>> pts;
    for (int v : vs) pts.push_back({Eigen::Vector2d(e1.dot(P[v]), e2.dot(P[v])), v});
    std::sort(pts.begin(), pts.end(), [](const auto& A, const auto& B) {
      return A.first.x() < B.first.x() || (A.first.x() == B.first.x() && A.first.y() < B.first.y());
    });
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
    HullFace face{Vec3::Zero(), 0.0, {}};
    for (int i = 0; i < k - 1; ++i) face.vertices.push_back(H[i].second);
    std::rotate(face.vertices.begin(), std::min_element(face.vertices.begin(), face.vertices.end()), face.vertices.end());
    const int m = static_cast<int>(face.vertices.size());
    const Vec3& c = P[face.vertices[0]];
    for (int i = 1; i + 1 < m; ++i) face.normal += (P[face.vertices[i]] - c).cross(P[face.vertices[i + 1]] - c);
    const double len = face.normal.norm();
    face.normal = len > 0.0 ? Vec3(face.normal / len) : n0;  // n0: a sliver face with no area to speak of
    for (int v : face.vertices) face.offset += face.normal.dot(P[v]);
    face.offset /= m;
    hull.faces.push_back(std::move(face));
  }
  std::sort(hull.faces.begin(), hull.faces.end(), [](const HullFace& a, const HullFace& b) { return a.vertices < b.vertices; });
  return hull;
}

}  // namespace idcol

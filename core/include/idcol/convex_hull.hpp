// 3-D convex hull, used to build a polytope from vertices and to enumerate
// the vertices of a half-space polytope (through its polar dual).
#pragma once

#include <array>
#include <vector>

#include "idcol/types.hpp"

namespace idcol {

struct HullFace {
  Vec3 normal;    // outward unit normal
  double offset;  // normal^T v = offset for every vertex v on the face
  std::vector<int> vertices;  // indices into the input points, counter-clockwise seen from outside
};

struct ConvexHull {
  std::vector<int> vertex_indices;             // input points that are hull vertices
  std::vector<std::array<int, 3>> triangles;   // outward-oriented triangles (input indices)
  std::vector<HullFace> faces;                 // coplanar triangles merged into planar faces
};

/// Incremental hull. Points closer than `rel_eps * scale` to a plane count as
/// on it (scale = the largest coordinate magnitude). Throws
/// std::invalid_argument (naming `what`) if there are fewer than 4 points, a
/// non-finite point, or all points are coplanar.
ConvexHull convex_hull(const std::vector<Vec3>& points, const char* what, double rel_eps = 1e-10);

}  // namespace idcol

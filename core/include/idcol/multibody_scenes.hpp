// The scenes of the paper's multibody example and of its scaling study,
// built from the library's shape families, for the example program
// (core/examples/multibody.cpp), the benchmark, the tests and Python.
#pragma once

#include <string>
#include <vector>

#include "idcol/rigid_body.hpp"

namespace idcol {

/// Bodies with their initial poses and body twists.
struct BodyScene {
  std::vector<std::string> names;
  std::vector<Shape> shapes;
  std::vector<MassProperties> masses;
  std::vector<Pose> X_W;
  std::vector<Vec6> eta;  // body twists (w, v)
};

/// The ten bodies of the paper's Fig. (contact physics, a): cone, cube,
/// cuboid, cylinder, ellipsoid, frustum, polytope, pyramid, sphere,
/// tetrahedron, of sizes about one unit. The flat ones are smooth
/// polytopes at the paper's beta = 20 (Table 1's), the cone and frustum
/// smooth truncated cones (beta = 20), the cylinder a superelliptic
/// cylinder (n = 8), the ellipsoid a superellipsoid with n = 1. Uniform
/// density 1 (mass_properties at `mass_cells` cells). Each body gets a uniformly
/// random orientation and a position on the sphere of `radius` about the
/// origin (random directions, redrawn until no two outer spheres are within
/// 0.5 of each other), and moves toward the origin at `speed` (its frame
/// origin's velocity), without spin. Seeded: the same seed gives the same
/// scene on every machine.
BodyScene paper_ten_bodies(unsigned seed = 1, double radius = 6.0, double speed = 2.0, int mass_cells = 64);

/// n bodies of the same ten kinds (cycled), scaled by `scale`, one per cell
/// of a cubic lattice of spacing 1 filled in order (the box's side grows as
/// n^(1/3)), each moved by a random offset of up to `jitter` per axis, with
/// random orientations and random velocities of magnitude `speed`: the
/// scaling scene, whose neighbours (and contacts) per body stay bounded as n
/// grows. The mass properties are computed once per kind.
BodyScene box_of_bodies(int n, unsigned seed = 1, double scale = 0.8, double jitter = 0.2, double speed = 1.0);

}  // namespace idcol

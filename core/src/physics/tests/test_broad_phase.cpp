// The broad phase (broad_phase.hpp) against brute force: on random scenes
// of spheres of mixed sizes (clustered, spread, touching exactly,
// coincident, one huge among small ones), every method finds exactly the
// pairs that a plain double loop over all pairs finds, in the same order.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "idcol/broad_phase.hpp"

using namespace idcol;

namespace {

/// The oracle: every pair i < j, tested as |c_i - c_j| <= r_i + r_j in long
/// double (no code shared with the library).
std::vector<BodyPair> brute_force(const std::vector<BoundingSphere>& s) {
  std::vector<BodyPair> out;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j) {
      long double d2 = 0.0L;
      for (int k = 0; k < 3; ++k) {
        const long double d = static_cast<long double>(s[i].center_W[k]) - s[j].center_W[k];
        d2 += d * d;
      }
      const long double r = static_cast<long double>(s[i].radius) + s[j].radius;
      if (d2 <= r * r) out.push_back({static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)});
    }
  return out;
}

std::vector<BoundingSphere> random_scene(std::mt19937_64& rng, int n, double box, double rmin, double rmax) {
  std::uniform_real_distribution<double> u(-box, box), r(rmin, rmax);
  std::vector<BoundingSphere> s(static_cast<std::size_t>(n));
  for (auto& b : s) b = {Vec3(u(rng), u(rng), u(rng)), r(rng)};
  return s;
}

std::string describe(const std::vector<BodyPair>& p) {
  std::string out = std::to_string(p.size()) + " pairs";
  for (std::size_t k = 0; k < p.size() && k < 5; ++k) out += " (" + std::to_string(p[k].i) + "," + std::to_string(p[k].j) + ")";
  return out;
}

TEST(BroadPhase, EveryMethodFindsTheBruteForcePairs) {
  std::mt19937_64 rng(11);
  int scenes = 0;
  std::size_t pairs = 0;
  for (int n : {0, 1, 2, 7, 48, 49, 300, 2000})
    for (double box : {1.0, 10.0, 100.0}) {
      std::vector<BoundingSphere> s = random_scene(rng, n, box, 0.05, 2.0);
      if (n >= 7) {
        s[0] = {Vec3(1.0, 1.0, 1.0), 0.5};
        s[1] = s[0];                               // coincident
        s[2] = {Vec3(1.75, 1.0, 1.0), 0.25};       // touching s[0] exactly (every number a dyadic)
        s[3] = {Vec3(1.0, 1.0, 1.75 + 0x1p-40), 0.25};  // apart from s[0] by 2^-40
        s[4].radius = 10.0 * box;  // one huge sphere among small ones
        s[5].radius = 0.0;  // a point
      }
      const std::vector<BodyPair> want = brute_force(s);
      pairs += want.size();
      for (BroadPhaseMethod m : {BroadPhaseMethod::AllPairs, BroadPhaseMethod::SweepAndPrune, BroadPhaseMethod::Tree,
                                 BroadPhaseMethod::Auto}) {
        BroadPhase bp(m);
        const std::vector<BodyPair>& got = bp.find(s);
        EXPECT_EQ(got, want) << to_string(m) << ", n " << n << ", box " << box << ": got " << describe(got)
                             << ", want " << describe(want);
      }
      ++scenes;
    }
  EXPECT_EQ(scenes, 24);
  EXPECT_GT(pairs, 10000u);  // the scenes are not all empty
}

TEST(BroadPhase, ScratchIsReusedAcrossCallsOfDifferentSizes) {
  std::mt19937_64 rng(12);
  BroadPhase bp(BroadPhaseMethod::Tree);
  for (int n : {500, 20, 900, 0, 300}) {
    const auto s = random_scene(rng, n, 8.0, 0.1, 1.0);
    EXPECT_EQ(bp.find(s), brute_force(s)) << n;
  }
}

TEST(BroadPhase, TheTreeTestsFarFewerBoxesThanAllPairs) {
  // 8000 unit-spaced bodies: all pairs is 32 million tests; the tree's
  // queries touch a few dozen nodes each.
  std::mt19937_64 rng(13);
  std::vector<BoundingSphere> s;
  for (int x = 0; x < 20; ++x)
    for (int y = 0; y < 20; ++y)
      for (int z = 0; z < 20; ++z) s.push_back({Vec3(x, y, z), 0.4 + 0.2 * std::uniform_real_distribution<double>(0, 1)(rng)});
  BroadPhase tree(BroadPhaseMethod::Tree);
  const std::size_t found = tree.find(s).size();
  EXPECT_GT(found, 1000u);
  EXPECT_LT(tree.tests(), 100 * static_cast<std::int64_t>(s.size()));
}

TEST(BroadPhase, BadSpheresAreNamed) {
  BroadPhase bp;
  std::vector<BoundingSphere> s(3, {Vec3::Zero(), 1.0});
  s[2].radius = -1.0;
  try {
    bp.find(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sphere 2"), std::string::npos) << e.what();
  }
  s[2].radius = 1.0;
  s[1].center_W.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(bp.find(s), std::invalid_argument);
}

}  // namespace

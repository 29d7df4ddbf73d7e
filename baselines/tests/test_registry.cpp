// The competitor table: names from it only, an unknown name refused with the
// known ones, rows present exactly where CMake found their library, and every
// row wired to an adapter that answers.
#include <random>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "idcol_baselines/baselines.hpp"
#include "idcol_baselines/registry.hpp"
#include "test_util.hpp"

namespace idcol::baselines {
namespace {

bool has(const char* name) { return find_competitor(name) != nullptr; }

TEST(Registry, RowsMatchTheLibrariesThisBuildFound) {
  EXPECT_TRUE(has("dcol")) << competitor_names();  // this project's C++: in every build with baselines
#ifdef IDCOL_BASELINES_WITH_FCL
  EXPECT_TRUE(has("fcl_collide") && has("fcl_distance")) << competitor_names();
#else
  EXPECT_FALSE(has("fcl_collide") || has("fcl_distance")) << competitor_names();
#endif
#ifdef IDCOL_BASELINES_WITH_CCD
  EXPECT_TRUE(has("ccd_gjk") && has("ccd_mpr") && has("ccd_mpr_penetration") && has("ccd_epa_unreliable"))
      << competitor_names();
#else
  EXPECT_FALSE(has("ccd_gjk") || has("ccd_mpr")) << competitor_names();
#endif
#ifdef IDCOL_BASELINES_WITH_BULLET
  EXPECT_TRUE(has("bullet_gjk_pair") && has("bullet_gjk_epa2")) << competitor_names();
#else
  EXPECT_FALSE(has("bullet_gjk_pair") || has("bullet_gjk_epa2")) << competitor_names();
#endif
}

TEST(Registry, NamesAreUniqueAndFoundByName) {
  std::set<std::string> seen;
  for (const Competitor* c : competitors()) {
    EXPECT_TRUE(seen.insert(c->name).second) << c->name;
    EXPECT_EQ(find_competitor(c->name), c);
    EXPECT_EQ(&competitor(c->name), c);
    EXPECT_NE(competitor_names().find(c->name), std::string::npos);
    EXPECT_NE(std::string(c->label), "") << c->name;
    EXPECT_TRUE(c->serves != nullptr && c->prepare != nullptr) << c->name;
  }
}

TEST(Registry, UnknownNameIsAnErrorNamingTheKnownOnes) {
  EXPECT_EQ(find_competitor("fcl_magic"), nullptr);
  try {
    (void)competitor("fcl_magic");
    FAIL() << "an unknown name must throw";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("\"fcl_magic\""), std::string::npos) << what;
    for (const Competitor* c : competitors()) EXPECT_NE(what.find(c->name), std::string::npos) << what;
  }
  // Near misses are not matched either.
  EXPECT_EQ(find_competitor("FCL_COLLIDE"), nullptr);
  EXPECT_EQ(find_competitor("fcl_collide "), nullptr);
  EXPECT_EQ(find_competitor(""), nullptr);
}

// Every row answers through its adapter: apart at alpha* = 1.5, overlapping
// at alpha* = 0.5, on each pair family it serves, and refuses a body with no
// exact counterpart, naming itself.
TEST(Registry, EveryRowServesAndAnswers) {
  const Shape ellip = Superellipsoid(0.5, 1.0, 1.5, 1.0), poly = test::paper_poly(20.0), sphere = Sphere(0.7);
  const Shape se8 = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  for (const Competitor* c : competitors()) {
    std::string why;
    EXPECT_FALSE(can_serve(*c, se8, poly, &why)) << c->name;
    EXPECT_EQ(why.rfind(std::string(c->name) + " cannot serve the pair", 0), 0u) << why;
  }
  std::mt19937_64 rng(61);
  const Pose X0 = test::random_pose(rng, 0.5, 2.0);
  for (const auto& [s1, s2] : {std::pair{ellip, poly}, std::pair{poly, poly}, std::pair{sphere, ellip}}) {
    const BaselinePair pair(s1, s2);
    EXPECT_EQ(pair.competitors().size(), competitors().size()) << pair.name();
    const OracleAnswer o = pair.oracle(X0);
    ASSERT_TRUE(o.ok) << o.error;
    for (const double target : {1.5, 0.5}) {
      const Pose X{X0.R, X0.p * (target / o.alpha)};
      for (const Competitor* c : pair.competitors()) {
        const BaselineAnswer a = pair.run(*c, X);
        ASSERT_FALSE(a.failed) << c->name << " on " << pair.name() << ": " << a.error;
        EXPECT_EQ(a.intersect, target < 1.0) << c->name << " on " << pair.name() << " at alpha* = " << target;
        EXPECT_EQ(pair.run(c->name, X).intersect, a.intersect) << c->name;
        // A method that answers alpha* itself (DCOL) gives it, near the oracle's.
        EXPECT_EQ(a.has_alpha, c->answers.alpha) << c->name;
        if (a.has_alpha) EXPECT_NEAR(a.alpha, target, 1e-3 * target) << c->name << " on " << pair.name();
      }
    }
  }
}

}  // namespace
}  // namespace idcol::baselines

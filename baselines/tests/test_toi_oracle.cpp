// idcol::time_of_impact against the independent time-of-impact oracle
// (toi_oracle.hpp: its own screw motion, and at each time a certified
// bracket on alpha* from a closed form, Perram-Wertheim or support functions,
// none of it core's), motion by motion, on translations and screw motions of
// a pair of every oracle method and every shape family.
//
// For each motion: where the oracle sees a clear hit, idcol reports an
// impact, at a time t no later than the oracle's last possible first contact
// t_hi, where the oracle's bracket at its own pose X(t) holds 1 (the bodies
// touch there); where it sees a clear miss, idcol reports none; on every
// motion idcol's certified free interval [0, t_free] ends no later than t_hi
// (it never certifies a contact away), and idcol's contact pose is the
// oracle's screw motion at t.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "idcol/toi.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/toi_oracle.hpp"
#include "test_util.hpp"

#include "../../core/examples/paper_shapes.hpp"

namespace idcol::baselines {
namespace {

struct ToiPair {
  std::string name;
  Shape body1, body2;
};

std::vector<ToiPair> pairs() {
  const auto paper = examples::paper_catalogue();  // Poly, TC, SE, SEC, Ellip
  const Shape box = SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
                                   {0.5, 0.5, 0.4, 0.4, 0.3, 0.3}, 2000.0);
  return {
      {"Sphere-Sphere", Sphere(0.3), Sphere(0.2)},                                              // closed form
      {"Ellip-Sphere", Superellipsoid(0.6, 0.3, 0.2, 1.0), Sphere(0.3)},                        // Perram-Wertheim
      {"Ellip-Ellip", Superellipsoid(0.5, 0.3, 0.2, 1.0), Superellipsoid(0.6, 0.25, 0.2, 1.0)},  // Perram-Wertheim
      {"SE-SEC", paper[2].shape, paper[3].shape},    // support functions, exact bodies
      {"Box-Sphere", box, Sphere(0.2)},              // support functions, smoothing bracket
      {"TC-Ellip", paper[1].shape, paper[4].shape},  // support functions, smoothing bracket
      {"Poly-SE", paper[0].shape, paper[2].shape},   // support functions, smoothing bracket
  };
}

/// Seeded motions scaled to the pair (L = the sum of the outer radii): body 2
/// from 1.05-2.05 L on one side of body 1 to as far on the other, shifted
/// sideways by up to 3 L (about half the motions pass by); a screw turns by 0.3-2.5 rad
/// about a random axis on the way.
std::vector<std::pair<Pose, Pose>> motions(double L, bool screw, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::pair<Pose, Pose>> out(n);
  for (auto& [X0, X1] : out) {
    const Vec3 d = test::random_unit(rng);
    X0.R = test::random_rotation(rng);
    X0.p = (1.05 + u(rng)) * L * d;
    X1.R = screw ? Mat3(X0.R * Eigen::AngleAxisd(0.3 + 2.2 * u(rng), test::random_unit(rng)).toRotationMatrix()) : X0.R;
    X1.p = -(1.05 + u(rng)) * L * d + 3.0 * u(rng) * L * test::random_unit(rng);
  }
  return out;
}

TEST(ToiAgainstOracle, TranslationsAndScrewsOfEveryOracleMethod) {
  int hits = 0, misses = 0, grazes = 0;
  for (const ToiPair& P : pairs()) {
    const ToiOracle oracle(to_desc(P.body1), to_desc(P.body2), {200, 1e-3, 45});
    // The support-function bracket costs ~0.2 ms an evaluation, the closed
    // forms next to nothing: fewer motions there.
    const int n = std::string(oracle.method()) == "support_function" ? 6 : 12;
    const double L = radii(P.body1).outer + radii(P.body2).outer;
    for (bool screw : {false, true}) {
      const auto ms = motions(L, screw, n, screw ? 71u : 70u);
      int pair_hits = 0, pair_misses = 0;
      for (std::size_t k = 0; k < ms.size(); ++k) {
        const auto& [X0, X1] = ms[k];
        SCOPED_TRACE(P.name + (screw ? " screw " : " translation ") + std::to_string(k) + " (" + oracle.method() + ")");
        const ToiOracleAnswer o = oracle.first_contact(X0, X1);
        const ToiResult r = time_of_impact(P.body1, P.body2, X0, X1);
        // Never certified free past the oracle's last possible first contact.
        EXPECT_LE(r.t_free, o.t_hi + 1e-12) << "t_free " << r.t_free << ", oracle's first contact in [" << o.t_lo << ", "
                                              << o.t_hi << "], idcol " << to_string(r.status);
        if (o.clear_hit) {
          ++pair_hits;
          ASSERT_EQ(r.status, ToiStatus::Impact) << "oracle: contact in [" << o.t_lo << ", " << o.t_hi << "]";
          EXPECT_LE(r.t, o.t_hi + 1e-9);
          // The bodies touch at idcol's t by the oracle, on the oracle's own motion.
          const OracleMotion m(X0, X1);
          const geom::Pose Xo = m.at(r.t);
          EXPECT_LT((Xo.R - r.X_12.R).norm(), 1e-12);
          EXPECT_LT((Xo.p - r.X_12.p).norm(), 1e-12 * L);
          const std::array<double, 2> b = oracle.bracket(Xo);
          EXPECT_LE(b[0], 1.0 + 1e-7) << "oracle's alpha* bracket at t = " << r.t << ": [" << b[0] << ", " << b[1] << "]";
          EXPECT_GE(b[1], 1.0 - 1e-7) << "oracle's alpha* bracket at t = " << r.t << ": [" << b[0] << ", " << b[1] << "]";
        } else if (o.clear_miss) {
          ++pair_misses;
          EXPECT_EQ(r.status, ToiStatus::NoImpact) << "oracle: least alpha* at least " << o.min_lo;
        } else {
          ++grazes;
        }
      }
      // Both verdicts occur for every pair and model: the checks above ran.
      EXPECT_GE(pair_hits, 2) << P.name << (screw ? " screw" : " translation");
      EXPECT_GE(pair_misses, 1) << P.name << (screw ? " screw" : " translation");
      std::printf("%-13s %-11s %-16s %2d clear hits, %2d clear misses\n", P.name.c_str(), screw ? "screw" : "translation",
                  oracle.method(), pair_hits, pair_misses);
      hits += pair_hits;
      misses += pair_misses;
    }
  }
  std::printf("time of impact against the oracle: %d clear hits, %d clear misses, %d grazes left out\n", hits, misses,
              grazes);
}

}  // namespace
}  // namespace idcol::baselines

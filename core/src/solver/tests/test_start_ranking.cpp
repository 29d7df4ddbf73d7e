// The cold start's ranking (formulas::rank_starts) and the Newton run's merit
// (formulas::kkt_merit), which the loop and the SIMD lanes share, against
// oracles that share no code with them: the ranking against a tournament
// written out candidate by candidate (the best so far kept, each loser
// appended to the spares, the spares then ordered by merit, a start whose
// merit is not finite skipped), on every triple drawn from a small set of
// values with ties, infinities and NaN; the merit against Eigen's own
// 0.5 * squaredNorm, bit for bit.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "idcol/detail/formulas/kkt.hpp"
#include "idcol/detail/formulas/support.hpp"
#include "idcol/detail/scalar_num.hpp"
#include "idcol/types.hpp"

namespace {

using idcol::detail::ScalarNum;
namespace formulas = idcol::detail::formulas;

struct Tournament {
  int best = -1;
  std::vector<int> spares;  // finite ones, best first
};

Tournament tournament(const double (&m)[3]) {
  Tournament t;
  double best = 0.0;
  std::vector<std::pair<int, double>> lost;
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(m[c])) continue;
    if (t.best < 0) {
      t.best = c, best = m[c];
    } else if (m[c] < best) {
      lost.emplace_back(t.best, best);
      t.best = c, best = m[c];
    } else {
      lost.emplace_back(c, m[c]);
    }
  }
  if (lost.size() == 2 && lost[1].second < lost[0].second) std::swap(lost[0], lost[1]);
  for (const auto& l : lost) t.spares.push_back(l.first);
  return t;
}

TEST(StartRanking, MatchesTheTournamentOnEveryTriple) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const double v[] = {0.0, 1e-300, 0.5, 1.0, 1.0 + 0x1p-52, 2.0, 1e300, inf, nan};
  int n = 0;
  for (double a : v)
    for (double b : v)
      for (double c : v) {
        const double m[3] = {a, b, c};
        const Tournament t = tournament(m);
        const auto r = formulas::rank_starts<ScalarNum>(m);
        const int finite = std::isfinite(a) + std::isfinite(b) + std::isfinite(c);
        SCOPED_TRACE(::testing::Message() << a << " " << b << " " << c);
        if (finite == 0) continue;  // no start: the caller tries the next guess
        EXPECT_EQ(r.best, t.best);
        // The finite spares are a prefix of rank.spare, in the tournament's order.
        ASSERT_EQ(static_cast<int>(t.spares.size()), finite - 1);
        for (std::size_t k = 0; k < t.spares.size(); ++k) EXPECT_EQ(r.spare[k], t.spares[k]);
        for (std::size_t k = t.spares.size(); k < 2; ++k) EXPECT_FALSE(std::isfinite(m[r.spare[k]]));
        // The three indices are a permutation.
        EXPECT_EQ((1 << r.best) | (1 << r.spare[0]) | (1 << r.spare[1]), 7);
        ++n;
      }
  EXPECT_EQ(n, 9 * 9 * 9 - 2 * 2 * 2);
}

TEST(KktMerit, IsHalfEigensSquaredNormBitForBit) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-100.0, 100.0);
  for (int k = 0; k < 200000; ++k) {
    idcol::Vec6 F;
    for (int i = 0; i < 6; ++i) F[i] = u(rng) * std::pow(10.0, e(rng));
    const double want = 0.5 * F.squaredNorm(), got = formulas::kkt_merit<ScalarNum>(F.data());
    ASSERT_EQ(std::memcmp(&want, &got, sizeof want), 0) << k << ": " << want << " vs " << got;
  }
}

}  // namespace

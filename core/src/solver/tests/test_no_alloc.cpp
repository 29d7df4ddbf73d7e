// A solve never touches the heap: every allocation in the process is counted
// through a replaced global operator new, and Eigen's own malloc guard is
// armed for the solver template instantiated in this translation unit.
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "idcol/batch.hpp"
#include "idcol/derivatives.hpp"
#include "src/solver/solver_impl.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

static std::atomic<long> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace idcol;

TEST(NoAlloc, SolvesOfEveryPairAllocateNothing) {
  const auto cat = test::catalogue();
  std::mt19937_64 rng(8);
  std::vector<Pose> poses;
  for (int i = 0; i < 50; ++i) poses.push_back(test::random_pose(rng, 0.01, 10.0));
  WarmStart warm;
  for (const auto& A : cat)
    for (const auto& B : cat) {
      const long before = g_allocations.load();
      Eigen::internal::set_is_malloc_allowed(false);
      int ok = 0;
      for (const Pose& X : poses) {
        ok += solve(A.shape, B.shape, X, SolverOptions{}, &warm).converged();
        ok += std::visit([&](const auto& a, const auto& b) { return detail::solve_pair(a, b, X, SolverOptions{}, nullptr); }, A.shape,
                         B.shape)
                  .converged();
      }
      Eigen::internal::set_is_malloc_allowed(true);
      EXPECT_EQ(g_allocations.load(), before) << A.name << "-" << B.name;
      EXPECT_EQ(ok, 100) << A.name << "-" << B.name;
    }
}

TEST(NoAlloc, DerivativesAllocateNothing) {
  const auto cat = test::catalogue();
  std::mt19937_64 rng(9);
  const HertzModel m{1.0, 1.5};
  for (const auto& A : cat)
    for (const auto& B : cat) {
      const Pose X = test::random_pose(rng, 0.3, 3.0);
      const SolverOptions o = test::with_derivatives();
      const long before_solve = g_allocations.load();
      Eigen::internal::set_is_malloc_allowed(false);
      const SolveResult r = solve(A.shape, B.shape, X, o);
      Eigen::internal::set_is_malloc_allowed(true);
      EXPECT_EQ(g_allocations.load(), before_solve) << A.name << "-" << B.name;
      ASSERT_TRUE(r.converged());
      const long before = g_allocations.load();
      Eigen::internal::set_is_malloc_allowed(false);
      const SolutionSensitivity s = solution_sensitivity(r);
      const ContactKinematicsDerivatives d = contact_kinematics_derivatives(r, s);
      const ContactKinematicsWorld w = contact_kinematics_world(contact_kinematics(r), &d, X, X);
      const ContactWrenchDerivatives wd = contact_wrench_derivatives(r, s, m);
      const Row6 g = gap_gradient(r) + alpha_gradient(r);
      const Mat6x12 dz = world_pose_sensitivity(s, X);
      Eigen::internal::set_is_malloc_allowed(true);
      EXPECT_EQ(g_allocations.load(), before) << A.name << "-" << B.name;
      EXPECT_TRUE(s.valid && d.valid && w.valid && wd.valid && g.allFinite() && dz.allFinite());
    }
}

// solve_batch on one thread allocates nothing, whatever the number of rows:
// the SIMD path's lanes (two ellipsoids, cold and warm) and the loop.
TEST(NoAlloc, BatchOnOneThreadAllocatesNothing) {
  std::mt19937_64 rng(10);
  std::vector<Pose> poses;
  for (int i = 0; i < 1000; ++i) poses.push_back(test::random_pose(rng, 0.05, 5.0));
  std::vector<double> alpha(poses.size()), x(3 * poses.size());
  std::vector<std::int32_t> status(poses.size()), iterations(poses.size());
  const BatchOutput out{alpha, x, status, iterations, {}};
  const Shape e1 = Superellipsoid(0.5, 1.0, 1.5, 1.0), e2 = Superellipsoid(1.2, 0.3, 0.7, 1.0), se = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  for (const Shape* b : {&e2, &se})
    for (bool warm : {false, true}) {
      BatchOptions o;
      o.warm_start = warm;
      o.warm_chain = 100;
      const long before = g_allocations.load();
      solve_batch(e1, *b, poses, o, out);
      EXPECT_EQ(g_allocations.load(), before) << (b == &se ? "Ellip-SE" : "Ellip-Ellip") << (warm ? " warm" : " cold");
      long conv = 0;
      for (std::int32_t s : status) conv += s == static_cast<std::int32_t>(SolveStatus::Converged);
      EXPECT_EQ(conv, static_cast<long>(poses.size()));
    }
}

// What the dispatcher (batch_simd.cpp) hands the lane kernels
// (batch_simd_kernel.hpp): plain data only, so that the kernels, compiled
// for other instruction sets, include no header that defines an inline
// function.
#pragma once

namespace idcol::detail {

/// The constants of one ellipsoid pair under one set of solver options.
struct EllipsoidLaneConsts {
  double M1[3], M2[3];      // the ellipsoid matrices diag(a^2, b^2, c^2) of body 1 and body 2
  double inv1[3], inv2[3];  // (1/a, 1/b, 1/c) of each body
  double L;                 // pair length r1_out + r2_out
  double fSL;               // surrogate_factor * L
  double c1f, c2f;          // surrogate_factor * r_i,out / L: c_i = c_if r_hat
  double lo, hi;            // the trust region of s = log alpha (PairSolver::bounds)
  double inv_sigma1, inv_sigma2;
  double accept;            // a lane is accepted with every relative residual term at most this
  double pose_tol2;         // squared Frobenius bound on R^T R - I accepted without the scalar check
  double rmax_lo, rmax_hi;  // lanes whose largest |r| coordinate lies outside go to the scalar solver
};

/// W poses (W = the kernel's lane count): R_in holds 9 rows of W (entry e of
/// R_12 row-major, lane i at [e W + i]), p_in 3 rows of W, l0_in W warm
/// starts of the closed form (l of the last contact, in (0, 1); anything
/// else: cold). Writes alpha* and x_1 (3 rows of W), the solution z
/// (6 rows of W: xi, s, lambda1, lambda2 in surrogate units, what a
/// WarmStart keeps), body 1's gradient at its witness point g1 (3 rows of
/// W: the solver's last evaluation, which SolveResult::internal.e1.grad
/// keeps and whose direction is the contact normal) and ok[i] = 1 where
/// lane i is the scalar solver's converged answer, else 0 (that pose must
/// be solved by the scalar solver).
typedef void (*EllipsoidLaneFn)(const EllipsoidLaneConsts&, const double* R_in, const double* p_in, const double* l0_in,
                                double* alpha, double* x, double* z, double* g1, int* ok);

void ellipsoid_lanes_sse2(const EllipsoidLaneConsts&, const double*, const double*, const double*, double*, double*, double*,
                          double*, int*);
void ellipsoid_lanes_avx2(const EllipsoidLaneConsts&, const double*, const double*, const double*, double*, double*, double*,
                          double*, int*);
void ellipsoid_lanes_avx512(const EllipsoidLaneConsts&, const double*, const double*, const double*, double*, double*,
                            double*, double*, int*);

}  // namespace idcol::detail

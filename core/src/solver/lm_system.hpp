// The linear algebra of the Levenberg-Marquardt step (PairSolver::lm_step),
// compiled once, out of line (solver.cpp), so that the scalar solver and the
// SIMD batch lanes, which make the step lane by lane, form it with the same
// instructions and so the same bits.
#pragma once

namespace idcol::detail {

/// From the Jacobian J (6x6 row-major, as PairSolver keeps it) and the
/// residual F (6): J^T J (column-major), g = J^T F and the first damping
/// mu = initial_damping * max(max diag(J^T J), 1e-300).
void lm_normal_equations(const double* J, const double* F, double initial_damping, double* JtJ, double* g, double* mu);

/// The damped step dz = -(J^T J + mu I)^-1 g by Cholesky (Eigen's LLT);
/// false where it is not finite (the trial is skipped).
bool lm_direction(const double* JtJ, const double* g, double mu, double* dz);

}  // namespace idcol::detail

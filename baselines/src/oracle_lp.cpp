// Exact polytope-polytope alpha* as a linear program (see oracles.hpp):
//   min alpha  s.t.  a1_i^T x - b1_i alpha <= 0,
//                    (R a2_j)^T x - b2_j alpha <= (R a2_j)^T r,
// x free in body-1 coordinates, alpha >= 0. GLPK's primal simplex finds the
// optimal vertex; that vertex is then recomputed from its four active
// constraints in double precision, which removes the simplex's feasibility
// tolerance from the answer.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/QR>
#include <glpk.h>

#include "idcol_baselines/oracles.hpp"

namespace idcol::baselines {

namespace {
/// Simplex pivots allowed per LP (GLPK's it_lim). A basis of four columns
/// is reached in tens of pivots; only a cycling or stalling simplex gets
/// near this.
constexpr int kLpIterationLimit = 10000;
}  // namespace

OracleAnswer polytope_lp(const ExactPolytope& P1, const ExactPolytope& P2, const geom::Pose& X_12) {
  OracleAnswer out;
  out.method = OracleMethod::PolytopeLP;
  const int m1 = static_cast<int>(P1.normals.size()), m2 = static_cast<int>(P2.normals.size());
  const int m = m1 + m2;
  // Constraint rows g_k^T (x, alpha) <= h_k.
  std::vector<Eigen::Vector4d> G(m);
  std::vector<double> h(m);
  for (int i = 0; i < m1; ++i) {
    G[i] << P1.normals[i], -P1.offsets[i];
    h[i] = 0.0;
  }
  for (int j = 0; j < m2; ++j) {
    const Vec3 n = X_12.R * P2.normals[j];
    G[m1 + j] << n, -P2.offsets[j];
    h[m1 + j] = n.dot(X_12.p);
  }

  glp_term_out(GLP_OFF);
  glp_prob* lp = glp_create_prob();
  glp_set_obj_dir(lp, GLP_MIN);
  glp_add_cols(lp, 4);
  for (int c = 1; c <= 3; ++c) glp_set_col_bnds(lp, c, GLP_FR, 0.0, 0.0);
  glp_set_col_bnds(lp, 4, GLP_LO, 0.0, 0.0);
  glp_set_obj_coef(lp, 4, 1.0);
  glp_add_rows(lp, m);
  int ind[5] = {0, 1, 2, 3, 4};
  for (int k = 0; k < m; ++k) {
    // Entries at rounding level (a rotation's cos(pi/2) = 6e-17) are dropped
    // for GLPK only: they wreck its scaling and pivoting. The polish below
    // uses the true rows.
    double val[5] = {0.0};
    int cnt = 0, idx[5] = {0};
    for (int c = 0; c < 4; ++c)
      if (std::abs(G[k][c]) > 1e-14) ++cnt, idx[cnt] = ind[c + 1], val[cnt] = G[k][c];
    glp_set_mat_row(lp, k + 1, cnt, idx, val);
    glp_set_row_bnds(lp, k + 1, GLP_UP, 0.0, h[k]);
  }
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_OFF;
  // A bound on the pivots: four columns need a few dozen, and GLPK's simplex
  // has been seen to run for minutes without end on one badly scaled
  // wide-range polytope pair. Past the bound the oracle gives no answer
  // (GLP_EITLIM below), counted as such, instead of stopping the run.
  parm.it_lim = kLpIterationLimit;
  const int rc = glp_simplex(lp, &parm);
  const int st = glp_get_status(lp);
  if (rc != 0 || st != GLP_OPT) {
    out.error = "glp_simplex returned " + std::to_string(rc) + ", status " + std::to_string(st);
    glp_delete_prob(lp);
    return out;
  }
  Eigen::Vector4d z(glp_get_col_prim(lp, 1), glp_get_col_prim(lp, 2), glp_get_col_prim(lp, 3),
                    glp_get_col_prim(lp, 4));
  out.iterations = glp_get_it_cnt(lp);
  std::vector<int> row_stat(m);
  for (int k = 0; k < m; ++k) row_stat[k] = glp_get_row_stat(lp, k + 1);
  glp_delete_prob(lp);

  // Worst violation of a candidate, relative to the problem's scale.
  const double scale = std::max(1.0, X_12.p.norm());
  auto violation = [&](const Eigen::Vector4d& v) {
    double w = 0.0;
    for (int k = 0; k < m; ++k) w = std::max(w, G[k].dot(v) - h[k]);
    return w / scale;
  };
  // Polish and certify. With A the rows active at the simplex point (to its
  // tolerance): the dual mu >= 0 solves G_A^T mu = -c, c = (0, 0, 0, 1), in
  // least squares, and gives the lower bound alpha >= -mu^T h_A; the primal
  // point projected onto G_A z = h_A (minimum-norm correction) gives an upper
  // bound if it is feasible. Both agree to rounding at the optimum, also at
  // degenerate (face-face) optima where x is not unique and fewer than four
  // rows are active.
  auto certify = [&](const std::vector<int>& act, Eigen::Vector4d& zc, double& gap) {
    const int na = static_cast<int>(act.size());
    if (na == 0) return false;
    Eigen::MatrixXd GA(na, 4);
    Eigen::VectorXd hA(na);
    for (int q = 0; q < na; ++q) GA.row(q) = G[act[q]].transpose(), hA[q] = h[act[q]];
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod_t(GA.transpose());
    const Eigen::VectorXd mu = cod_t.solve(-Eigen::Vector4d::UnitW());
    const double dual_res = (GA.transpose() * mu + Eigen::Vector4d::UnitW()).cwiseAbs().maxCoeff();
    if (dual_res > 1e-12 || mu.minCoeff() < -1e-12) return false;
    const double lower = -mu.dot(hA);
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(GA);
    zc = z + cod.solve(hA - GA * z);
    if (violation(zc) > 1e-13) return false;
    gap = std::abs(zc[3] - lower);
    return gap <= 1e-12 * std::max(1.0, zc[3]);
  };
  std::vector<int> act_tol, act_basis;
  for (int k = 0; k < m; ++k) {
    if (std::abs(G[k].dot(z) - h[k]) <= 1e-7 * scale * std::max(1.0, z.cwiseAbs().maxCoeff())) act_tol.push_back(k);
    if (row_stat[k] == GLP_NU) act_basis.push_back(k);
  }
  Eigen::Vector4d zc;
  double gap = 0.0;
  bool ok = certify(act_tol, zc, gap) || certify(act_basis, zc, gap);
  // A nearly active row that is not active at the optimum spoils both; then
  // try the subsets of at most four near-active rows (a vertex needs four).
  const int na = static_cast<int>(act_tol.size());
  for (unsigned mask = 1; !ok && na <= 16 && mask < (1u << na); ++mask) {
    if (__builtin_popcount(mask) > 4) continue;
    std::vector<int> sub;
    for (int q = 0; q < na; ++q)
      if (mask & (1u << q)) sub.push_back(act_tol[q]);
    ok = certify(sub, zc, gap);
  }
  if (!ok) {
    out.error = "LP optimum not certified (simplex alpha " + std::to_string(z[3]) + ", " +
                std::to_string(act_tol.size()) + " active rows)";
    return out;
  }
  z = zc;
  out.alpha = z[3];
  out.x_1 = z.head<3>();
  out.has_x = true;
  out.alpha_lo = out.alpha_hi = out.alpha;
  out.ok = std::isfinite(out.alpha) && out.alpha > 0.0;
  if (!out.ok) out.error = "LP gave a non-positive alpha";
  return out;
}

}  // namespace idcol::baselines

// The step's cost of the paper's multibody example, for the regression
// guard scripts/ci_multibody.sh: the ten-body scene (seed 1, thrown at 2
// units/s from a sphere of radius 6, Hertz k = 1e4, p = 1.5; its mass
// properties at 24 cells, not 64, to start fast under valgrind) integrated to
// T seconds with analytical Jacobians (rtol 1e-6, atol 1e-8, steps of at
// most a quarter of the smallest inner radius at the throwing speed, as
// idcol_multibody takes them), callgrind collecting only inside the
// integration:
//
//   valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file=cg.out \
//       build/core/idcol_prof_multibody [T]      (default T = 2.2: the first collisions)
//
// Prints one JSON object: the accepted steps, f and Jacobian evaluations,
// narrow-phase rows, contacts per accepted step and the momentum drift
// (relative to the bodies' total, as idcol_multibody reports it). The
// instructions are callgrind's summary; the script divides them by the steps.
#include <valgrind/callgrind.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "idcol/multibody_scenes.hpp"
#include "idcol/rigid_body.hpp"

using namespace idcol;

int main(int argc, char** argv) {
  const double t_end = argc > 1 ? std::atof(argv[1]) : 2.2;
  if (!(t_end > 0.0)) {
    std::fprintf(stderr, "usage: idcol_prof_multibody [T > 0]\n");
    return 2;
  }
  const double speed = 2.0;
  const BodyScene sc = paper_ten_bodies(1, 6.0, speed, 24);  // coarser masses: a cheaper start under valgrind
  SceneOptions so;
  so.contact.stiffness = 1e4;
  so.contact.exponent = 1.5;
  MultibodySystem sys(sc.shapes, sc.masses, so);
  StiffOdeOptions oo;
  oo.rtol = 1e-6;
  oo.atol = 1e-8;
  double r_in = INFINITY;
  for (const Shape& s : sc.shapes) r_in = std::min(r_in, radii(s).inner);
  oo.max_step = 0.25 * r_in / speed;
  const Eigen::VectorXd y0 = sys.state(sc.X_W, sc.eta);
  CALLGRIND_TOGGLE_COLLECT;
  const MultibodyRun run = simulate(sys, y0, t_end, {t_end}, oo, true);
  CALLGRIND_TOGGLE_COLLECT;
  // The drift over the outputs (t = 0 and t_end), scaled as idcol_multibody does.
  const Vec6 dh = sys.momentum(run.y.back()) - sys.momentum(y0);
  double lin = 0.0, ang = 0.0;
  for (int i = 0; i < sys.num_bodies(); ++i) {
    const Vec6 mu = sys.mass(i).spatial_inertia() * sys.twist(y0, i);
    lin += mu.tail<3>().norm();
    ang += mu.head<3>().norm() + sys.pose(y0, i).p.norm() * mu.tail<3>().norm();
  }
  std::printf("{\"t_end\": %g, \"status\": \"%s\", \"steps\": %ld, \"rhs_evaluations\": %ld, \"jacobian_evaluations\": %ld, "
              "\"narrow_rows\": %ld, \"contacts_per_step\": %.4f, \"contacts_max\": %ld, \"momentum_drift_linear\": %.3e, "
              "\"momentum_drift_angular\": %.3e, \"rtol\": %g}\n",
              t_end, to_string(run.status), run.ode.steps, run.ode.rhs_evaluations, run.ode.jacobian_evaluations,
              run.counters.narrow_rows, run.step_contacts_mean, run.step_contacts_max, dh.tail<3>().norm() / lin,
              dh.head<3>().norm() / ang, oo.rtol);
  return run.status == StiffOdeStatus::Success ? 0 : 1;
}

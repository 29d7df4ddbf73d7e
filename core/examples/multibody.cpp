// The paper's multibody example (Sec. "Multibody Collision"): ten convex
// bodies thrown at the origin, frictionless Hertz contact, 5 s, integrated
// by a stiff solver with the contact wrenches' analytical Jacobians, then
// again with finite-difference Jacobians.
//
//   build/core/idcol_multibody [-o OUT.json] [--seed S] [--speed V] [--t-end T]
//                              [--stiffness K] [--exponent P] [--rtol R] [--atol A]
//                              [--reps N] [--frames F] [--no-fd]
//
// Prints the run time, the share of the broad and narrow phase, the steps,
// Jacobian evaluations and contacts of each run, and the ratio of the two
// run times; checks what must hold whatever the integrator (no gravity and
// no friction: the total momentum is conserved; every contact's two
// wrenches are equal and opposite) and exits 1 if a check fails. OUT.json
// (default build/out/multibody.json) holds every figure with the machine,
// compiler, flags and git revision, and the frames that
// scripts/plot_multibody.py draws.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "idcol/multibody_scenes.hpp"
#include "idcol/rigid_body.hpp"
#include "idcol/stiff_ode.hpp"
#include "run_info.hpp"

using namespace idcol;

namespace {

struct Args {
  std::string out = "build/out/multibody.json";
  unsigned seed = 1;
  double speed = 2.0, t_end = 5.0, stiffness = 1e4, exponent = 1.5, rtol = 1e-6, atol = 1e-8;
  int reps = 3, frames = 101;
  bool fd = true;
};

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "%s\nusage: idcol_multibody [-o OUT.json] [--seed S] [--speed V] [--t-end T] [--stiffness K]\n"
               "                       [--exponent P] [--rtol R] [--atol A] [--reps N] [--frames F] [--no-fd]\n",
               why);
  std::exit(2);
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage(("missing value after " + k).c_str());
      return argv[++i];
    };
    auto number = [&](double lo) {
      const char* v = value();
      char* end = nullptr;
      const double x = std::strtod(v, &end);
      if (end == v || *end != '\0' || !std::isfinite(x) || !(x >= lo))
        usage((k + " needs a number >= " + std::to_string(lo) + ", got '" + v + "'").c_str());
      return x;
    };
    if (k == "-o") a.out = value();
    else if (k == "--seed") a.seed = static_cast<unsigned>(number(0));
    else if (k == "--speed") a.speed = number(0);
    else if (k == "--t-end") a.t_end = number(1e-6);
    else if (k == "--stiffness") a.stiffness = number(1e-300);
    else if (k == "--exponent") a.exponent = number(1);
    else if (k == "--rtol") a.rtol = number(1e-13);
    else if (k == "--atol") a.atol = number(1e-300);
    else if (k == "--reps") a.reps = static_cast<int>(number(1));
    else if (k == "--frames") a.frames = static_cast<int>(number(2));
    else if (k == "--no-fd") a.fd = false;
    else if (k == "-h" || k == "--help") usage("The paper's multibody example (core/examples/multibody.cpp).");
    else usage(("unknown argument " + k).c_str());
  }
  return a;
}

/// The runs of one mode: the integration `reps` times (the last one's
/// figures and frames are kept).
struct Run {
  MultibodyRun last;
  std::vector<double> wall;  // seconds, one per repetition
};

SceneOptions scene_options(const Args& a) {
  SceneOptions o;
  o.contact.stiffness = a.stiffness;
  o.contact.exponent = a.exponent;
  return o;
}

/// The error estimate sees nothing of a contact ahead: in free flight a
/// step may grow until bodies pass through each other between two steps.
/// A step moves no body by more than a quarter of the smallest inner
/// radius at the throwing speed.
double max_step(const BodyScene& sc, const Args& a) {
  double r_in = INFINITY;
  for (const Shape& s : sc.shapes) r_in = std::min(r_in, radii(s).inner);
  return a.speed > 0.0 ? 0.25 * r_in / a.speed : INFINITY;
}

Run integrate(const BodyScene& sc, const Args& a, bool analytic) {
  Run run;
  std::vector<double> outputs;
  for (int f = 1; f < a.frames; ++f) outputs.push_back(a.t_end * f / (a.frames - 1));
  StiffOdeOptions oo;
  oo.rtol = a.rtol;
  oo.atol = a.atol;
  oo.max_step = max_step(sc, a);
  for (int rep = 0; rep < a.reps; ++rep) {
    MultibodySystem sys(sc.shapes, sc.masses, scene_options(a));
    run.last = simulate(sys, sys.state(sc.X_W, sc.eta), a.t_end, outputs, oo, analytic);
    run.wall.push_back(run.last.wall_seconds);
  }
  return run;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

/// What must hold whatever the integrator, over the frames of a run.
struct Checks {
  double momentum_linear = 0.0, momentum_angular = 0.0;  // max |h(t) - h(0)| / scale
  double linear_scale = 0.0, angular_scale = 0.0;        // sum over bodies of |h_i(0)|
  double wrench_pair = 0.0;  // max |world F1 + world F2| / |F1| over the frames' active contacts
  int contacts_checked = 0;
  double max_penetration = 0.0;
  bool momentum_ok = false, wrench_ok = false;
};

Vec6 world_wrench(const Pose& X_W, const Vec6& F_B) {
  const Vec3 f = X_W.R * F_B.tail<3>();
  Vec6 out;
  out.head<3>() = X_W.R * F_B.head<3>() + X_W.p.cross(f);
  out.tail<3>() = f;
  return out;
}

Checks check(const BodyScene& sc, const Args& a, const Run& run) {
  MultibodySystem sys(sc.shapes, sc.masses, scene_options(a));
  Checks c;
  const Eigen::VectorXd& y0 = run.last.y.front();
  const Vec6 h0 = sys.momentum(y0);
  // The scales: the sum of the bodies' momenta, and for the angular part
  // that of their moments at their distance from the origin (each body
  // heads for the origin, so its own angular momentum about it is ~0).
  for (int i = 0; i < sys.num_bodies(); ++i) {
    const Pose X = sys.pose(y0, i);
    const Vec6 mu = sys.mass(i).spatial_inertia() * sys.twist(y0, i);
    c.linear_scale += mu.tail<3>().norm();
    c.angular_scale += mu.head<3>().norm() + X.p.norm() * mu.tail<3>().norm();
  }
  for (const Eigen::VectorXd& y : run.last.y) {
    const Vec6 dh = sys.momentum(y) - h0;
    c.momentum_angular = std::max(c.momentum_angular, dh.head<3>().norm() / c.angular_scale);
    c.momentum_linear = std::max(c.momentum_linear, dh.tail<3>().norm() / c.linear_scale);
    const std::vector<Pose> X = sys.poses(y);
    for (const Contact& k : sys.scene().update(X)) {
      if (!k.active) continue;
      const Vec6 sum = world_wrench(X[k.body1], k.F1_1) + world_wrench(X[k.body2], k.F2_2);
      const double size = world_wrench(X[k.body1], k.F1_1).norm();
      c.wrench_pair = std::max(c.wrench_pair, sum.norm() / size);
      c.max_penetration = std::max(c.max_penetration, -k.gap);
      ++c.contacts_checked;
    }
  }
  // The momentum is conserved by the equations exactly; the integrator keeps
  // it to its error control (the linear part is a linear function of the
  // state only through R_i v_i, so both drift at the level of rtol).
  c.momentum_ok = c.momentum_linear <= 50.0 * a.rtol && c.momentum_angular <= 50.0 * a.rtol;
  c.wrench_ok = c.wrench_pair <= 1e-12;
  return c;
}

}  // namespace

namespace {

/// A drawable surface of a body, in its frame: the boundary point along
/// each direction of a latitude-longitude grid (every convex body is
/// star-shaped about an interior point, and the frame origin is one), by
/// bisection on phi along the ray.
std::vector<Vec3> surface_grid(const Shape& s, int nlat, int nlon) {
  const double pi = 3.14159265358979323846, rmax = radii(s).outer * 1.01;
  std::vector<Vec3> pts;
  ShapeEval e;
  for (int i = 0; i < nlat; ++i)
    for (int j = 0; j < nlon; ++j) {
      const double th = pi * i / (nlat - 1), ph = 2.0 * pi * j / (nlon - 1);
      const Vec3 u(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      double lo = 0.0, hi = rmax;
      for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        eval(s, mid * u, e);
        (e.phi <= 0.0 ? lo : hi) = mid;
      }
      pts.push_back(lo * u);
    }
  return pts;
}

std::string vec_json(const double* v, int n, int digits = 9) {
  std::ostringstream o;
  o.precision(digits);
  o << "[";
  for (int i = 0; i < n; ++i) o << (i ? ", " : "") << v[i];
  return o.str() + "]";
}

std::string run_json(const Run& r, const Checks& c) {
  const auto& k = r.last.counters;
  const double total = r.wall.back();  // the run the counters are of
  std::ostringstream o;
  o.precision(6);
  o << "{\"status\": " << examples::json_str(to_string(r.last.status)) << ", \"t_reached\": " << r.last.t_reached
    << ", \"wall_seconds\": {\"median\": " << median(r.wall) << ", \"mean\": " << mean(r.wall)
    << ", \"reps\": " << r.wall.size() << "}, \"share\": {\"broad_phase\": " << k.broad_seconds / total
    << ", \"narrow_phase\": " << k.narrow_seconds / total << ", \"equations_of_motion\": " << k.dynamics_seconds / total
    << ", \"integrator\": " << 1.0 - (k.broad_seconds + k.narrow_seconds + k.dynamics_seconds) / total << "}"
    << ", \"steps\": " << r.last.ode.steps << ", \"error_failures\": " << r.last.ode.error_failures
    << ", \"newton_failures\": " << r.last.ode.newton_failures << ", \"function_failures\": " << r.last.ode.function_failures
    << ", \"rhs_evaluations\": " << r.last.ode.rhs_evaluations << ", \"jacobian_evaluations\": " << r.last.ode.jacobian_evaluations
    << ", \"seconds_per_jacobian\": " << r.last.ode.jacobian_seconds / std::max(1L, r.last.ode.jacobian_evaluations)
    << ", \"lu_decompositions\": " << r.last.ode.lu_decompositions << ", \"newton_iterations\": " << r.last.ode.newton_iterations
    << ", \"restarts\": " << r.last.ode.restarts << ", \"max_order\": " << r.last.ode.max_order_used
    << ", \"scene_updates\": " << k.rhs_calls + k.jacobian_calls << ", \"narrow_rows\": " << k.narrow_rows
    << ", \"active_contacts\": " << k.active_contacts << ", \"contacts_per_step\": {\"max\": " << r.last.step_contacts_max
    << ", \"mean\": " << r.last.step_contacts_mean << "}"
    << ", \"narrow_newton_iterations\": " << k.newton_iterations << ", \"failed_scene_updates\": " << k.failed_calls;
  o.precision(3);
  o << ", \"checks\": {\"momentum_linear_drift\": " << c.momentum_linear << ", \"momentum_angular_drift\": "
    << c.momentum_angular << ", \"wrench_pair_error\": " << c.wrench_pair << ", \"contacts_checked\": "
    << c.contacts_checked << ", \"max_penetration\": " << c.max_penetration << ", \"momentum_ok\": "
    << (c.momentum_ok ? "true" : "false") << ", \"wrench_ok\": " << (c.wrench_ok ? "true" : "false") << "}}";
  return o.str();
}

std::string scene_json(const BodyScene& sc, const Args& a) {
  std::ostringstream o;
  o << "{\"seed\": " << a.seed << ", \"radius\": 6, \"speed\": " << a.speed << ", \"t_end\": " << a.t_end
    << ", \"pairs\": " << sc.shapes.size() * (sc.shapes.size() - 1) / 2 << ", \"contact\": {\"law\": \"hertz\", \"stiffness\": "
    << a.stiffness << ", \"exponent\": " << a.exponent << "}, \"bodies\": [";
  for (std::size_t i = 0; i < sc.shapes.size(); ++i) {
    const MassProperties& m = sc.masses[i];
    const std::vector<Vec3> g = surface_grid(sc.shapes[i], 17, 33);
    o << (i ? ",\n    " : "\n    ") << "{\"name\": " << examples::json_str(sc.names[i])
      << ", \"shape\": " << examples::json_str(describe(sc.shapes[i])) << ", \"mass\": " << m.mass
      << ", \"com\": " << vec_json(m.com_B.data(), 3) << ", \"outer_radius\": " << radii(sc.shapes[i]).outer
      << ", \"surface\": {\"nlat\": 17, \"nlon\": 33, \"points\": " << vec_json(g.front().data(), static_cast<int>(3 * g.size()), 5)
      << "}}";
  }
  o << "]}";
  return o.str();
}

/// The frames of a run: each body's pose and each active contact (where,
/// its normal, its force) at the frame's time.
std::string frames_json(const BodyScene& sc, const Args& a, const Run& r) {
  MultibodySystem sys(sc.shapes, sc.masses, scene_options(a));
  std::ostringstream o;
  o << "[";
  for (std::size_t f = 0; f < r.last.y.size(); ++f) {
    const std::vector<Pose> X = sys.poses(r.last.y[f]);
    o << (f ? ",\n  " : "\n  ") << "{\"t\": " << r.last.t[f] << ", \"R\": [";
    for (std::size_t i = 0; i < X.size(); ++i) {
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = X[i].R;
      o << (i ? ", " : "") << vec_json(R.data(), 9);
    }
    o << "], \"p\": [";
    for (std::size_t i = 0; i < X.size(); ++i) o << (i ? ", " : "") << vec_json(X[i].p.data(), 3);
    o << "], \"contacts\": [";
    bool first = true;
    for (const Contact& k : sys.scene().update(X)) {
      if (!k.active) continue;
      o << (first ? "" : ", ") << "{\"bodies\": [" << k.body1 << ", " << k.body2 << "], \"x\": " << vec_json(k.x_W.data(), 3)
        << ", \"normal\": " << vec_json(k.normal_W.data(), 3) << ", \"f_n\": " << k.f_n << ", \"gap\": " << k.gap << "}";
      first = false;
    }
    o << "]}";
  }
  return o.str() + "]";
}

void print_run(const char* name, const Run& r, const Checks& c) {
  const auto& k = r.last.counters;
  const double total = r.wall.back();
  std::printf("%-18s %s to t = %.3g s in %.3f s (median of %zu; mean %.3f s): broad phase %.1f%%, narrow phase %.1f%%, "
              "equations of motion %.1f%%, integrator (LU, steps) %.1f%%\n",
              name, to_string(r.last.status), r.last.t_reached, median(r.wall), r.wall.size(), mean(r.wall),
              100.0 * k.broad_seconds / total, 100.0 * k.narrow_seconds / total, 100.0 * k.dynamics_seconds / total,
              100.0 * (1.0 - (k.broad_seconds + k.narrow_seconds + k.dynamics_seconds) / total));
  std::printf("%-18s %ld steps (%ld rejected by the error test, %ld by Newton), %ld f evaluations, %ld Jacobians "
              "(%.1f us each), %ld LU, order <= %d, %ld rechart restarts\n",
              "", r.last.ode.steps, r.last.ode.error_failures, r.last.ode.newton_failures, r.last.ode.rhs_evaluations,
              r.last.ode.jacobian_evaluations, 1e6 * r.last.ode.jacobian_seconds / std::max(1L, r.last.ode.jacobian_evaluations),
              r.last.ode.lu_decompositions, r.last.ode.max_order_used, r.last.ode.restarts);
  std::printf("%-18s %ld scene updates, %ld narrow-phase rows (%.2f Newton steps per row), %ld active contacts in "
              "all; contacts per accepted step: %.2f on average, at most %ld\n",
              "", k.rhs_calls + k.jacobian_calls, k.narrow_rows,
              k.narrow_rows ? static_cast<double>(k.newton_iterations) / k.narrow_rows : 0.0, k.active_contacts,
              r.last.step_contacts_mean, r.last.step_contacts_max);
  std::printf("%-18s momentum drift %.2e (linear), %.2e (angular) of the bodies' total: %s; wrench pairs equal and "
              "opposite to %.1e over %d contacts: %s; deepest penetration %.4f\n",
              "", c.momentum_linear, c.momentum_angular, c.momentum_ok ? "ok" : "FAILED", c.wrench_pair,
              c.contacts_checked, c.wrench_ok ? "ok" : "FAILED", c.max_penetration);
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  try {
    const BodyScene sc = paper_ten_bodies(a.seed, 6.0, a.speed);
    std::printf("ten bodies, 45 pairs, Hertz k = %g, p = %g; NDF orders 1-5, rtol %g, atol %g, steps <= %.3g s; %g s\n",
                a.stiffness, a.exponent, a.rtol, a.atol, max_step(sc, a), a.t_end);
    const Run an = integrate(sc, a, true);
    const Checks ca = check(sc, a, an);
    print_run("analytic Jacobian", an, ca);
    bool ok = an.last.status == StiffOdeStatus::Success && ca.momentum_ok && ca.wrench_ok;
    std::string fd_json = "null", ratio = "null";
    if (a.fd) {
      const Run fd = integrate(sc, a, false);
      const Checks cf = check(sc, a, fd);
      print_run("finite differences", fd, cf);
      ok = ok && fd.last.status == StiffOdeStatus::Success && cf.momentum_ok && cf.wrench_ok;
      fd_json = run_json(fd, cf);
      ratio = std::to_string(median(fd.wall) / median(an.wall));
      std::printf("finite-difference Jacobians take %.2fx the time of the analytical ones (the paper: 6.5x, MATLAB)\n",
                  median(fd.wall) / median(an.wall));
    }
    std::ostringstream js;
    js << "{\"example\": \"multibody\", " << examples::provenance_json(examples::command_line(argc, argv)) << ",\n\"scene\": " << scene_json(sc, a)
       << ",\n\"integrator\": {\"method\": \"NDF, variable step, orders 1-5 (ode15s's)\", \"rtol\": " << a.rtol
       << ", \"atol\": " << a.atol << ", \"max_step\": " << max_step(sc, a) << "},\n\"runs\": {\"analytic\": " << run_json(an, ca)
       << ",\n\"finite_difference\": " << fd_json << "},\n\"fd_over_analytic\": " << ratio
       << ",\n\"frames\": " << frames_json(sc, a, an) << "}\n";
    examples::write_whole(a.out, js.str());
    std::printf("wrote %s%s\n", a.out.c_str(), ok ? "" : " (a check FAILED)");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "idcol_multibody: %s\n", e.what());
    return 2;
  }
}

// Time of impact: idcol::time_of_impact against FCL's continuousCollide
// (naive sampling at its default 10 poses and at 100, and conservative
// advancement) on the same motions, each
// answer checked against an oracle that shares no code with either:
//   - sphere-sphere: |r(t)| - (R1 + R2), a closed form;
//   - sphere-ellipsoid: the distance from a point to an ellipsoid (bisection
//     on the Lagrange multiplier), minus the radius;
//   - ellipsoid-ellipsoid: Perram-Wertheim's alpha* (baselines/oracles.hpp) - 1;
//   - cylinder-sphere: the distance from a point to a solid cylinder, for
//     FCL's exact cylinder and for the one the superelliptic cylinder (n = 8)
//     is certified to contain, as for the box below;
//   - box-sphere: the distance from a point to a box (clamping), minus the
//     radius, for the exact box P (FCL's) and for the shrunk box (1 - delta) P
//     that the smooth polytope is certified to contain: idcol's first contact
//     lies between the two; the same for a 0.01-thick plate and a sphere of
//     radius 0.02 (tunnelling).
// The oracle samples its gap function at `samples` times and bisects the
// first sign change; motions whose smallest sampled gap over the whole
// motion lies within 1e-3 of the pair's size of 0 (grazes, too shallow to
// call) are timed but left out of the miss counts.
//
// Motions: body 1 at rest at the identity, body 2 from X0 to X1, seeded:
// "translation" (R1 = R0, FCL CCDM_TRANS) and "screw" (a turn of 0.3..2.5 rad,
// FCL CCDM_SCREW, checked to be the same motion as idcol's at t = 0.37).
// FCL's conservative advancement has no ellipsoid: those rows say so.
//
//   build/baselines/idcol_toi_vs_fcl [--quick] [--motions N] [--samples S]
//                                    [--reps K] [--out results/toi_vs_fcl]
// writes <out>.json and <out>.md. --quick: 40 motions, 400 samples, 1 rep.
#include <fcl/config.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/ellipsoid.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/motion/screw_motion.h>
#include <fcl/narrowphase/continuous_collision.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <sys/utsname.h>
#include <unistd.h>

#include "idcol/toi.hpp"
#include "idcol_baselines/oracles.hpp"
#include "test_util.hpp"

using namespace idcol;
using idcol::test::point_ellipsoid_distance;  // 0 inside: only the sign matters here
using idcol::test::se3_exp;

namespace {

// ---------------------------------------------------------------------------
// Independent geometry for the oracles.

/// Distance from q to the solid cylinder of radius R and half-length h about
/// the x axis; -1 inside.
double cylinder_distance(double R, double h, const Vec3& q) {
  const double da = std::abs(q.x()) - h, dr = std::hypot(q.y(), q.z()) - R;
  if (da <= 0.0 && dr <= 0.0) return -1.0;
  return std::hypot(std::max(da, 0.0), std::max(dr, 0.0));
}

double box_distance(const Vec3& half, const Vec3& q) {
  const Vec3 c = q.cwiseMax(-half).cwiseMin(half);
  if (c == q) return -1.0;  // inside
  return (q - c).norm();
}

/// Screw motion written from its definition (test_util.hpp's SE(3)
/// exponential, Rodrigues' formula), not core's.
Pose screw_at(const Pose& X0, const Vec6& xi, double t) { return X0 * se3_exp(t * xi.head<3>(), t * xi.tail<3>()); }

// ---------------------------------------------------------------------------
// Pairs.

struct PairSpec {
  std::string name;
  Shape body1, body2;
  std::shared_ptr<fcl::CollisionGeometryd> fcl1, fcl2;
  bool fcl_ca = true;  // FCL's conservative advancement has this pair
  double size = 1.0;   // length scale for the graze threshold
  /// gap(X) > 0 iff apart, for the geometry idcol solves (`exact` = false) or
  /// FCL's exact bodies (`exact` = true); they differ for the box, the plate and the cylinder.
  std::function<double(const Pose&, bool exact)> gap;
  /// FCL's frame of body 1 in idcol's (FCL's cylinder runs along z, idcol's along x).
  Mat3 fcl_R1 = Mat3::Identity();
};

std::vector<PairSpec> make_pairs() {
  std::vector<PairSpec> pairs;
  {
    PairSpec p{"Sphere-Sphere", Sphere(0.3), Sphere(0.2), std::make_shared<fcl::Sphered>(0.3),
               std::make_shared<fcl::Sphered>(0.2), true, 0.5, nullptr};
    p.gap = [](const Pose& X, bool) { return X.p.norm() - 0.5; };
    pairs.push_back(p);
  }
  {
    const Vec3 ax(0.6, 0.3, 0.2);
    PairSpec p{"Sphere-Ellip", Sphere(0.3), Superellipsoid(ax[0], ax[1], ax[2], 1.0),
               std::make_shared<fcl::Sphered>(0.3), std::make_shared<fcl::Ellipsoidd>(ax[0], ax[1], ax[2]), false, 0.5,
               nullptr};
    p.gap = [ax](const Pose& X, bool) { return point_ellipsoid_distance(ax, X.R.transpose() * (-X.p)) - 0.3; };
    pairs.push_back(p);
  }
  {
    const Vec3 a1(0.5, 0.3, 0.2), a2(0.6, 0.25, 0.2);
    PairSpec p{"Ellip-Ellip", Superellipsoid(a1[0], a1[1], a1[2], 1.0), Superellipsoid(a2[0], a2[1], a2[2], 1.0),
               std::make_shared<fcl::Ellipsoidd>(a1[0], a1[1], a1[2]),
               std::make_shared<fcl::Ellipsoidd>(a2[0], a2[1], a2[2]), false, 0.5, nullptr};
    p.gap = [a1, a2](const Pose& X, bool) {
      const baselines::OracleAnswer o = baselines::perram_wertheim(a1, a2, X);
      return o.ok ? o.alpha - 1.0 : std::nan("");
    };
    pairs.push_back(p);
  }
  {
    const Vec3 half(0.5, 0.4, 0.3);
    const double beta = 2000.0, Rs = 0.2;
    // SmoothPolytope's certified shrink: it holds (1 - log(m) / (beta b_min)) P.
    const double shrink = 1.0 - std::log(6.0) / (beta * half.minCoeff());
    PairSpec p{"Box-Sphere",
               SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
                              {half[0], half[0], half[1], half[1], half[2], half[2]}, beta),
               Sphere(Rs), std::make_shared<fcl::Boxd>(2 * half[0], 2 * half[1], 2 * half[2]),
               std::make_shared<fcl::Sphered>(Rs), true, 0.5, nullptr};
    p.gap = [half, shrink, Rs](const Pose& X, bool exact) {
      return box_distance(exact ? half : Vec3(shrink * half), X.p) - Rs;
    };
    pairs.push_back(p);
  }
  {
    // A superelliptic cylinder of exponent n lies inside the exact cylinder
    // (FCL's) and holds it scaled by 2^(-1/(2n)): the sum of two terms each
    // at most c^(2n) is at most 1 when c^(2n) <= 1/2.
    const double R = 0.3, h = 0.4, n = 8.0, Rs = 0.2;
    const double shrink = std::pow(2.0, -1.0 / (2.0 * n));
    PairSpec p{"Cylinder-Sphere", SuperellipticCylinder(R, h, n), Sphere(Rs),
               std::make_shared<fcl::Cylinderd>(R, 2 * h), std::make_shared<fcl::Sphered>(Rs), true, 0.4, nullptr};
    p.gap = [R, h, shrink, Rs](const Pose& X, bool exact) {
      const double c = exact ? 1.0 : shrink;
      return cylinder_distance(c * R, c * h, X.p) - Rs;
    };
    p.fcl_R1 = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();  // FCL's z onto idcol's x
    pairs.push_back(p);
  }
  {
    // Tunnelling: a 0.01-thick plate and a small sphere crossing it.
    const Vec3 half(0.5, 0.5, 0.005);
    const double beta = 10000.0, Rs = 0.02;
    const double shrink = 1.0 - std::log(6.0) / (beta * half.minCoeff());
    PairSpec p{"Plate-SmallSphere",
               SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
                              {half[0], half[0], half[1], half[1], half[2], half[2]}, beta),
               Sphere(Rs), std::make_shared<fcl::Boxd>(2 * half[0], 2 * half[1], 2 * half[2]),
               std::make_shared<fcl::Sphered>(Rs), true, 0.02, nullptr};
    p.gap = [half, shrink, Rs](const Pose& X, bool exact) {
      return box_distance(exact ? half : Vec3(shrink * half), X.p) - Rs;
    };
    pairs.push_back(p);
  }
  return pairs;
}

struct Motion {
  Pose X0, X1;
  Vec6 xi;
};

std::vector<Motion> make_motions(bool screw, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto unit = [&] { return Vec3(g(rng), g(rng), g(rng)).normalized(); };
  auto rotation = [&] { return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix(); };
  std::vector<Motion> out;
  for (int k = 0; k < n; ++k) {
    Motion m;
    const Vec3 d = unit();
    m.X0.R = rotation();
    m.X0.p = (1.5 + u(rng)) * d;
    m.X1.R = screw ? Mat3(m.X0.R * Eigen::AngleAxisd(0.3 + 2.2 * u(rng), unit()).toRotationMatrix()) : m.X0.R;
    m.X1.p = -(1.5 + u(rng)) * d + 1.2 * u(rng) * unit();
    m.xi = se3_log(m.X0.inverse() * m.X1);
    if (!screw) m.xi.head<3>().setZero(), m.xi.tail<3>() = m.X0.R.transpose() * (m.X1.p - m.X0.p);
    out.push_back(m);
  }
  return out;
}

/// The oracle's first contact of one geometry along a motion.
struct OracleToi {
  bool hit = false;
  double t = 1.0;
  double min_gap = 1e300;
};

OracleToi oracle_toi(const PairSpec& P, const Motion& m, bool exact, int samples) {
  OracleToi o;
  auto gap = [&](double t) { return P.gap(screw_at(m.X0, m.xi, t), exact); };
  double prev = 0.0;
  for (int j = 0; j <= samples; ++j) {
    const double t = static_cast<double>(j) / samples, gv = gap(t);
    o.min_gap = std::min(o.min_gap, gv);
    if (gv <= 0.0 && !o.hit) {
      double lo = prev, hi = t;
      for (int it = 0; it < 60 && j > 0; ++it) {
        const double mid = 0.5 * (lo + hi);
        (gap(mid) > 0.0 ? lo : hi) = mid;
      }
      o.hit = true;
      o.t = hi;
    }
    prev = t;
  }
  return o;
}

fcl::Transform3d to_fcl(const Pose& X) {
  fcl::Transform3d T = fcl::Transform3d::Identity();
  T.linear() = X.R;
  T.translation() = X.p;
  return T;
}

struct Tally {
  std::string method;
  bool supported = true;
  int motions = 0, clear_hits = 0, clear_misses = 0, grazes = 0;
  int misses = 0;      // oracle: clear hit; method: no contact
  int false_hits = 0;  // oracle: clear miss; method: contact
  int undecided = 0;   // idcol: NumericalFailure or IterationLimit
  double max_t_error = 0.0;
  double solves = 0.0;  // per query (idcol: solves; naive: collide calls)
  std::vector<double> us_per_query;
  double median_us() const {
    if (us_per_query.empty()) return std::nan("");
    std::vector<double> v = us_per_query;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  }
};

std::string shell(const char* cmd) {
  std::string out;
  if (FILE* f = popen(cmd, "r")) {
    char buf[256];
    while (fgets(buf, sizeof buf, f)) out += buf;
    pclose(f);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string json_str(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    o += c;
  }
  return o + "\"";
}

std::string fmt(double x, int prec = 4) {
  if (std::isnan(x)) return "null";
  std::ostringstream os;
  os.precision(prec);
  os << x;
  return os.str();
}

}  // namespace

int main(int argc, char** argv) {
  int motions = 200, samples = 2000, reps = 5;
  std::string out = "results/toi_vs_fcl";
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--quick") {
      quick = true;
      motions = 40;
      samples = 400;
      reps = 1;
    } else if (a == "--motions") {
      motions = std::atoi(next().c_str());
    } else if (a == "--samples") {
      samples = std::atoi(next().c_str());
    } else if (a == "--reps") {
      reps = std::atoi(next().c_str());
    } else if (a == "--out") {
      out = next();
    } else {
      std::fprintf(stderr, "usage: %s [--quick] [--motions N] [--samples S] [--reps K] [--out PREFIX]\n", argv[0]);
      return 2;
    }
  }
  if (motions < 1 || samples < 10 || reps < 1) {
    std::fprintf(stderr, "--motions >= 1, --samples >= 10, --reps >= 1\n");
    return 2;
  }

  const std::vector<PairSpec> pairs = make_pairs();
  const int naive_steps = 100;
  struct Row {
    std::string pair, motion;
    std::vector<Tally> tallies;
    double fcl_screw_deviation = 0.0;
  };
  std::vector<Row> rows;
  long total_misses_idcol = 0;

  for (const PairSpec& P : pairs) {
    for (int screw = 0; screw < 2; ++screw) {
      const std::vector<Motion> ms = make_motions(screw, motions, 35u + 1000u * screw);
      Row row{P.name, screw ? "screw" : "translation", {}, 0.0};
      fcl::ContinuousCollisionRequestd req_naive(naive_steps, 1.0 / naive_steps, screw ? fcl::CCDM_SCREW : fcl::CCDM_TRANS,
                                                 fcl::GST_LIBCCD, fcl::CCDC_NAIVE);
      // FCL's default request: num_max_iterations = 10, so 10 poses.
      fcl::ContinuousCollisionRequestd req_default;
      req_default.ccd_motion_type = screw ? fcl::CCDM_SCREW : fcl::CCDM_TRANS;
      fcl::ContinuousCollisionRequestd req_ca(100, 1e-6, screw ? fcl::CCDM_SCREW : fcl::CCDM_TRANS, fcl::GST_LIBCCD,
                                              fcl::CCDC_CONSERVATIVE_ADVANCEMENT);
      // FCL's screw is idcol's: compare the pose at t = 0.37.
      if (screw)
        for (const Motion& m : ms) {
          fcl::ScrewMotion<double> sm(to_fcl(m.X0), to_fcl(m.X1));
          sm.integrate(0.37);
          fcl::Transform3d T;
          sm.getCurrentTransform(T);
          const Pose Xi = screw_interpolate(m.X0, m.X1, 0.37);
          row.fcl_screw_deviation =
              std::max(row.fcl_screw_deviation, std::max((T.linear() - Xi.R).norm(), (T.translation() - Xi.p).norm()));
        }
      // Oracles.
      std::vector<OracleToi> o_ours(ms.size()), o_exact(ms.size()), o_shrunk(ms.size());
      for (std::size_t k = 0; k < ms.size(); ++k) {
        o_exact[k] = oracle_toi(P, ms[k], true, samples);
        o_shrunk[k] = oracle_toi(P, ms[k], false, samples);
      }
      auto classify = [&](const OracleToi& o, Tally& t) {
        ++t.motions;
        if (std::abs(o.min_gap) < 1e-3 * P.size) return 0;
        if (o.hit) return ++t.clear_hits, 1;
        return ++t.clear_misses, -1;
      };
      // idcol: its geometry lies between the exact body and the shrunk one.
      Tally ti;
      ti.method = "idcol_toi";
      std::vector<ToiResult> res(ms.size());
      for (int r = 0; r < reps; ++r) {
        const auto c0 = std::clock();
        for (std::size_t k = 0; k < ms.size(); ++k) res[k] = time_of_impact(P.body1, P.body2, ms[k].X0, ms[k].X1);
        ti.us_per_query.push_back(1e6 * double(std::clock() - c0) / CLOCKS_PER_SEC / ms.size());
      }
      for (std::size_t k = 0; k < ms.size(); ++k) {
        // clear hit: the shrunk body is hit; clear miss: the exact one is missed
        const OracleToi& lo = o_exact[k];
        const OracleToi& hi = o_shrunk[k];
        ++ti.motions;
        ti.solves += res[k].solves;
        if (res[k].status == ToiStatus::NumericalFailure || res[k].status == ToiStatus::IterationLimit) {
          ++ti.undecided;
          std::printf("UNDECIDED idcol %s %s motion %zu: %s, t_free %.17g\n", P.name.c_str(), row.motion.c_str(), k,
                      to_string(res[k].status), res[k].t_free);
        }
        const bool said_hit = res[k].status == ToiStatus::Impact || res[k].status == ToiStatus::InitiallyInContact;
        const bool graze = std::abs(lo.min_gap) < 1e-3 * P.size || std::abs(hi.min_gap) < 1e-3 * P.size;
        if (graze) {
          ++ti.grazes;
        } else if (hi.hit) {
          ++ti.clear_hits;
          if (!said_hit) {
            ++ti.misses;
            std::printf("MISS idcol %s %s motion %zu: oracle t in [%.17g, %.17g], status %s\n", P.name.c_str(),
                        row.motion.c_str(), k, lo.t, hi.t, to_string(res[k].status));
          } else {
            const double err = std::max({0.0, lo.t - res[k].t, res[k].t - hi.t});
            ti.max_t_error = std::max(ti.max_t_error, err);
          }
        } else if (!lo.hit) {
          ++ti.clear_misses;
          if (said_hit) ++ti.false_hits;
        } else {
          ++ti.grazes;  // between the two bodies: either answer is right
        }
      }
      ti.solves /= ms.size();
      total_misses_idcol += ti.misses;
      row.tallies.push_back(ti);

      // FCL: the exact bodies.
      for (int method = 0; method < 3; ++method) {
        Tally tf;
        tf.method = method == 0 ? "fcl_naive_10_default" : method == 1 ? "fcl_naive_100" : "fcl_conservative_advancement";
        const auto& req = method == 0 ? req_default : method == 1 ? req_naive : req_ca;
        const int steps = method == 0 ? 10 : naive_steps;
        if (method == 2 && !P.fcl_ca) {
          tf.supported = false;
          row.tallies.push_back(tf);
          continue;
        }
        std::vector<fcl::ContinuousCollisionResultd> fr(ms.size());
        fcl::Transform3d I = fcl::Transform3d::Identity();
        I.linear() = P.fcl_R1;
        for (int r = 0; r < reps; ++r) {
          const auto c0 = std::clock();
          for (std::size_t k = 0; k < ms.size(); ++k) {
            fr[k] = fcl::ContinuousCollisionResultd();
            fcl::continuousCollide(P.fcl1.get(), I, I, P.fcl2.get(), to_fcl(ms[k].X0), to_fcl(ms[k].X1), req, fr[k]);
          }
          tf.us_per_query.push_back(1e6 * double(std::clock() - c0) / CLOCKS_PER_SEC / ms.size());
        }
        for (std::size_t k = 0; k < ms.size(); ++k) {
          const int c = classify(o_exact[k], tf);
          if (method < 2) tf.solves += fr[k].is_collide ? std::round(fr[k].time_of_contact * (steps - 1)) + 1 : steps;
          if (c == 0) {
            ++tf.grazes;
          } else if (c == 1) {
            if (!fr[k].is_collide) {
              ++tf.misses;
              if (method == 2)
                std::printf("MISS %s %s %s motion %zu: oracle t = %.17g, min gap %.3g\n", tf.method.c_str(),
                            P.name.c_str(), row.motion.c_str(), k, o_exact[k].t, o_exact[k].min_gap);
            }
            else tf.max_t_error = std::max(tf.max_t_error, std::abs(fr[k].time_of_contact - o_exact[k].t));
          } else if (fr[k].is_collide) {
            ++tf.false_hits;
          }
        }
        tf.solves = method < 2 ? tf.solves / ms.size() : std::nan("");
        row.tallies.push_back(tf);
      }
      rows.push_back(row);
      std::printf("%-14s %-11s", P.name.c_str(), row.motion.c_str());
      for (const Tally& t : row.tallies)
        if (t.supported)
          std::printf("  %s: %.2f us, misses %d/%d, false %d, |dt| %.1e", t.method.c_str(), t.median_us(), t.misses,
                      t.clear_hits, t.false_hits, t.max_t_error);
      std::printf("\n");
      std::fflush(stdout);
    }
  }

  // ---- metadata and files --------------------------------------------------
  utsname un{};
  uname(&un);
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) < 0) load[0] = load[1] = load[2] = std::nan("");
  const std::string git = shell("git rev-parse --short HEAD 2>/dev/null");
  // Dirty: a tracked file outside results/ differs (results files are outputs).
  const std::string dirty = shell("git status --porcelain --untracked-files=no -- . ':(exclude)results' 2>/dev/null | head -1");
  const std::string cpu = shell("grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2 | sed 's/^ //'");
  std::string cmd;
  for (int i = 0; i < argc; ++i) cmd += (i ? " " : "") + std::string(argv[i]);

  std::ofstream js(out + ".json");
  js << "{\n  \"context\": {\n"
     << "    \"date\": " << json_str(date) << ",\n"
     << "    \"command\": " << json_str(cmd) << ",\n"
     << "    \"git_revision\": " << json_str(git + (dirty.empty() ? "" : "-dirty")) << ",\n"
     << "    \"host\": " << json_str(un.nodename) << ",\n"
     << "    \"kernel\": " << json_str(std::string(un.sysname) + " " + un.release) << ",\n"
     << "    \"cpu\": " << json_str(cpu) << ",\n"
     << "    \"num_cpus\": " << sysconf(_SC_NPROCESSORS_ONLN) << ",\n"
     << "    \"load_avg\": [" << fmt(load[0]) << ", " << fmt(load[1]) << ", " << fmt(load[2]) << "],\n"
     << "    \"compiler\": " << json_str(IDCOL_TOI_COMPILER) << ",\n"
     << "    \"build_type\": " << json_str(IDCOL_TOI_BUILD_TYPE) << ",\n"
     << "    \"flags\": " << json_str(IDCOL_TOI_FLAGS) << ",\n"
     << "    \"fcl_version\": " << json_str(FCL_VERSION) << ",\n"
     << "    \"quick\": " << (quick ? "true" : "false") << ",\n"
     << "    \"motions_per_scene\": " << motions << ",\n"
     << "    \"oracle_samples\": " << samples << ",\n"
     << "    \"repetitions\": " << reps << ",\n"
     << "    \"timer\": \"std::clock (process CPU time); median over repetitions of the mean per query\"\n"
     << "  },\n  \"rows\": [\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    for (std::size_t j = 0; j < r.tallies.size(); ++j) {
      const Tally& t = r.tallies[j];
      js << "    {\"pair\": " << json_str(r.pair) << ", \"motion\": " << json_str(r.motion)
         << ", \"method\": " << json_str(t.method) << ", \"supported\": " << (t.supported ? "true" : "false");
      if (t.supported)
        js << ", \"motions\": " << t.motions << ", \"clear_hits\": " << t.clear_hits
           << ", \"clear_misses\": " << t.clear_misses << ", \"grazes\": " << t.grazes << ", \"misses\": " << t.misses
           << ", \"false_hits\": " << t.false_hits << ", \"undecided\": " << t.undecided
           << ", \"max_t_error\": " << fmt(t.max_t_error, 3)
           << ", \"us_per_query\": " << fmt(t.median_us()) << ", \"solves_per_query\": " << fmt(t.solves);
      if (r.motion == "screw") js << ", \"fcl_screw_deviation\": " << fmt(r.fcl_screw_deviation, 3);
      js << "}" << (i + 1 == rows.size() && j + 1 == r.tallies.size() ? "" : ",") << "\n";
    }
  }
  js << "  ]\n}\n";

  std::ofstream md(out + ".md");
  md << "# Time of impact against FCL continuousCollide\n\n"
     << "`" << out << ".json`, written by\n\n    " << cmd << "\n\n"
     << "- git revision: " << git << (dirty.empty() ? "" : " (with uncommitted changes)") << "; " << date << "\n"
     << "- machine: " << cpu << ", " << sysconf(_SC_NPROCESSORS_ONLN) << " CPUs, " << un.sysname << " " << un.release
     << ", load average " << fmt(load[0], 3) << "\n"
     << "- compiler: " << IDCOL_TOI_COMPILER << ", " << IDCOL_TOI_BUILD_TYPE << ", flags `" << IDCOL_TOI_FLAGS
     << "`; FCL " << FCL_VERSION << "\n"
     << "- " << motions << " motions per pair and motion kind, oracle sampled at " << samples
     << " times then bisected; CPU time per query, median of " << reps << " repetitions"
     << (quick ? " (--quick: a smoke run, not for quoting)" : "") << "\n\n"
     << "A miss is a motion the oracle says clearly hits (smallest sampled gap over the motion below -1e-3 of the pair's size; for idcol's "
        "smoothed box, the shrunk box it certainly contains is hit) where the method reports no contact. "
        "|dt| is the largest error in the time of contact over the hits it found (idcol: distance outside the "
        "oracle's bracket). FCL naive sampling tests 10 poses (its default request) or "
     << naive_steps
     << "; its solves column counts the collide calls made. FCL's conservative advancement reports no count.\n\n"
     << "| pair | motion | method | clear hits | misses | false hits | grazes left out | max abs dt | us / query | "
        "solves / query |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows)
    for (const Tally& t : r.tallies) {
      if (!t.supported) {
        md << "| " << r.pair << " | " << r.motion << " | " << t.method
           << " | - | - | - | - | - | not supported by FCL | - |\n";
        continue;
      }
      md << "| " << r.pair << " | " << r.motion << " | " << t.method << " | " << t.clear_hits << " | " << t.misses
         << " | " << t.false_hits << " | " << t.grazes << " | " << fmt(t.max_t_error, 2) << " | "
         << fmt(t.median_us(), 3) << " | " << (std::isnan(t.solves) ? std::string("n/a") : fmt(t.solves, 3)) << " |\n";
    }
  double dev = 0.0;
  for (const Row& r : rows) dev = std::max(dev, r.fcl_screw_deviation);
  md << "\nFCL's screw motion agrees with idcol's X0 exp(t log(X0^-1 X1)) to " << fmt(dev, 2)
     << " (largest pose difference at t = 0.37 over the screw motions).\n";
  std::printf("wrote %s.json and %s.md; idcol misses: %ld\n", out.c_str(), out.c_str(), total_misses_idcol);
  long undecided = 0;
  for (const Row& r : rows) undecided += r.tallies[0].undecided;
  md << "idcol left " << undecided << " motions undecided (NumericalFailure or IterationLimit).\n";
  return total_misses_idcol == 0 ? 0 : 1;
}

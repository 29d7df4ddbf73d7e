#include "studies/toi/toi.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>

#include "exec/chains.hpp"
#include "gen/poses.hpp"
#include "idcol/toi.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "io/record.hpp"
#include "io/text.hpp"
#include "studies/entry_shards.hpp"
#include "studies/toi/toi_fcl.hpp"
#include "studies/toi/toi_keys.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {
/// CPU seconds of this thread: time per query that other processes on a
/// shared machine do not inflate (wall time does, by whole time slices).
double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

ToiMotion toi_motion(const ToiSpec& spec, double L, bool screw, std::uint64_t k) {
  const std::uint64_t base = 4 * ((spec.seed << 20) + k);
  const auto a = halton6(base), b = halton6(base + 1), c = halton6(base + 2);
  ToiMotion m;
  m.X0.R = uniform_rotation(a[0], a[1], a[2]);
  const Vec3 dir = uniform_direction(a[3], a[4]);
  m.X0.p = (1.05 + spec.spread * a[5]) * L * dir;
  if (c[0] < spec.end_inside) {
    m.X1.p = c[1] * L * uniform_direction(c[2], c[3]);
  } else {
    m.X1.p = -(1.05 + spec.spread * b[0]) * L * dir + spec.offset * b[1] * L * uniform_direction(b[2], b[3]);
  }
  m.X1.R = m.X0.R;
  if (screw) {
    const double turn = spec.turn_min + (spec.turn_max - spec.turn_min) * b[4];
    m.X1.R = m.X0.R * Eigen::AngleAxisd(turn, uniform_direction(b[5], c[4])).toRotationMatrix();
  }
  return m;
}

std::string ToiTally::add(const baselines::ToiOracleAnswer& o, const ToiAnswer& a) {
  ++motions;
  solves += a.solves;
  if (!a.decided) {
    ++failures;
    return "failure";
  }
  if (a.initial) ++initial;
  else if (a.hit) ++impacts;
  else ++no_impacts;
  if (o.clear_hit && !a.hit) return ++missed, "missed_contact";
  if (o.clear_miss && a.hit) return ++false_impacts, "false_impact";
  if (o.clear_hit && a.hit) t_error_max = std::max({t_error_max, o.t_lo - a.t, a.t - o.t_hi});
  return "";
}

json ToiTally::to_json() const {
  const double n = motions ? static_cast<double>(motions) : 1.0;
  return {{key::impacts, impacts},
          {key::no_impacts, no_impacts},
          {key::initially_in_contact, initial},
          {key::failures, failures},
          {key::missed_contacts, missed},
          {key::false_impacts, false_impacts},
          {key::t_error, {{key::max, t_error_max}}},
          {key::solves_per_query, solves / n},
          {key::us_per_query, 1e6 * seconds / n}};
}

namespace {

/// The record of a motion a method got wrong (or could not decide), with
/// what the oracle said: the poses at 17 digits, ready for a test.
json toi_record(const Scene& s, int i1, int i2, const std::string& model, std::uint64_t k, const ToiMotion& m,
                const std::string& method, const std::string& problem, const ToiAnswer& a,
                const baselines::ToiOracleAnswer& o, const std::string& status) {
  FailureSite site{s.shapes[i1].name, s.shapes[i2].name, &*s.shapes[i1].shape, &*s.shapes[i2].shape, model, k, "toi"};
  json f = failure_record(site, m.X0);
  f["problem"] = problem;
  f["method"] = method;
  f["X1"] = pose_to_json(m.X1);
  f["X1_text"] = pose_text(m.X1);
  f["status"] = status;
  f["t"] = a.t;
  f["oracle_t"] = {o.t_lo, o.t_hi};
  f["oracle_min_alpha"] = {o.min_lo, o.min_hi};
  return f;
}

}  // namespace

json run_toi(const Scene& s, const StudyOptions& opt, const json& metadata, json& failures) {
  const ToiSpec& spec = s.spec.as<ToiSpec>();
  const auto wall0 = Clock::now();
  json entries = json::array();
  std::vector<std::size_t> ran;
  ToiOptions toi_opt;
  toi_opt.solver = s.solver;
  toi_opt.derivatives = false;  // FCL gives none: both sides answer the same question
  std::size_t index = 0;
  for (const auto& [i1, i2] : spec.pairs) {
    const Shape& b1 = *s.shapes[i1].shape;
    const Shape& b2 = *s.shapes[i2].shape;
    const double L = radii(b1).outer + radii(b2).outer;
    const baselines::ToiOracle oracle(baselines::to_desc(b1), baselines::to_desc(b2),
                                      {spec.oracle_samples, spec.graze, 60});
    std::string fcl_why;
    const std::unique_ptr<FclToi> fcl = spec.fcl.empty() ? nullptr : make_fcl_toi(b1, b2, fcl_why);
    if (spec.fcl.empty()) fcl_why = "not asked for by the scene";
    for (const std::string& model : spec.models) {
      const std::size_t entry = index++;
      if (!in_shard(entry, opt.shard_index, opt.shard_count)) continue;
      ran.push_back(entry);
      const auto entry0 = Clock::now();
      const bool screw = model == "screw";
      std::vector<ToiMotion> motions(spec.motions);
      for (std::uint64_t k = 0; k < spec.motions; ++k) motions[k] = toi_motion(spec, L, screw, k);
      if (opt.progress)
        std::fprintf(stderr, "\r%-60s", (s.shapes[i1].name + "-" + s.shapes[i2].name + "/" + model + ": oracle").c_str());
      std::vector<baselines::ToiOracleAnswer> truth(motions.size());
      std::uint64_t grazes = 0, clear_hits = 0, clear_misses = 0;
      for (std::size_t k = 0; k < motions.size(); ++k) {
        if (interrupt_flag().load()) throw Interrupted();  // the oracle is the slow part: Ctrl-C stops here
        truth[k] = oracle.first_contact(motions[k].X0, motions[k].X1);
        clear_hits += truth[k].clear_hit;
        clear_misses += truth[k].clear_miss;
        grazes += !truth[k].clear_hit && !truth[k].clear_miss;
      }
      // idcol: every motion timed in one loop, then tallied.
      std::vector<ToiResult> res(motions.size());
      std::vector<std::string> thrown(motions.size());
      ToiTally ours;
      ours.seconds = INFINITY;
      for (int loop = 0; loop < kToiTimingLoops; ++loop) {
        const double t0 = thread_seconds();
        for (std::size_t k = 0; k < motions.size(); ++k) {
          try {
            ToiResult r = time_of_impact(b1, b2, motions[k].X0, motions[k].X1, toi_opt);
            if (loop == 0) res[k] = r;
          } catch (const std::exception& e) {
            thrown[k] = e.what();
          }
        }
        ours.seconds = std::min(ours.seconds, thread_seconds() - t0);
      }
      for (std::size_t k = 0; k < motions.size(); ++k) {
        const ToiResult& r = res[k];
        ToiAnswer a;
        a.decided = thrown[k].empty() && r.status != ToiStatus::NumericalFailure && r.status != ToiStatus::IterationLimit;
        a.initial = r.status == ToiStatus::InitiallyInContact;
        a.hit = r.status == ToiStatus::Impact || a.initial;
        a.t = r.t;
        a.solves = r.solves;
        const std::string problem = ours.add(truth[k], a);
        if (!problem.empty())
          failures.push_back(toi_record(s, i1, i2, model, k, motions[k], "idcol", problem, a, truth[k],
                                        thrown[k].empty() ? to_string(r.status) : "threw: " + thrown[k]));
      }
      json ej = {{"name", s.shapes[i1].name + "-" + s.shapes[i2].name + "/" + model},
                 {"body1", s.shapes[i1].name},
                 {"body2", s.shapes[i2].name},
                 {"model", model},
                 {key::motions, spec.motions},
                 {"oracle_method", oracle.method()},
                 {key::oracle_verdicts, {{key::clear_hits, clear_hits}, {key::clear_misses, clear_misses}, {key::grazes, grazes}}},
                 {key::idcol_toi, ours.to_json()}};
      // FCL on the same motions, its exact bodies checked against the same
      // oracle (a smoothed body lies inside FCL's, so a clear hit of the
      // smooth bodies is one of FCL's as well, and a clear miss of the
      // oracle's outer bodies one of FCL's).
      json fj = json::object();
      json unsupported = json::object();
      if (!fcl) {
        for (const std::string& m : spec.fcl) unsupported[m] = fcl_why;
      } else {
        for (const std::string& method : spec.fcl) {
          if (opt.progress)
            std::fprintf(stderr, "\r%-60s", (s.shapes[i1].name + "-" + s.shapes[i2].name + "/" + model + ": fcl " + method).c_str());
          // One query first: FCL answers -1 (and prints a warning) where it
          // has no such solver for the pair.
          if (!motions.empty() && !fcl->query(method, motions[0].X0, motions[0].X1, screw, spec.fcl_naive_steps).supported) {
            unsupported[method] = "FCL's continuousCollide has no " + method + " for this pair";
            continue;
          }
          std::vector<FclToiAnswer> fr(motions.size());
          ToiTally tf;
          tf.seconds = INFINITY;
          for (int loop = 0; loop < kToiTimingLoops; ++loop) {
            const double f0 = thread_seconds();
            for (std::size_t k = 0; k < motions.size(); ++k) {
              const FclToiAnswer a = fcl->query(method, motions[k].X0, motions[k].X1, screw, spec.fcl_naive_steps);
              if (loop == 0) fr[k] = a;
            }
            tf.seconds = std::min(tf.seconds, thread_seconds() - f0);
          }
          if (std::any_of(fr.begin(), fr.end(), [](const FclToiAnswer& a) { return !a.supported; })) {
            unsupported[method] = "FCL's continuousCollide has no " + method + " for this pair";
            continue;
          }
          const bool naive = method == "naive";
          for (std::size_t k = 0; k < motions.size(); ++k) {
            ToiAnswer a;
            a.hit = fr[k].hit;
            a.t = fr[k].t;
            a.initial = fr[k].hit && fr[k].t == 0.0;
            // naive: the collide calls made (up to the first pose in contact); CA reports none.
            a.solves = naive ? (fr[k].hit ? std::round(fr[k].t * (spec.fcl_naive_steps - 1)) + 1 : spec.fcl_naive_steps) : NAN;
            tf.add(truth[k], a);
          }
          fj[method] = tf.to_json();
        }
      }
      ej[key::fcl_methods] = fj;
      if (!unsupported.empty()) ej["fcl_not_run"] = unsupported;
      ej["wall_seconds"] = std::chrono::duration<double>(Clock::now() - entry0).count();
      entries.push_back(std::move(ej));
    }
  }
  if (opt.progress) std::fprintf(stderr, "\r%60s\r", "");
  json r = results_header(kToiSchema, metadata, {s.path, s.name, s.text}, s.solver);
  r.update(json{{"failure_records", failures.size()},
                {"wall_seconds", std::chrono::duration<double>(Clock::now() - wall0).count()},
                {key::toi_pairs, entries}});
  if (opt.shard_count > 1) r["shard"] = entry_shard_json(opt.shard_index, opt.shard_count, ran);
  return r;
}

namespace {
std::string cell(const json& j, const char* k, int digits = 3) {
  const json* v = j.contains(k) ? &j.at(k) : nullptr;
  if (!v || v->is_null()) return "-";
  if (v->is_number_unsigned() || v->is_number_integer()) return std::to_string(v->get<long long>());
  return sci(v->get<double>(), digits);
}
}  // namespace

std::string toi_markdown(const json& R, const std::string& path) {
  if (R.value("schema", "") != kToiSchema) throw std::runtime_error(path + ": not a time-of-impact results file");
  const json& m = R.at("metadata");
  std::string o = "# Time of impact: " + md_text(R.at("scene").value("name", std::string())) + "\n\n";
  o += md_code(path) + ", from the scene " + md_code(R.at("scene").value("path", std::string())) + "; " +
       format("wall %.1f s", R.at("wall_seconds").get<double>()) + "; git " + md_text(m.value("git_revision", std::string("?"))) +
       "; " + md_text(m.value("cpu_model", std::string("?"))) + ", " + std::to_string(m.value("logical_cores", 0)) + " logical cores.\n\n";
  o += "Each motion's answer is checked against an oracle that shares no code with the solver (closed form for two spheres, "
       "Perram-Wertheim for ellipsoids, the support-function bracket otherwise; sampled along the motion, then bisected). "
       "A miss: the oracle sees a clear hit, the method reports no contact. |dt|: the largest distance of a reported time "
       "of contact outside the oracle's bracket. idcol runs without derivatives (FCL gives none). FCL works on the exact "
       "bodies (a smooth polytope's polytope); its naive method tests evenly spaced poses, its solves column the collide calls "
       "made. Times are the thread's CPU time per query, the fastest of 3 loops over the entry's motions, on whatever machine made the file (its metadata says which).\n\n";
  o += "| pair / motion | oracle hits / misses / grazes | method | impacts | no impact | failures | misses | false impacts | max abs dt | solves / query | us / query |\n";
  o += "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const json& e : R.at(key::toi_pairs)) {
    const json& ov = e.at(key::oracle_verdicts);
    const std::string head = "| " + md_text(e.at("name").get<std::string>()) + " | " + cell(ov, key::clear_hits) + " / " +
                             cell(ov, key::clear_misses) + " / " + cell(ov, key::grazes) + " | ";
    auto row = [&](const std::string& method, const json& t) {
      o += head + method + " | " + cell(t, key::impacts) + " | " + cell(t, key::no_impacts) + " | " + cell(t, key::failures) +
           " | " + cell(t, key::missed_contacts) + " | " + cell(t, key::false_impacts) + " | " +
           cell(t.at(key::t_error), key::max, 2) + " | " + cell(t, key::solves_per_query) + " | " + cell(t, key::us_per_query) + " |\n";
    };
    row("idcol", e.at(key::idcol_toi));
    for (const auto& [method, t] : e.at(key::fcl_methods).items()) row("fcl " + md_text(method), t);
    if (e.contains("fcl_not_run"))
      for (const auto& [method, why] : e.at("fcl_not_run").items())
        o += head + "fcl " + md_text(method) + " | " + md_text(why.get<std::string>()) + " | | | | | | | |\n";
  }
  return o;
}

}  // namespace idcol::harness

#include "studies/sweep/sweep.hpp"

#include <sched.h>
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cerrno>
#include <cstring>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "idcol/batch.hpp"
#include "studies/sweep/agreement.hpp"
#include "referee/checks.hpp"
#include "io/solver_options.hpp"
#include "stats/stats.hpp"
#include "studies/entry_shards.hpp"
#include "io/files.hpp"
#include "io/text.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

const char* per_pose_csv_header() { return "body1,body2,pass,k,status,iterations,alpha,residual,time_ns\n"; }

namespace {

class CollectingTrace : public TraceSink {
 public:
  void record(const TraceRecord& r) override {
    trace.push_back({{"run", r.run},
                     {"run_kind", r.run_kind ? r.run_kind : ""},
                     {"sharp1", r.sharp1},
                     {"sharp2", r.sharp2},
                     {"iteration", r.iteration},
                     {"z", {r.z[0], r.z[1], r.z[2], r.z[3], r.z[4], r.z[5]}},
                     {"residual", r.residual},
                     {"step", r.step ? r.step : ""},
                     {"step_length", r.step_length}});
  }
  json trace = json::array();
};

std::uint64_t involuntary_switches() {
  rusage ru{};
  getrusage(RUSAGE_THREAD, &ru);
  return static_cast<std::uint64_t>(ru.ru_nivcsw);
}

bool is_failure(const SolveResult& r) { return r.status != SolveStatus::Converged && r.status != SolveStatus::Concentric; }

struct Progress {
  bool on = false;
  std::uint64_t total = 0;
  std::atomic<std::uint64_t> done{0};
  Clock::time_point start = Clock::now(), last = start;
  /// Counts a pose; only the `show` thread prints, at most twice a second.
  void tick(const std::string& label, std::uint64_t k, std::uint64_t hi, bool show) {
    const std::uint64_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
    if (!on || !show || (d & 1023) != 0) return;
    const auto now = Clock::now();
    if (now - last < std::chrono::milliseconds(500)) return;
    last = now;
    const double el = std::chrono::duration<double>(now - start).count();
    const double rate = d / el;
    const double eta = (total - d) / rate;
    std::fprintf(stderr, "\r%-28s pose %" PRIu64 "/%" PRIu64 "  %.0f poses/s  ETA %.0f s   ", label.c_str(), k, hi, rate, eta);
    std::fflush(stderr);
  }
  void finish() {
    if (on) std::fprintf(stderr, "\r%80s\r", "");
  }
};

/// What every pass of one run shares: the scene and the options, the shard,
/// the timer's overhead, the threads, the progress line and the count of
/// failures traced so far.
struct SweepRun {
  SweepRun(const Scene& s, const StudyOptions& o, const ShardRange& sh, double overhead, int n_threads)
      : scene(s), spec(s.spec.as<SweepSpec>()), opt(o), shard(sh), overhead_ns(overhead), threads(n_threads),
        baseline_pairs(spec.baselines.pairs.begin(), spec.baselines.pairs.end()),
        derivative_pairs(spec.derivatives.pairs.begin(), spec.derivatives.pairs.end()) {
    progress.on = o.progress;
    progress.total = spec.pairs.size() * spec.passes.size() * (sh.pose_hi - sh.pose_lo);
  }
  const Scene& scene;
  const SweepSpec& spec;  // the scene's [run] and what it asks for
  const StudyOptions& opt;
  const ShardRange& shard;
  double overhead_ns;
  int threads;
  Progress progress;
  std::atomic<std::size_t> traced{0};
  // The pairs the agreement and derivative checks cover, as sets: each is
  // looked up once per pair, and may hold all 500,500 pairs of 1,000 shapes.
  const std::set<std::pair<int, int>> baseline_pairs, derivative_pairs;
};

/// One pair as every pass over it reads it: its bodies, its pose generator
/// and its answer checker (built once, read by every thread).
struct PairRun {
  const ShapeSpec& s1;
  const ShapeSpec& s2;
  RadialRange range;
  PoseGenerator gen;
  std::unique_ptr<AnswerChecker> checker;
};

/// One block of poses solved by solve_batch on this thread (the timed path
/// [run] timed_path = "batch"), its outputs kept for the comparison with the
/// loop. Storage grows to the largest block and is then reused.
struct BatchBlock {
  BatchOptions o;
  std::vector<double> alpha, x;
  std::vector<std::int32_t> status, iterations;
  BatchBlock(const Scene& scene, bool warm) {
    o.solver = scene.solver;
    o.warm_start = warm;
    o.warm_chain = static_cast<std::size_t>(scene.warm_chain);
    o.threads = 1;
  }
  void solve(const Shape& b1, const Shape& b2, const std::vector<Pose>& poses) {
    const std::size_t n = poses.size();
    alpha.resize(n), x.resize(3 * n), status.resize(n), iterations.resize(n);
    BatchOutput out;
    out.alpha = {alpha.data(), n}, out.x_1 = {x.data(), 3 * n}, out.status = {status.data(), n};
    out.iterations = {iterations.data(), n};
    solve_batch(b1, b2, Span<const Pose>(poses.data(), n), o, out);
  }
  /// Whether row i is r to the bit (solve_batch promises it, batch.hpp).
  bool same(std::size_t i, const SolveResult& r) const {
    return status[i] == static_cast<std::int32_t>(r.status) && iterations[i] == r.iterations &&
           std::memcmp(&alpha[i], &r.alpha, sizeof(double)) == 0 && std::memcmp(&x[3 * i], r.x_1.data(), 3 * sizeof(double)) == 0;
  }
};

/// Empty statistics of a pass, keeping what the scene records.
PassStats fresh_stats(const RecordSpec& rec) {
  PassStats st;
  st.has_timing = rec.timing;
  st.has_iterations = rec.iterations;
  st.has_residuals = rec.residuals;
  st.has_checks = rec.checks;
  return st;
}

/// Before a timed pass: solves of the pass's first poses, untimed, to warm
/// caches, branch predictors and the clock frequency.
void warm_up(const SweepRun& run, const PairRun& p, bool warm) {
  const Scene& scene = run.scene;
  WarmStart ws;
  const std::uint64_t n = std::min(scene.warmup, scene.poses);
  if (run.spec.timed_batch) {  // the path that is timed
    std::vector<Pose> poses;
    for (std::uint64_t k = 0; k < n; ++k) poses.push_back(p.gen(k));
    BatchBlock b(scene, warm);
    b.solve(*p.s1.shape, *p.s2.shape, poses);
    return;
  }
  for (std::uint64_t k = 0; k < n; ++k) {
    if (k % scene.warm_chain == 0) ws.reset();
    (void)solve(*p.s1.shape, *p.s2.shape, p.gen(k), scene.solver, warm ? &ws : nullptr);
  }
}

/// The failure records of solve k (when the scene records failures): a
/// converged answer an answer check refutes (check_problem), and a failed
/// solve, the first max_traced_failures of the run with its iteration trace
/// (solved again from the same warm start).
void record_failures(SweepRun& run, const PairRun& p, Pass pass, std::uint64_t k, const Pose& X, const SolveResult& r,
                     const WarmStart& before, const std::string& check_problem, json& failures) {
  const Scene& scene = run.scene;
  const bool warm = pass == Pass::Warm;
  const Shape& b1 = *p.s1.shape;
  const Shape& b2 = *p.s2.shape;
  auto record = [&] {
    json f = failure_record({p.s1.name, p.s2.name, &b1, &b2, to_string(pass), k, to_string(scene.generator)}, X, &r,
                            warm ? &before : nullptr);
    f["t"] = static_cast<double>(k) * scene.dt;
    return f;
  };
  if (!check_problem.empty()) {
    json f = record();
    f["problem"] = "converged, but " + check_problem;
    failures.push_back(std::move(f));
  }
  if (is_failure(r)) {
    json f = record();
    if (run.traced.fetch_add(1) < run.opt.max_traced_failures) {
      CollectingTrace tr;
      WarmStart again = before;
      const SolveResult r2 = solve(b1, b2, X, scene.solver, warm ? &again : nullptr, &tr);
      f["trace"] = std::move(tr.trace);
      f["trace_status"] = to_string(r2.status);
    }
    failures.push_back(std::move(f));
  }
}

/// Poses [lo, hi) of one pass (whole warm-start chains) into st and
/// failures: each solve timed where the scene records timing, its answer
/// checked outside the timed region, its failure records and its per-pose
/// line written. `show`: this thread prints the progress line.
void run_poses(SweepRun& run, const PairRun& p, Pass pass, std::uint64_t lo, std::uint64_t hi, PassStats& st, json& failures,
               bool show) {
  const Scene& scene = run.scene;
  const RecordSpec& rec = run.spec.record;
  const bool warm = pass == Pass::Warm;
  const std::string label = p.s1.name + "-" + p.s2.name + " " + to_string(pass);
  const bool batch = run.spec.timed_batch && rec.timing;
  std::optional<BatchBlock> block;
  std::vector<Pose> poses;
  if (batch) block.emplace(scene, warm);
  std::uint64_t block_end = lo;  // the batch path: poses [.., block_end) are solved, each taking block_ns
  double block_ns = 0.0;
  WarmStart ws;
  for (std::uint64_t k = lo; k < hi; ++k) {
    if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
    if (batch && k == block_end) {
      // The next block: one warm-start chain (a cold pass: 1024 poses),
      // timed as a whole; each of its solves is given the block's mean.
      block_end = std::min(hi, warm ? (k / scene.warm_chain + 1) * scene.warm_chain : k + 1024);
      poses.clear();
      for (std::uint64_t j = k; j < block_end; ++j) poses.push_back(p.gen(j));
      const auto t0 = Clock::now();
      block->solve(*p.s1.shape, *p.s2.shape, poses);
      const auto t1 = Clock::now();
      block_ns = (std::chrono::duration<double, std::nano>(t1 - t0).count() - run.overhead_ns) / static_cast<double>(poses.size());
    }
    const std::size_t i = batch ? static_cast<std::size_t>(k - (block_end - poses.size())) : 0;  // row k in the block
    const Pose X = batch ? poses[i] : p.gen(k);
    const bool chain_start = warm && (k % scene.warm_chain == 0);
    if (chain_start) ws.reset();
    const WarmStart before = ws;
    const auto t0 = Clock::now();
    const SolveResult r = solve(*p.s1.shape, *p.s2.shape, X, scene.solver, warm ? &ws : nullptr);
    const auto t1 = Clock::now();
    double t_ns = rec.timing ? std::chrono::duration<double, std::nano>(t1 - t0).count() - run.overhead_ns : 0.0;
    if (batch) {
      // The statistics and checks read the loop's answer, which is the batch's.
      if (!block->same(i, r))
        throw std::runtime_error("timed_path = \"batch\": pose " + std::to_string(k) + " of " + label +
                                 " differs between solve_batch and the loop of solve() (status " + to_string(r.status) +
                                 ", alpha " + fmt17(r.alpha) + " against the batch's " + fmt17(block->alpha[i]) + ")");
      t_ns = block_ns;
    }
    st.add(r, chain_start, t_ns);
    // A converged answer that fails an answer check is a false convergence.
    std::string check_problem;
    if (p.checker && r.converged()) {
      const AnswerCheck ch = p.checker->check(X, r, true);
      st.checks.add(ch);
      check_problem = ch.problem;
    }
    if (rec.failures) record_failures(run, p, pass, k, X, r, before, check_problem, failures);
    if (rec.per_pose && run.opt.per_pose)
      std::fprintf(run.opt.per_pose, "%s,%s,%s,%" PRIu64 ",%s,%d,%.17g,%.17g,%.1f\n", p.s1.name.c_str(), p.s2.name.c_str(),
                   to_string(pass), k, to_string(r.status), r.iterations, r.alpha, r.residual_norm, t_ns);
    run.progress.tick(label, k, run.shard.pose_hi, show);
  }
}

/// One pass over one pair, the shard's poses in whole chains per thread,
/// merged in chain order (the statistics equal the single-threaded ones
/// exactly); its failure records go to out.failures. Returns its statistics.
json run_pass(SweepRun& run, const PairRun& p, Pass pass, RunOutput& out) {
  const RecordSpec& rec = run.spec.record;
  if (rec.timing) warm_up(run, p, pass == Pass::Warm);
  const auto loop_wall0 = Clock::now();
  const double loop_cpu0 = rec.timing ? thread_cpu_seconds() : 0.0;
  const std::uint64_t switches0 = rec.timing ? involuntary_switches() : 0;
  std::vector<PassStats> sts(run.threads, fresh_stats(rec));
  std::vector<json> fs(run.threads, json::array());
  run_in_chains(run.shard.pose_lo, run.shard.pose_hi, run.scene.warm_chain, run.threads,
                [&](int t, std::uint64_t lo, std::uint64_t hi) { run_poses(run, p, pass, lo, hi, sts[t], fs[t], t == 0); });
  PassStats st = fresh_stats(rec);
  json failures = json::array();
  for (int t = 0; t < run.threads; ++t) {
    st.merge(sts[t]);
    for (auto& f : fs[t]) failures.push_back(std::move(f));
  }
  if (rec.timing) {
    st.loop_wall_s = std::chrono::duration<double>(Clock::now() - loop_wall0).count();
    st.loop_cpu_s = thread_cpu_seconds() - loop_cpu0;
    st.involuntary_switches = involuntary_switches() - switches0;
  }
  append_failures(out.failures, std::move(failures), run.opt.failures_path);
  return st.to_json();
}

/// One pair of the scene: its description, each pass, then its agreement
/// with the baselines and oracles and its derivatives' agreement with finite
/// differences, where the scene records them for this pair.
json run_pair(SweepRun& run, int i1, int i2, RunOutput& out) {
  const Scene& scene = run.scene;
  const RecordSpec& rec = run.spec.record;
  const Shape& b1 = *scene.shapes[i1].shape;
  const Shape& b2 = *scene.shapes[i2].shape;
  const RadialRange range = radial_range(b1, b2);
  const PairRun p{scene.shapes[i1], scene.shapes[i2], range, PoseGenerator(scene.generator, range, scene.dt),
                  rec.checks ? std::make_unique<AnswerChecker>(b1, b2, OracleChoice::Auto, scene.solver) : nullptr};
  json pair = {{"body1", p.s1.name},    {"body2", p.s2.name},        {"shape1", describe(b1)},
               {"shape2", describe(b2)}, {"rmin", range.rmin}, {"rmax", range.rmax},
               {"passes", json::object()}};
  for (const Pass pass : run.spec.passes) pair["passes"][to_string(pass)] = run_pass(run, p, pass, out);
  json extra_failures = json::array();
  const ShardRange& sr = run.shard;
  if (rec.baselines && run.baseline_pairs.count({i1, i2}))
    pair["baselines"] = run_agreement(scene, i1, i2, sr.pose_lo, sr.pose_hi, run.threads, run.overhead_ns, extra_failures).to_json();
  if (rec.derivatives && run.derivative_pairs.count({i1, i2}))
    pair["derivatives"] = run_derivatives(scene, i1, i2, sr.pose_lo, sr.pose_hi, run.threads, extra_failures).to_json();
  if (rec.failures) append_failures(out.failures, std::move(extra_failures), run.opt.failures_path);
  return pair;
}

}  // namespace

RunOutput run_scene(const Scene& scene, const StudyOptions& opt) {
  RunOutput out;
  out.shard = shard_range(scene, opt.shard_index, opt.shard_count);
  const SweepSpec& sw = scene.spec.as<SweepSpec>();
  const RecordSpec& rec = sw.record;
  const int threads = std::max(1, opt.threads);
  if (threads > 1 && (rec.timing || rec.per_pose))
    throw std::invalid_argument("threads > 1 is only for scenes that record neither timing nor per_pose");
  if (rec.timing) out.timer_overhead_ns = measure_timer_overhead_ns();
  const auto wall0 = Clock::now();
  SweepRun run(scene, opt, out.shard, out.timer_overhead_ns, threads);
  for (const auto& [i1, i2] : sw.pairs) out.pairs.push_back(run_pair(run, i1, i2, out));
  run.progress.finish();
  out.wall_seconds = std::chrono::duration<double>(Clock::now() - wall0).count();
  return out;
}

json make_results(const Scene& scene, const RunOutput& out, const json& metadata) {
  const SweepSpec& sw = scene.spec.as<SweepSpec>();
  std::vector<std::string> passes;
  for (Pass p : sw.passes) passes.push_back(to_string(p));
  const ShardRange& s = out.shard;
  json r = results_header(kResultsSchema, metadata, {scene.path, scene.name, scene.text}, scene.solver);
  r["sweep"] = {{"generator", to_string(scene.generator)}, {"poses", scene.poses},     {"dt", scene.dt},
                {"warm_chain", scene.warm_chain},          {"warmup", scene.warmup},   {"solver_tolerance", scene.solver.tolerance},
                {"solver_max_iterations", scene.solver.max_iterations}};
  r["passes"] = passes;
  r["record"] = record_names(sw.record);
  r["shard"] = {{"index", s.index}, {"count", s.count}, {"chains", {s.chain_lo, s.chain_hi}}, {"poses", {s.pose_lo, s.pose_hi}}};
  r["timing"] = {{"timer_overhead_ns", out.timer_overhead_ns},
                 {"pinned_cpu", metadata.is_object() ? metadata.value("pinned_cpu", json(nullptr)) : json(nullptr)},
                 // Which path the times are of: "loop" (each solve of solve() timed on its
                 // own) or "batch" (solve_batch on one thread, blocks of poses timed whole,
                 // each solve given its block's mean; SIMD lanes: batch_simd).
                 {"path", sw.timed_batch ? "batch" : "loop"},
                 {"batch_simd", sw.timed_batch ? json(batch_simd_isa()) : json(nullptr)}};
  r["wall_seconds"] = out.wall_seconds;
  if (!sw.reference.empty()) r["reference"] = {{"source", sw.reference.source}, {"mean_us", sw.reference.mean_us}};
  r["pairs"] = out.pairs;
  return r;
}

namespace {

/// Names an input of merge in its errors: its path when the caller gave
/// one, else its position among the inputs.
using InputName = std::function<std::string(std::size_t)>;

/// A shard's place in its run.
struct ShardId {
  int index, count;
};

/// The shard identity of every input, each checked first to be an undamaged
/// sweep results file of this schema version.
std::vector<ShardId> shard_ids(const std::vector<json>& shards, const InputName& input_name) {
  std::vector<ShardId> ids;
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const json& r = shards[k];
    const std::string schema = r.is_object() && r.contains("schema") && r["schema"].is_string()
                                   ? r["schema"].get<std::string>() : std::string("none");
    if (schema != kResultsSchema || !r.contains("schema_version") || r["schema_version"] != kResultsSchemaVersion)
      throw std::invalid_argument("merge: " + input_name(k) + " is not a results file: its schema is '" + schema +
                                  "', expected '" + kResultsSchema + "' version " +
                                  std::to_string(kResultsSchemaVersion) +
                                  (schema == kFailuresSchema ? " (a failures file; give merge only the shards' results files)" : ""));
    try {
      const json& sh = r.at("shard");
      ids.push_back({sh.at("index").get<int>(), sh.at("count").get<int>()});
      (void)sh.at("poses").at(1).get<std::uint64_t>();
      (void)sh.at("chains").at(1);
      for (const char* key : {"scene", "sweep", "passes", "record", "metadata", "timing", "pairs"}) (void)r.at(key);
      (void)r.at("scene").at("content");
      (void)r.at("wall_seconds").get<double>();
    } catch (const json::exception& e) {
      throw std::invalid_argument("merge: " + input_name(k) + " is a damaged results file: " + e.what());
    }
    if (ids[k].count < 1 || ids[k].index < 0 || ids[k].index >= ids[k].count)
      throw std::invalid_argument("merge: " + input_name(k) + " claims to be shard " + std::to_string(ids[k].index) + "/" +
                                  std::to_string(ids[k].count) + ", expected an index in [0, count)");
  }
  return ids;
}

/// The inputs by shard index (and each one's position among the inputs),
/// after checking that they are shards 0..N-1 of one scene, each once
/// (`names`: the inputs' paths, where given, for the rerun of a missing one).
std::vector<std::pair<const json*, std::size_t>> shards_in_order(const std::vector<json>& shards, const std::vector<ShardId>& ids,
                                                                  const InputName& input_name, const std::vector<std::string>& names) {
  const json& first = shards.front();
  const int n = ids.front().count;
  std::vector<const json*> by_index(n, nullptr);
  std::vector<std::size_t> source(n, 0);
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const json& r = shards[k];
    if (r.at("scene").at("content") != first.at("scene").at("content") || r.at("sweep") != first.at("sweep") ||
        r.value("solver", json()) != first.value("solver", json()) ||
        r.at("passes") != first.at("passes") || r.at("record") != first.at("record"))
      throw std::invalid_argument("merge: " + input_name(k) + " comes from a different scene or sweep than " + input_name(0));
    if (ids[k].count != n)
      throw std::invalid_argument("merge: " + input_name(k) + " is shard " + std::to_string(ids[k].index) + "/" +
                                  std::to_string(ids[k].count) + ", but " + input_name(0) + " is one of " + std::to_string(n) +
                                  " shards");
    const int i = ids[k].index;
    if (by_index[i])
      throw std::invalid_argument("merge: shard " + std::to_string(i) + "/" + std::to_string(n) + " given twice: " +
                                  input_name(source[i]) + " and " + input_name(k));
    by_index[i] = &r;
    source[i] = k;
  }
  std::string missing;
  std::vector<int> lost;
  for (int i = 0; i < n; ++i)
    if (!by_index[i]) {
      missing += (lost.empty() ? "" : ", ") + std::to_string(i) + "/" + std::to_string(n);
      lost.push_back(i);
    }
  if (!lost.empty()) {
    std::string given;
    std::vector<std::string> paths;
    std::vector<int> index;
    for (std::size_t k = 0; k < shards.size(); ++k) {
      given += (k ? ", " : "") + input_name(k);
      if (k < names.size()) paths.push_back(names[k]);
      index.push_back(ids[k].index);
    }
    const std::string scene = first.at("scene").contains("path") ? first["scene"]["path"].get<std::string>() : "SCENE";
    throw std::invalid_argument("merge: " + (lost.size() == 1 ? "shard " + missing + " is" : "shards " + missing + " are") +
                                " missing: the sweep has " + std::to_string(n) + " shards and " +
                                std::to_string(shards.size()) + " results files were given (" + given + ")" +
                                rerun_missing_shards(scene, paths, index, lost, n));
  }
  std::vector<std::pair<const json*, std::size_t>> out;
  for (int i = 0; i < n; ++i) out.emplace_back(by_index[i], source[i]);
  return out;
}

/// The metadata fields in which the shards differ. Shards made by different
/// code, or (for timing) on different CPUs, compilers or flags, do not make
/// one sweep: refused unless `allow_mixed`.
json mixed_builds(const std::vector<json>& shards, bool allow_mixed, const InputName& input_name) {
  const json& first = shards.front();
  const bool timed = first.at("record").is_array() &&
                     std::find(first.at("record").begin(), first.at("record").end(), "timing") != first.at("record").end();
  std::vector<std::string> keys = {"git_revision", "git_revision_configure", "git_dirty"};
  if (timed)
    for (const char* k : {"cpu_model", "compiler", "cxx_flags", "build_type", "native"}) keys.push_back(k);
  json mixed = json::array();
  for (std::size_t k = 1; k < shards.size(); ++k) {
    const json& m0 = first.at("metadata");
    const json& mk = shards[k].at("metadata");
    for (const std::string& key : keys) {
      const auto field = [&](const json& m) { return m.is_object() ? m.value(key, json()) : json(); };
      const json a = field(m0), b = field(mk);
      if (a == b) continue;
      if (!allow_mixed)
        throw std::invalid_argument("merge: " + input_name(k) + " was made with " + key + " " + b.dump() + ", " + input_name(0) +
                                    " with " + a.dump() + (timed ? ": timing figures" : ": figures") +
                                    " of different builds or machines do not make one sweep (rerun the odd shards, or give "
                                    "--allow-mixed to merge anyway; every shard's metadata is kept under shard.merged_from)");
      if (std::find(mixed.begin(), mixed.end(), key) == mixed.end()) mixed.push_back(key);
    }
  }
  return mixed;
}

/// Merges the pairs of shard file r into `merged` (the pairs so far, from
/// the inputs before it); `at_merged` and `at_r` are the positions of the
/// inputs whose counts are read, for the error of a missing count.
void merge_pairs_into(json& merged, const json& r, std::size_t at_merged, std::size_t at_r, const InputName& input_name) {
  // A count missing from a file of an older harness names that file (the
  // merged pairs are the first input's until first merged).
  const auto read = [&](auto from_json, const json& stats, const json& merged_stats, const std::string& where) {
    std::size_t k = at_merged;
    try {
      auto a = from_json(merged_stats);
      k = at_r;
      a.merge(from_json(stats));
      return a.to_json();
    } catch (const MissingField& e) {
      throw std::invalid_argument("merge: " + input_name(k) + ": " + where + ": " + e.what());
    } catch (const BadCount& e) {
      throw std::invalid_argument("merge: " + input_name(k) + ": " + where + "." + e.what());
    }
  };
  try {
    // Pairs are matched by their bodies' names, not by position: a shard
    // whose pairs come in another order still adds each pair's figures to
    // the same pair.
    std::map<std::pair<std::string, std::string>, const json*> by_name;
    const auto name_of = [](const json& pair) {
      return std::make_pair(pair.at("body1").get<std::string>(), pair.at("body2").get<std::string>());
    };
    for (const json& rp : r.at("pairs"))
      if (!by_name.emplace(name_of(rp), &rp).second)
        throw std::invalid_argument("merge: " + input_name(at_r) + " holds the pair [" + rp.at("body1").get<std::string>() + ", " +
                                    rp.at("body2").get<std::string>() + "] twice");
    if (by_name.size() != merged["pairs"].size())
      throw std::invalid_argument("merge: " + input_name(at_r) + " holds " + std::to_string(by_name.size()) + " pairs, " +
                                  input_name(0) + " " + std::to_string(merged["pairs"].size()));
    for (std::size_t p = 0; p < merged["pairs"].size(); ++p) {
      json& mp = merged["pairs"][p];
      const auto it = by_name.find(name_of(mp));
      if (it == by_name.end())
        throw std::invalid_argument("merge: " + input_name(at_r) + " has no pair [" + mp.at("body1").get<std::string>() + ", " +
                                    mp.at("body2").get<std::string>() + "], which " + input_name(0) + " holds");
      const json& rp = *it->second;
      const std::string at = "pairs[" + std::to_string(p) + "]";
      for (auto& [name, pass] : mp["passes"].items())
        pass = read(PassStats::from_json, rp.at("passes").at(name), pass, at + ".passes." + name);
      if (mp.contains("baselines")) mp["baselines"] = read(AgreementStats::from_json, rp.at("baselines"), mp["baselines"], at + ".baselines");
      if (mp.contains("derivatives"))
        mp["derivatives"] = read(DerivativeStats::from_json, rp.at("derivatives"), mp["derivatives"], at + ".derivatives");
    }
  } catch (const json::exception& e) {
    throw std::invalid_argument("merge: " + input_name(at_r) + " does not hold the pairs and passes of " + input_name(0) + ": " +
                                e.what());
  }
}

}  // namespace

json merge_results(const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names, bool allow_mixed) {
  if (shards.empty()) throw std::invalid_argument("merge: no results files given");
  const InputName input_name = [&](std::size_t k) {
    return k < names.size() ? names[k] : "results file " + std::to_string(k) + " (counting from 0)";
  };
  const std::vector<ShardId> ids = shard_ids(shards, input_name);
  const auto ordered = shards_in_order(shards, ids, input_name, names);
  const json mixed = mixed_builds(shards, allow_mixed, input_name);
  const int n = static_cast<int>(ordered.size());
  json merged = *ordered[0].first;  // the pairs of shard 0, then shards 1.. merged into them
  merged["metadata"] = metadata;
  if (!mixed.empty()) merged["metadata"]["mixed_shards"] = mixed;  // the fields in which the shards differ
  json shard_meta = json::array();
  double wall = 0.0;
  std::uint64_t pose_lo = 0;
  for (int i = 0; i < n; ++i) {
    const json& r = *ordered[i].first;
    if (r.at("shard").at("poses").at(0).get<std::uint64_t>() != pose_lo)
      throw std::invalid_argument("merge: " + input_name(ordered[i].second) + " (shard " + std::to_string(i) + "/" + std::to_string(n) +
                                  ") starts at pose " + r.at("shard").at("poses").at(0).dump() + ", expected " +
                                  std::to_string(pose_lo) + ": the shards do not tile the sweep");
    pose_lo = r.at("shard").at("poses").at(1).get<std::uint64_t>();
    wall += r.at("wall_seconds").get<double>();
    shard_meta.push_back({{"shard", r.at("shard")}, {"metadata", r.at("metadata")}, {"timing", r.at("timing")},
                          {"wall_seconds", r.at("wall_seconds")}});
    if (i > 0) merge_pairs_into(merged, r, ordered[0].second, ordered[i].second, input_name);
  }
  merged["shard"] = {{"index", 0}, {"count", 1}, {"chains", {0, (*ordered[n - 1].first).at("shard").at("chains").at(1)}},
                     {"poses", {0, pose_lo}}, {"merged_from", shard_meta}};
  merged["wall_seconds"] = wall;
  merged["timing"]["timer_overhead_ns"] = nullptr;  // per shard, see merged_from
  return merged;
}

}  // namespace idcol::harness

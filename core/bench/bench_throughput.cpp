// Solves per second of solve_batch(threads = 1) against the loop of solve()
// it replaces, per pair, cold and warm, on the paper's sweep (pose k at
// t = k 1e-4, as configs/paper_table1.toml; warm chains of 10^4 poses in
// both), on one pinned core, the median of repetitions. Before anything is
// timed, the batch's answers are checked against the loop's (status, alpha*
// and x* to 1e-12 relative, and how many rows are not bit-identical,
// iteration counts included); a pair whose answers differ is reported as
// such and its ratio is not claimed. Optionally, solve_batch's scaling with
// threads (cold and warm, 1..T threads, no pinning; warm runs at most as
// many threads as chains, 10 for 10^5 poses) and how evenly the splits
// spread the rows' costs (--balance T). With --narrow ISA (sse2 or avx2),
// each repetition also times the batch on that instruction set's lanes
// (IDCOL_SIMD=ISA: 2 or 4 where the CPU's own take 8), so that the table
// shows what the wider lanes gain pair by pair.
//
//   build/core/idcol_bench_throughput [--poses N] [--reps R] [--cpu C]
//       [--pairs Poly-Poly,Ellip-Ellip,...] [--scaling T] [--balance T] [--narrow ISA] [--out results/throughput]
//
// writes OUT.json (every figure, with the machine, compiler, flags, git
// revision and the batch path timed: scalar or SIMD and its instruction
// set) and OUT.md (the table).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sched.h>
#endif

#include <Eigen/Geometry>

#include "idcol/batch.hpp"
#include "idcol/solver.hpp"
#include "../src/batch/batch_simd.hpp"
#include "../examples/cli_args.hpp"
#include "../examples/paper_shapes.hpp"
#include "../examples/write_whole.hpp"

#if __has_include("bench_revision.h")
#include "bench_revision.h"  // IDCOL_BENCH_GIT: the revision this binary was built from
#endif
#ifndef IDCOL_BENCH_GIT
#define IDCOL_BENCH_GIT "unknown"
#endif
#ifndef IDCOL_BENCH_FLAGS
#define IDCOL_BENCH_FLAGS "unknown"
#endif
#ifndef IDCOL_BENCH_SOURCE_DIR
#define IDCOL_BENCH_SOURCE_DIR "."
#endif

using namespace idcol;

namespace {

/// The first line a shell command prints ("" if it fails).
std::string command_line(const std::string& cmd) {
  std::string outp;
  if (FILE* f = ::popen(cmd.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof(buf), f)) outp += buf;
    ::pclose(f);
  }
  const std::size_t nl = outp.find('\n');
  return nl == std::string::npos ? outp : outp.substr(0, nl);
}

/// The revision this binary was built from (bench_revision.h, written at
/// every build; "-dirty" when tracked sources outside results/ differed from
/// it then) and, where the checkout it runs in is at another commit (a
/// binary carried to another machine's copy, or a commit since the last
/// build), that commit too.
std::string build_revision() {
  const std::string built = IDCOL_BENCH_GIT;
  const std::string head = command_line(std::string("git -C '") + IDCOL_BENCH_SOURCE_DIR + "' rev-parse --short HEAD 2>/dev/null");
  if (head.empty() || built.compare(0, head.size(), head) == 0) return built;
  return built + " (checkout at run time: " + head + ")";
}

using idcol::examples::write_whole;

using examples::NamedShape;
// The paper's Table 1 shapes (core/examples/paper_shapes.hpp).
std::vector<NamedShape> shapes() { return examples::paper_catalogue(); }

/// The rows solve_batch's SIMD path takes (batch_simd.hpp), for the results.
constexpr const char* kSimdPairs =
    "Ellip-Ellip cold and warm, by the closed form in lanes; SE-SE, SE-SEC, SEC-SEC, TC-TC, TC-SE, TC-SEC, Poly-Poly, "
    "Poly-TC, Poly-SE, Poly-SEC and Poly-Ellip cold and warm, by Newton steps in lanes; every other row runs the scalar "
    "loop inside solve_batch";

/// The paper_table1 pairs, then Poly-Ellip and Ellip-Ellip.
const char* kDefaultPairs =
    "Poly-Poly,Poly-TC,Poly-SE,Poly-SEC,TC-TC,TC-SE,TC-SEC,SE-SE,SE-SEC,SEC-SEC,Poly-Ellip,Ellip-Ellip";


struct Out {
  std::vector<double> alpha, x;
  std::vector<std::int32_t> status, iterations;
  explicit Out(std::size_t n) : alpha(n), x(3 * n), status(n), iterations(n) {}
  BatchOutput view() { return {alpha, x, status, iterations, {}}; }
};

constexpr std::size_t kChain = 10000;  // paper_table1's warm_chain

/// The loop of solve() that solve_batch documents, writing the same outputs.
void loop(const Shape& a, const Shape& b, const std::vector<Pose>& P, bool warm, Out& o) {
  WarmStart ws;
  const SolverOptions opt;
  for (std::size_t k = 0; k < P.size(); ++k) {
    if (k % kChain == 0) ws.reset();
    const SolveResult r = solve(a, b, P[k], opt, warm ? &ws : nullptr);
    o.alpha[k] = r.alpha;
    o.x[3 * k] = r.x_1[0];
    o.x[3 * k + 1] = r.x_1[1];
    o.x[3 * k + 2] = r.x_1[2];
    o.status[k] = static_cast<std::int32_t>(r.status);
    o.iterations[k] = r.iterations;
  }
}

volatile double sink = 0.0;  // where timed solves leave their results

/// The rows marked in `marks` with the WarmStart that the loop carries
/// to each (warm) or none (cold): the loop's own solves of the rows that the
/// lanes hand to it.
struct Declined {
  std::vector<std::size_t> rows;
  std::vector<WarmStart> starts;
};
Declined declined_rows(const Shape& a, const Shape& b, const std::vector<Pose>& P, bool warm, const std::vector<std::uint8_t>& marks) {
  Declined d;
  WarmStart ws;
  const SolverOptions opt;
  for (std::size_t k = 0; k < P.size(); ++k) {
    if (k % kChain == 0) ws.reset();
    if (marks[k]) d.rows.push_back(k), d.starts.push_back(ws);
    if (warm) solve(a, b, P[k], opt, &ws);
  }
  return d;
}
/// How many of those rows the scalar solver solves with a Levenberg-Marquardt
/// step, which the lanes do not make (its trace, from the same warm start).
std::size_t declined_with_lm(const Shape& a, const Shape& b, const std::vector<Pose>& P, bool warm, const Declined& d) {
  struct Lm : TraceSink {
    bool seen = false;
    void record(const TraceRecord& r) override { seen = seen || !std::strncmp(r.step, "lm", 2); }
  };
  const SolverOptions opt;
  std::size_t count = 0;
  for (std::size_t i = 0; i < d.rows.size(); ++i) {
    WarmStart ws = d.starts[i];
    Lm t;
    solve(a, b, P[d.rows[i]], opt, warm ? &ws : nullptr, &t);
    count += t.seen;
  }
  return count;
}

/// The loop's time on those rows alone.
void loop_declined(const Shape& a, const Shape& b, const std::vector<Pose>& P, bool warm, const Declined& d) {
  const SolverOptions opt;
  for (std::size_t i = 0; i < d.rows.size(); ++i) {
    WarmStart ws = d.starts[i];
    sink = sink + solve(a, b, P[d.rows[i]], opt, warm ? &ws : nullptr).alpha;
  }
}

void batch(const Shape& a, const Shape& b, const std::vector<Pose>& P, bool warm, int threads, Out& o) {
  BatchOptions opt;
  opt.warm_start = warm;
  opt.warm_chain = kChain;
  opt.threads = threads;
  solve_batch(a, b, P, opt, o.view());
}

bool close(double u, double v) {
  if (std::isnan(u) || std::isnan(v)) return std::isnan(u) && std::isnan(v);
  return std::abs(u - v) <= 1e-12 * std::max(std::abs(u), std::abs(v));
}

/// Rows whose status, iterations, alpha or x differ in any bit (NaN = NaN).
long not_bit_identical(const Out& u, const Out& v) {
  auto same = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
  long d = 0;
  for (std::size_t k = 0; k < u.alpha.size(); ++k) {
    bool eq = u.status[k] == v.status[k] && u.iterations[k] == v.iterations[k] && same(u.alpha[k], v.alpha[k]);
    for (int j = 0; j < 3; ++j) eq = eq && same(u.x[3 * k + j], v.x[3 * k + j]);
    d += !eq;
  }
  return d;
}

long differing(const Out& u, const Out& v) {
  long d = 0;
  for (std::size_t k = 0; k < u.alpha.size(); ++k) {
    bool same = u.status[k] == v.status[k] && close(u.alpha[k], v.alpha[k]);
    for (int j = 0; j < 3; ++j) same = same && close(u.x[3 * k + j], v.x[3 * k + j]);
    d += !same;
  }
  return d;
}

template <class F>
double seconds(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median_of(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

template <class F>
double median_seconds(int reps, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) t.push_back(seconds(f));
  return median_of(std::move(t));
}

std::string cpu_model() {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

std::string json_str(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

struct Row {
  std::string pair, mode;
  double loop_s, batch_s;
  long differ;
  long bits_differ;   // rows not bit-identical to the loop's (iterations included)
  double lane_share;  // of the rows, the share the SIMD path answered in lanes
  double declined_s;  // the loop's time on the rows the lanes declined, alone
  std::size_t declined_n;  // how many rows they are
  std::size_t declined_lm;  // of them, the rows whose scalar solve takes a Levenberg-Marquardt step
  double narrow_s;          // --narrow: the batch on the narrower lanes (0 without)
  long narrow_bits_differ;  // ... and its rows not bit-identical to the loop's
};

struct ScaleRow {
  std::string pair, mode;
  int threads;
  double seconds;
};

/// How evenly a split spreads one pass over T threads, from each row's
/// solve time on one thread: total / (the largest thread's share), the
/// speed-up that the split alone allows, for contiguous chunks (units
/// t T/threads..., a unit being a row cold and a chain warm: solve_batch's
/// warm split) and for blocks of 256 rows (cold: solve_batch's split) or
/// single chains (warm) handed to whichever thread is free first.
struct BalanceRow {
  std::string pair, mode;
  int threads;
  double static_bound, dynamic_bound;
};

BalanceRow balance(const std::string& pair, const Shape& a, const Shape& b, const std::vector<Pose>& P, bool warm, int T) {
  const std::size_t n = P.size();
  std::vector<double> c(n);
  WarmStart ws;
  const SolverOptions opt;
  for (std::size_t k = 0; k < n; ++k) {
    if (k % kChain == 0) ws.reset();
    const auto t0 = std::chrono::steady_clock::now();
    const SolveResult r = solve(a, b, P[k], opt, warm ? &ws : nullptr);
    c[k] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    sink = sink + r.alpha;  // the solve's result is used
  }
  const std::size_t unit = warm ? kChain : 1;
  const std::size_t units = (n + unit - 1) / unit;
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(T), units);
  auto cost = [&](std::size_t lo, std::size_t hi) {
    double s = 0.0;
    for (std::size_t k = std::min(n, lo); k < std::min(n, hi); ++k) s += c[k];
    return s;
  };
  const double total = cost(0, n);
  double worst = 0.0;
  for (std::size_t t = 0; t < threads; ++t)
    worst = std::max(worst, cost(units * t / threads * unit, units * (t + 1) / threads * unit));
  // Greedy list scheduling: each block to the thread that is free first.
  const std::size_t block = warm ? kChain : 256;
  std::vector<double> busy(static_cast<std::size_t>(T), 0.0);
  for (std::size_t lo = 0; lo < n; lo += block) *std::min_element(busy.begin(), busy.end()) += cost(lo, lo + block);
  const double makespan = *std::max_element(busy.begin(), busy.end());
  return {pair, warm ? "warm" : "cold", T, total / worst, total / makespan};
}

int run(int argc, char** argv) {
  std::size_t n = 100000;
  int reps = 5, cpu = 0, scaling = 0, balance_threads = 0;
  std::string pairs = kDefaultPairs, out = "results/throughput", narrow;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    auto count = [&](long lo, long hi) { return examples::count_arg("idcol_bench_throughput", a.c_str(), next().c_str(), lo, hi); };
    if (a == "--poses") n = static_cast<std::size_t>(count(1, 100000000));
    else if (a == "--reps") reps = static_cast<int>(count(1, 1000));
    else if (a == "--cpu") cpu = static_cast<int>(count(0, 4095));
    else if (a == "--pairs") pairs = next();
    else if (a == "--scaling") scaling = static_cast<int>(count(0, 4096));
    else if (a == "--balance") balance_threads = static_cast<int>(count(0, 4096));
    else if (a == "--narrow") narrow = next();
    else if (a == "--out") out = next();
    else {
      std::fprintf(stderr, "usage: %s [--poses N] [--reps R] [--cpu C] [--pairs A-B,...] [--scaling T] [--balance T] [--narrow ISA] [--out PREFIX]\n", argv[0]);
      return 2;
    }
  }
  const std::string isa = batch_simd_isa();  // the lanes solve_batch takes on this CPU
  // IDCOL_SIMD as the caller set it, restored after each --narrow pass.
  const char* simd_env = std::getenv("IDCOL_SIMD");
  const std::string simd_saved = simd_env ? simd_env : "";
  auto restore_simd = [&] {
    if (simd_env) setenv("IDCOL_SIMD", simd_saved.c_str(), 1);
    else unsetenv("IDCOL_SIMD");
  };
  if (!narrow.empty()) {
    if (narrow != "sse2" && narrow != "avx2") throw std::invalid_argument("--narrow must be sse2 or avx2, not '" + narrow + "'");
    setenv("IDCOL_SIMD", narrow.c_str(), 1);
    const std::string got = batch_simd_isa();
    restore_simd();
    const int wide = isa == "avx512" ? 3 : isa == "avx2" ? 2 : isa == "sse2" ? 1 : 0, asked = narrow == "avx2" ? 2 : 1;
    if (got != narrow || wide <= asked) {  // nothing to compare on this CPU (the command stays portable)
      std::printf("--narrow %s: this CPU's lanes are %s, and IDCOL_SIMD=%s gives %s: no narrower lanes to time\n", narrow.c_str(),
                  isa.c_str(), narrow.c_str(), got.c_str());
      narrow.clear();
    }
  }
  // The batch on the --narrow lanes (IDCOL_SIMD is read by each solve_batch call).
  auto narrow_batch = [&](const Shape& a, const Shape& b, const std::vector<Pose>& P, bool warm, Out& o) {
    setenv("IDCOL_SIMD", narrow.c_str(), 1);
    batch(a, b, P, warm, 1, o);
    restore_simd();
  };
  const auto S = shapes();
  auto find = [&](const std::string& name) -> const Shape& {
    for (const NamedShape& s : S)
      if (name == s.name) return s.shape;
    throw std::invalid_argument("unknown shape '" + name + "' (Poly, TC, SE, SEC, Ellip)");
  };

  std::vector<Row> rows;
  std::vector<ScaleRow> scale_rows;
  std::vector<BalanceRow> balance_rows;
  std::vector<std::string> names;
  {
    std::stringstream ss(pairs);
    std::string p;
    while (std::getline(ss, p, ',')) names.push_back(p);
  }
  const int all_threads = resolve_thread_count(0);
  bool pinned = false;
#if defined(__linux__)
  cpu_set_t all_set;
  sched_getaffinity(0, sizeof(all_set), &all_set);
#endif
  for (const std::string& pn : names) {
    const auto dash = pn.find('-');
    if (dash == std::string::npos) throw std::invalid_argument("pair '" + pn + "' is not A-B");
    const Shape& a = find(pn.substr(0, dash));
    const Shape& b = find(pn.substr(dash + 1));
    const std::vector<Pose> P = examples::paper_sweep(a, b, n);
#if defined(__linux__)
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    pinned = sched_setaffinity(0, sizeof(one), &one) == 0;
#endif
    for (bool warm : {false, true}) {
      Out lo(n), bo(n);
      loop(a, b, P, warm, lo);  // also the warm-up
      const std::size_t before = detail::batch_simd_lane_rows();
      std::vector<std::uint8_t> marks(n, 0);
      detail::batch_simd_mark_declined(&marks);
      batch(a, b, P, warm, 1, bo);
      detail::batch_simd_mark_declined(nullptr);
      const double share = static_cast<double>(detail::batch_simd_lane_rows() - before) / static_cast<double>(n);
      const long differ = differing(lo, bo), bits = not_bit_identical(lo, bo);
      const Declined dec = declined_rows(a, b, P, warm, marks);
      // The three timed runs alternate, rep by rep, so that a slow spell of
      // a shared machine falls on all three rather than on one block.
      long narrow_bits = 0;
      if (!narrow.empty()) {
        Out no(n);
        narrow_batch(a, b, P, warm, no);
        narrow_bits = not_bit_identical(lo, no);
      }
      std::vector<double> vl, vb, vd, vn;
      for (int r = 0; r < reps; ++r) {
        vl.push_back(seconds([&] { loop(a, b, P, warm, lo); }));
        vb.push_back(seconds([&] { batch(a, b, P, warm, 1, bo); }));
        vd.push_back(seconds([&] { loop_declined(a, b, P, warm, dec); }));
        if (!narrow.empty()) vn.push_back(seconds([&] { narrow_batch(a, b, P, warm, bo); }));
      }
      const double tl = median_of(vl), tb = median_of(vb), td = median_of(vd), tn = vn.empty() ? 0.0 : median_of(vn);
      rows.push_back({pn, warm ? "warm" : "cold", tl, tb, differ, bits, share, dec.rows.empty() ? 0.0 : td, dec.rows.size(),
                      declined_with_lm(a, b, P, warm, dec), tn, narrow_bits});
      std::printf("%-12s %s  loop %8.0f solves/s  batch %8.0f solves/s  ratio %.2f  differ %ld  not bit-identical %ld  in lanes %.1f%%"
                  "  declined rows %.1f%% of the loop's time\n",
                  pn.c_str(), warm ? "warm" : "cold", n / tl, n / tb, tl / tb, differ, bits, 100.0 * share, 100.0 * td / tl);
      if (!narrow.empty())
        std::printf("%-12s %s  %s lanes: ratio %.2f  not bit-identical %ld\n", pn.c_str(), warm ? "warm" : "cold", narrow.c_str(),
                    tl / tn, narrow_bits);
      std::fflush(stdout);
      if (balance_threads > 0) {
        balance_rows.push_back(balance(pn, a, b, P, warm, balance_threads));
        const BalanceRow& r = balance_rows.back();
        std::printf("%-12s %s  %d threads: contiguous chunks allow %.1fx, free-thread blocks %.1fx\n", pn.c_str(), r.mode.c_str(),
                    r.threads, r.static_bound, r.dynamic_bound);
        std::fflush(stdout);
      }
    }
#if defined(__linux__)
    sched_setaffinity(0, sizeof(all_set), &all_set);
#endif
    for (int t = 1; t <= scaling; ++t)
      for (bool warm : {false, true}) {
        Out bo(n);
        const double s = median_seconds(reps, [&] { batch(a, b, P, warm, t, bo); });
        scale_rows.push_back({pn, warm ? "warm" : "cold", t, s});
        std::printf("%-12s %s  threads %2d  %9.0f solves/s\n", pn.c_str(), warm ? "warm" : "cold", t, n / s);
        std::fflush(stdout);
      }
  }

  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const std::string rev = build_revision();
  std::ostringstream js;
  js << "{\n  \"benchmark\": \"throughput\",\n  \"date\": " << json_str(date) << ",\n  \"machine\": {\"cpu\": "
     << json_str(cpu_model()) << ", \"cpus_available\": " << all_threads << "},\n  \"compiler\": " << json_str(__VERSION__)
     << ",\n  \"flags\": " << json_str(IDCOL_BENCH_FLAGS) << ",\n  \"git_revision\": " << json_str(rev)
     << ",\n  \"batch_path\": {\"simd_isa\": " << json_str(isa)
     << ", \"simd_pairs\": " << json_str(kSimdPairs)
     << ", \"narrow_isa\": " << (narrow.empty() ? std::string("null") : json_str(narrow)) << "}"
     << ",\n  \"poses_per_pair\": " << n << ",\n  \"repetitions\": " << reps << ",\n  \"statistic\": \"median\""
     << ",\n  \"pinned_cpu\": " << (pinned ? std::to_string(cpu) : std::string("null")) << ",\n  \"warm_chain\": " << kChain
     << ",\n  \"command\": " << json_str([&] {
          std::string c;
          for (int i = 0; i < argc; ++i) c += (i ? " " : "") + std::string(argv[i]);
          return c;
        }())
     << ",\n  \"rows\": [\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    js << "    {\"pair\": " << json_str(r.pair) << ", \"mode\": " << json_str(r.mode) << ", \"loop_solves_per_s\": " << n / r.loop_s
       << ", \"batch_solves_per_s\": " << n / r.batch_s << ", \"batch_over_loop\": " << r.loop_s / r.batch_s
       << ", \"answers_differ\": " << r.differ << ", \"not_bit_identical\": " << r.bits_differ
       << ", \"rows_in_lanes\": " << r.lane_share << ", \"declined_rows_loop_share\": " << r.declined_s / r.loop_s
       << ", \"declined_rows\": " << r.declined_n << ", \"declined_rows_with_lm_step\": " << r.declined_lm
       << ", \"declined_rows_batch_share\": " << r.declined_s / r.batch_s
       << ", \"bound_if_lanes_took_no_time\": " << (r.declined_n > 0 ? std::to_string(r.loop_s / r.declined_s) : std::string("null"))
       << ", \"lanes_over_loop_on_lane_rows\": " << (r.loop_s - r.declined_s) / (r.batch_s - r.declined_s)
       << ", \"narrow_batch_over_loop\": " << (r.narrow_s > 0.0 ? std::to_string(r.loop_s / r.narrow_s) : std::string("null"))
       << ", \"narrow_not_bit_identical\": " << (r.narrow_s > 0.0 ? std::to_string(r.narrow_bits_differ) : std::string("null")) << "}"
       << (i + 1 < rows.size() ? ",\n" : "\n");
  }
  js << "  ],\n  \"thread_scaling\": [\n";
  for (std::size_t i = 0; i < scale_rows.size(); ++i) {
    const ScaleRow& r = scale_rows[i];
    js << "    {\"pair\": " << json_str(r.pair) << ", \"mode\": " << json_str(r.mode) << ", \"threads\": " << r.threads
       << ", \"solves_per_s\": " << n / r.seconds << "}" << (i + 1 < scale_rows.size() ? ",\n" : "\n");
  }
  js << "  ],\n  \"chunk_balance\": [\n";
  for (std::size_t i = 0; i < balance_rows.size(); ++i) {
    const BalanceRow& r = balance_rows[i];
    js << "    {\"pair\": " << json_str(r.pair) << ", \"mode\": " << json_str(r.mode) << ", \"threads\": " << r.threads
       << ", \"contiguous_chunks_bound\": " << r.static_bound << ", \"free_thread_blocks_bound\": " << r.dynamic_bound << "}"
       << (i + 1 < balance_rows.size() ? ",\n" : "\n");
  }
  js << "  ]\n}\n";

  std::ostringstream md;
  md << "# solve_batch(threads = 1) against the loop of solve()\n\n"
     << "Paper sweep, " << n << " poses per pair, warm chains of " << kChain << ", median of " << reps << " runs (the loop and the batch alternating)"
     << (pinned ? ", pinned to CPU " + std::to_string(cpu) : std::string(", not pinned")) << ".\n"
     << "CPU: " << cpu_model() << "; compiler " << __VERSION__ << "; flags `" << IDCOL_BENCH_FLAGS << "`; git "
     << rev << "; SIMD path: " << isa << " (" << kSimdPairs << ").\n\n"
     << "| pair | mode | loop solves/s | batch solves/s | batch / loop | answers differ | not bit-identical | rows in lanes "
        "| declined rows: share of the loop's time | batch / loop if the lanes took no time | on the lanes' rows |"
     << (narrow.empty() ? std::string() : " batch / loop, " + narrow + " lanes | not bit-identical, " + narrow + " lanes |") << "\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|" << (narrow.empty() ? "" : "---|---|") << "\n";
  char buf[320];
  for (const Row& r : rows) {
    const std::string bound = r.declined_n > 0 ? std::to_string(static_cast<long>(r.loop_s / r.declined_s + 0.5)) : std::string("-");
    std::snprintf(buf, sizeof(buf), "| %s | %s | %.0f | %.0f | %.2f | %ld | %ld | %.1f%% | %.1f%% | %s | %.2f |", r.pair.c_str(),
                  r.mode.c_str(), n / r.loop_s, n / r.batch_s, r.loop_s / r.batch_s, r.differ, r.bits_differ, 100.0 * r.lane_share,
                  100.0 * r.declined_s / r.loop_s, bound.c_str(), (r.loop_s - r.declined_s) / (r.batch_s - r.declined_s));
    md << buf;
    if (r.narrow_s > 0.0) {
      std::snprintf(buf, sizeof(buf), " %.2f | %ld |", r.loop_s / r.narrow_s, r.narrow_bits_differ);
      md << buf;
    }
    md << "\n";
  }
  md << "\nDeclined rows: the rows that the lanes hand to the loop inside solve_batch (a Levenberg-Marquardt step, "
        "a restart, a chain's cold first row, a value within the band of a threshold), timed through the loop alone, "
        "each from the warm start the loop carries to it. Their share of the loop's time bounds batch / loop however "
        "fast the lanes are (loop / declined); on the lanes' rows: (loop - declined) / (batch - declined), the lanes' "
        "speed on the rows they answer, the declined rows' lane work before they leave included. A cold row whose first "
        "run reaches a Levenberg-Marquardt step goes on from there: W such rows together in lanes (not declined), and a "
        "row that those lanes hand back, or one left over at the end of a block, on the scalar solver, which resumes it "
        "rather than solving it again, so that it costs the batch less than the loop and the last column credits the "
        "lanes with a little of that saving.\n";
  if (!narrow.empty())
    md << "\n" << narrow << " lanes: the same batch with IDCOL_SIMD=" << narrow << " (" << (narrow == "avx2" ? 4 : 2)
       << " lanes where this CPU's " << isa << " lanes take " << (isa == "avx512" ? 8 : 4)
       << "), timed in the same repetitions; what the wider lanes gain is the ratio of the two batch / loop columns.\n";
  if (!scale_rows.empty()) {
    md << "\n## solve_batch thread scaling (not pinned)\n\n| pair | mode | threads | solves/s | speed-up |\n|---|---|---|---|---|\n";
    for (const ScaleRow& r : scale_rows) {
      double one = r.seconds;
      for (const ScaleRow& q : scale_rows)
        if (q.pair == r.pair && q.mode == r.mode && q.threads == 1) one = q.seconds;
      std::snprintf(buf, sizeof(buf), "| %s | %s | %d | %.0f | %.2f |\n", r.pair.c_str(), r.mode.c_str(), r.threads, n / r.seconds,
                    one / r.seconds);
      md << buf;
    }
  }
  if (!balance_rows.empty()) {
    md << "\n## How evenly solve_batch's split spreads the work (from one thread's per-row times)\n\n"
       << "The speed-up the split alone allows on T threads: the pass's total time over the largest thread's share, "
          "from each row's solve time on one pinned thread. Contiguous chunks: one run of rows (cold) or of chains of "
       << kChain << " (warm, solve_batch's split) a thread. Free-thread blocks: blocks of 256 rows (cold, solve_batch's "
          "split) or single chains (warm), each to the thread free first.\n\n| pair | mode | threads | contiguous chunks | free-thread blocks |\n|---|---|---|---|---|\n";
    for (const BalanceRow& r : balance_rows) {
      std::snprintf(buf, sizeof(buf), "| %s | %s | %d | %.1f | %.1f |\n", r.pair.c_str(), r.mode.c_str(), r.threads,
                    r.static_bound, r.dynamic_bound);
      md << buf;
    }
  }
  md << "\nCommand: `";
  for (int i = 0; i < argc; ++i) md << (i ? " " : "") << argv[i];
  md << "`\n";
  write_whole(out + ".json", js.str());
  write_whole(out + ".md", md.str());
  long bad = 0;
  for (const Row& r : rows) bad += r.differ;
  return bad == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // a bad option or pair: named, without an abort
    std::fprintf(stderr, "idcol_bench_throughput: %s\n", e.what());
    return 2;
  }
}

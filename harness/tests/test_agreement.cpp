// The genuine / band classification of a baseline disagreement, the method
// names, the agreement statistics' JSON, and the Markdown writers (sweep
// table and stress report) on results whose figures are known.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "idcol/shapes.hpp"
#include "studies/sweep/agreement.hpp"
#include "studies/sweep/sweep.hpp"
#include "stats/stats.hpp"
#include "studies/stress/stress.hpp"
#include "io/files.hpp"
#include "io/keys.hpp"
#include "scene/scene.hpp"
#ifdef IDCOL_HARNESS_TESTS_WITH_BASELINES
#include "idcol_baselines/registry.hpp"
#endif

namespace idcol::harness {
namespace {

using nlohmann::json;
using V = AgreementVerdict;

TEST(Agreement, ClassificationFollowsTheWidenedBracket) {
  const double tol = 1e-6;
  // Same answer: agree, whatever the bracket.
  EXPECT_EQ(classify_answer(true, true, false, true, 0.5, 0.6, tol), V::Agree);
  EXPECT_EQ(classify_answer(false, false, false, false, NAN, NAN, tol), V::Agree);
  // A failed library call is "failed" even when its answer would agree.
  EXPECT_EQ(classify_answer(true, true, true, true, 0.5, 0.6, tol), V::Failed);
  // Disagreement with 1 inside [lo, hi]: explained by smoothing.
  EXPECT_EQ(classify_answer(true, false, false, true, 0.99, 1.01, tol), V::Band);
  EXPECT_EQ(classify_answer(false, true, false, true, 1.0, 1.0, tol), V::Band);
  // 1 just outside [lo, hi] but inside the band tolerance: band; beyond it: genuine.
  EXPECT_EQ(classify_answer(true, false, false, true, 1.0 + 0.5e-6, 1.1, tol), V::Band);
  EXPECT_EQ(classify_answer(true, false, false, true, 1.0 + 2e-6, 1.1, tol), V::Genuine);
  EXPECT_EQ(classify_answer(true, false, false, true, 0.9, 1.0 - 0.5e-6, tol), V::Band);
  EXPECT_EQ(classify_answer(true, false, false, true, 0.9, 1.0 - 2e-6, tol), V::Genuine);
  // No oracle answer, or a NaN bracket: nothing explains it.
  EXPECT_EQ(classify_answer(true, false, false, false, 0.99, 1.01, tol), V::Genuine);
  EXPECT_EQ(classify_answer(true, false, false, true, NAN, NAN, tol), V::Genuine);
  EXPECT_EQ(classify_answer(true, false, false, true, 0.99, NAN, tol), V::Genuine);
}

// A method that solves for alpha* to a tolerance (DCOL) disagrees with
// iDCOL's status only beyond its own bound too: `own` widens the band by an
// absolute amount on both sides.
TEST(Agreement, AMethodsOwnBoundWidensTheBand) {
  const double tol = 1e-6;
  EXPECT_EQ(classify_answer(true, false, false, true, 1.0 + 2e-5, 1.1, tol), V::Genuine);
  EXPECT_EQ(classify_answer(true, false, false, true, 1.0 + 2e-5, 1.1, tol, 3e-5), V::Band);
  EXPECT_EQ(classify_answer(true, false, false, true, 0.9, 1.0 - 2e-5, tol, 3e-5), V::Band);
  EXPECT_EQ(classify_answer(true, false, false, true, 0.9, 1.0 - 2e-5, tol, 1e-5), V::Genuine);
  EXPECT_EQ(classify_answer(true, false, false, false, 1.0, 1.0, tol, 1.0), V::Genuine);  // no oracle: nothing explains it
}

// The per-method answers (alpha*, iterations, normals) merge as sums and
// round-trip through JSON; an alpha beyond the method's own bound counts in
// genuine_total.
TEST(Agreement, MethodAnswerStatsMergeAndCountAsGenuine) {
  AgreementStats a, b;
  MethodAnswerStats& da = a.answers["dcol"];
  da.alpha_poses = 3, da.alpha_outside_bound = 1;
  for (double e : {1e-7, 2e-6, 3e-5}) da.alpha_rel_err.add(e), da.alpha_rel_diff_idcol.add(10 * e);
  for (int it : {6, 7, 9}) da.iterations.add(it);
  b.answers["dcol"].alpha_poses = 2;
  b.answers["dcol"].iterations.add(8);
  b.answers["fcl_distance"].normal_poses = 1;
  b.answers["fcl_distance"].normal_angle.add(0.01);
  a.merge(b);
  EXPECT_EQ(a.answers.at("dcol").alpha_poses, 5u);
  EXPECT_EQ(a.answers.at("dcol").iterations.count(), 4u);
  EXPECT_DOUBLE_EQ(a.answers.at("dcol").iterations.mean(), 7.5);
  EXPECT_EQ(a.answers.at("fcl_distance").normal_poses, 1u);
  const json j = a.to_json();
  EXPECT_EQ(j.at("genuine_total"), 1);
  EXPECT_EQ(j.at("answers").at("dcol").at("alpha_outside_bound"), 1);
  EXPECT_EQ(AgreementStats::from_json(j).to_json(), j);
}

// DCOL's alpha* through the agreement pass: compared with the oracle on
// every pose, none beyond its own bound, its iterations counted.
TEST(Agreement, DcolsAlphaIsComparedWithTheOracle) {
#ifdef IDCOL_HARNESS_TESTS_WITH_BASELINES
  const Scene s = parse_scene(R"(
name = "dcol_agreement"
[shapes]
Ellip = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 1 }
Poly = { family = "smooth_polytope", normals = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1], [-1, -1, -1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]], offsets = [1, 1, 1, 1, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667], beta = 20 }
[sweep]
generator = "paper"
poses = 300
[run]
pairs = [["Ellip", "Ellip"], ["Poly", "Poly"]]
passes = ["cold"]
record = ["baselines"]
[baselines]
methods = ["dcol", "oracle"]
pairs = "run"
timing_poses = 0
)", "dcol.toml");
  for (int i = 0; i < 2; ++i) {
    json failures = json::array();
    const AgreementStats st = run_agreement(s, i, i, 0, 300, 1, 0.0, failures);
    const MethodAnswerStats& d = st.answers.at("dcol");
    EXPECT_EQ(d.alpha_poses, 300u) << i;
    EXPECT_EQ(d.alpha_outside_bound, 0u) << i;
    EXPECT_EQ(d.iterations.count(), 300u) << i;
    EXPECT_GT(d.iterations.mean(), 3.0) << i;
    EXPECT_LT(d.alpha_rel_err.max(), 1e-3) << i;
    EXPECT_EQ(st.status.at("dcol").genuine, 0u) << i;
    EXPECT_TRUE(failures.empty()) << failures.dump();
  }
#else
  GTEST_SKIP() << "built without baselines";
#endif
}

TEST(Agreement, AlphaInsideTheWidenedBracket) {
  EXPECT_TRUE(in_widened_bracket(1.0, 1.0, 1.0, 0.0));
  EXPECT_TRUE(in_widened_bracket(0.9999995, 1.0, 1.2, 1e-6));
  EXPECT_FALSE(in_widened_bracket(0.999998, 1.0, 1.2, 1e-6));
  EXPECT_TRUE(in_widened_bracket(1.2000001, 1.0, 1.2, 1e-6));
  EXPECT_FALSE(in_widened_bracket(1.2001, 1.0, 1.2, 1e-6));
  EXPECT_FALSE(in_widened_bracket(NAN, 1.0, 1.2, 1e-6));
  EXPECT_FALSE(in_widened_bracket(1.1, NAN, NAN, 1e-6));
}

TEST(Agreement, MethodNamesComeFromOneList) {
  // The harness accepts exactly the competitor table's names, in its order.
#ifdef IDCOL_HARNESS_TESTS_WITH_BASELINES
  std::vector<std::string> table;
  for (const baselines::Competitor* c : baselines::competitors()) table.emplace_back(c->name);
  EXPECT_EQ(boolean_methods(), table);
  for (const baselines::Competitor* c : baselines::competitors()) EXPECT_EQ(method_label(c->name), c->label);
  // Agreement by the gap's sign where the registry declares a signed distance.
  if (baselines::find_competitor("fcl_distance")) EXPECT_TRUE(answers_gap("fcl_distance"));
  if (baselines::find_competitor("fcl_collide")) EXPECT_FALSE(answers_gap("fcl_collide"));
#else
  EXPECT_TRUE(boolean_methods().empty());
#endif
  EXPECT_EQ(method_label("not_in_this_build"), "not_in_this_build");
  EXPECT_FALSE(answers_gap("not_in_this_build"));
  // Report order: the table's names in its order, then names it does not know.
  EXPECT_EQ(in_report_order({"zz_other"}), std::vector<std::string>{"zz_other"});
  if (boolean_methods().size() >= 2) {
    const std::string& a = boolean_methods()[0];
    const std::string& b = boolean_methods()[1];
    EXPECT_EQ(in_report_order({"zz_other", b, a}), (std::vector<std::string>{a, b, "zz_other"}));
  }
  const Shape sphere = Sphere(1.0);
  for (const auto& m : boolean_methods()) {
    std::string why;
    EXPECT_TRUE(baseline_serves(m, sphere, sphere, &why)) << m << ": " << why;
  }
  const std::string known = known_methods();
  for (const auto& m : boolean_methods()) EXPECT_NE(known.find(m), std::string::npos) << m;
  EXPECT_NE(known.find("oracle"), std::string::npos);
  // An unknown name is refused with the known ones, never mapped to a competitor.
  std::string why;
  const Shape s = Sphere(1.0);
  EXPECT_FALSE(baseline_serves("fcl_magic", s, s, &why));
  EXPECT_NE(why.find("unknown method"), std::string::npos) << why;
  EXPECT_NE(why.find(known), std::string::npos) << why;
}

TEST(Agreement, StatisticsMergeAndRoundTrip) {
  StatusAgreement a, b;
  a.queries = 10, a.agree = 7, a.band = 2, a.genuine = 1;
  b.queries = 5, b.agree = 4, b.failed = 1;
  a.merge(b);
  EXPECT_EQ(a.queries, 15u);
  EXPECT_EQ(a.agree + a.band + a.genuine + a.failed, a.queries);
  const StatusAgreement c = StatusAgreement::from_json(a.to_json());
  EXPECT_EQ(c.to_json(), a.to_json());
  DerivativeStats d;
  d.converged = 10, d.fd_failed = 2, d.agree = 6;
  EXPECT_DOUBLE_EQ(d.agreement(), 6.0 / 8.0);
}

// AgreementStats::merge keeps every method's status counts: into an empty
// one (what an unsharded run does with its one part), and across parts
// holding different methods; and the round trip through JSON keeps them.
TEST(Agreement, AgreementStatsMergeKeepsEachMethodsStatus) {
  AgreementStats part1, part2;
  part1.poses = 10;
  part1.status["fcl_collide"].queries = 10, part1.status["fcl_collide"].agree = 8, part1.status["fcl_collide"].band = 1;
  part1.status["fcl_collide"].genuine = 1;
  part1.status["ccd_gjk"].queries = 10, part1.status["ccd_gjk"].agree = 9, part1.status["ccd_gjk"].failed = 1;
  part2.poses = 5;
  part2.status["fcl_collide"].queries = 5, part2.status["fcl_collide"].agree = 5;
  part2.status["ccd_mpr"].queries = 5, part2.status["ccd_mpr"].genuine = 2, part2.status["ccd_mpr"].agree = 3;
  AgreementStats whole;
  whole.merge(part1);
  ASSERT_EQ(whole.status.size(), 2u);
  EXPECT_EQ(whole.status.at("fcl_collide").to_json(), part1.status.at("fcl_collide").to_json());
  whole.merge(part2);
  EXPECT_EQ(whole.poses, 15u);
  ASSERT_EQ(whole.status.size(), 3u);
  const StatusAgreement& f = whole.status.at("fcl_collide");
  EXPECT_EQ(f.queries, 15u);
  EXPECT_EQ(f.agree, 13u);
  EXPECT_EQ(f.band, 1u);
  EXPECT_EQ(f.genuine, 1u);
  EXPECT_EQ(whole.status.at("ccd_gjk").failed, 1u);
  EXPECT_EQ(whole.status.at("ccd_mpr").genuine, 2u);
  const nlohmann::json j = whole.to_json();
  EXPECT_EQ(j.at("genuine_total"), 3);
  EXPECT_EQ(AgreementStats::from_json(j).to_json().at("status"), j.at("status"));
}

// The sweep table from a results file whose figures are set by hand: each
// cell "cold / **warm**" at the row of body 1 and the column of body 2.
TEST(MarkdownWriters, SweepTableCells) {
  auto pass = [](double rate, int failures, double iters) {
    return json{{key::convergence_rate, rate}, {key::failures, failures}, {key::iterations, {{key::mean, iters}}}};
  };
  const json r = {{"schema", kResultsSchema},
                  {"scene", {{"name", "md_test"}}},
                  {"metadata",
                   {{"cpu_model", "CPU-X"}, {"compiler", "GNU 12"}, {"cxx_flags", "-O3"}, {"git_revision", "abc123"},
                    {"date_utc", "2026-01-01T00:00:00Z"}}},
                  {"sweep", {{"poses", 100}, {"generator", "paper"}}},
                  {"passes", {"cold", "warm"}},
                  {"pairs",
                   {{{"body1", "A"}, {"body2", "B"}, {"passes", {{"cold", pass(0.99, 1, 5.25)}, {"warm", pass(1.0, 0, 3.5)}}}},
                    {{"body1", "A"}, {"body2", "A"}, {"passes", {{"cold", pass(1.0, 0, 4.0)}, {"warm", pass(1.0, 0, 2.0)}}}}}}};
  const std::string md = markdown_table(r, "x.json");
  EXPECT_EQ(md.rfind("# md_test\n", 0), 0u) << md;
  EXPECT_NE(md.find("`idcol_harness table x.json`"), std::string::npos) << md;
  EXPECT_NE(md.find("100 poses per pair and pass (generator `paper`)"), std::string::npos) << md;
  EXPECT_NE(md.find("CPU: CPU-X; compiler GNU 12, flags `-O3`; git abc123"), std::string::npos) << md;
  EXPECT_NE(md.find("| Body 1 \\ Body 2 | A | B |"), std::string::npos) << md;
  EXPECT_NE(md.find("| A | 100.0000 / **100.0000** | 99.0000 / **100.0000** |\n| B | n/a | n/a |"), std::string::npos) << md;
  EXPECT_NE(md.find("| A | 0 / **0** | 1 / **0** |"), std::string::npos) << md;
  EXPECT_NE(md.find("| A | 4.00 / **2.00** | 5.25 / **3.50** |"), std::string::npos) << md;
  EXPECT_EQ(md.find("time per solve"), std::string::npos) << "no timing recorded, no timing table";

  // A few explicit pairs among many shapes: one row per pair, not a mostly
  // empty matrix.
  json sparse = r;
  sparse["pairs"] = {{{"body1", "C"}, {"body2", "D"}, {"passes", {{"cold", pass(1.0, 0, 4.0)}, {"warm", pass(1.0, 0, 2.0)}}}},
                     {{"body1", "E"}, {"body2", "F"}, {"passes", {{"cold", pass(0.5, 7, 9.0)}, {"warm", pass(1.0, 0, 2.5)}}}}};
  const std::string rows = markdown_table(sparse, "x.json");
  EXPECT_EQ(rows.find("Body 1 \\ Body 2"), std::string::npos) << rows;
  EXPECT_NE(rows.find("| Body 1 | Body 2 | cold / **warm** |"), std::string::npos) << rows;
  EXPECT_NE(rows.find("| E | F | 50.0000 / **100.0000** |"), std::string::npos) << rows;
  EXPECT_NE(rows.find("| E | F | 7 / **0** |"), std::string::npos) << rows;
  EXPECT_EQ(rows.find(" n/a |"), std::string::npos) << rows;
}

// Wall minus CPU time of an undisturbed loop can come out slightly negative
// (the clocks are read at different instants): the results file stores 0 and
// the table prints 0.00, never -0.00, also for files written before the clamp.
TEST(MarkdownWriters, DescheduledTimeIsNeverNegative) {
  PassStats s;
  s.has_timing = true;
  SolveResult r;
  r.status = SolveStatus::Converged;
  s.add(r, true, 1500.0);
  s.loop_wall_s = 1.000;
  s.loop_cpu_s = 1.004;
  json pass = s.to_json();
  EXPECT_EQ(pass["time"]["loop"]["descheduled_seconds"].get<double>(), 0.0) << pass["time"]["loop"];
  s.loop_cpu_s = 0.75;
  EXPECT_DOUBLE_EQ(s.to_json()["time"]["loop"]["descheduled_seconds"].get<double>(), 0.25);

  pass["time"]["loop"]["descheduled_seconds"] = -0.003;  // as an older harness wrote it
  const json r_file = {{"schema", kResultsSchema},
                       {"scene", {{"name", "desched"}}},
                       {"metadata", {{"cpu_model", "CPU-X"}, {"compiler", "GNU 12"}, {"cxx_flags", "-O3"}, {"git_revision", "abc123"},
                                     {"date_utc", "2026-01-01T00:00:00Z"}}},
                       {"sweep", {{"poses", 1}, {"generator", "paper"}}},
                       {"passes", {"cold"}},
                       {"pairs", {{{"body1", "A"}, {"body2", "A"}, {"passes", {{"cold", pass}}}}}}};
  const std::string md = markdown_table(r_file, "x.json");
  const auto at = md.find("Time the thread was descheduled");
  ASSERT_NE(at, std::string::npos) << md;
  const std::string table = md.substr(at, md.find("p99 time per solve", at) - at);
  EXPECT_NE(table.find("| A | 0.00 |"), std::string::npos) << table;
  EXPECT_EQ(table.find("-0.00"), std::string::npos) << table;
}

// The stress report from the trimmed stress fixture (two cases, two passes).
TEST(MarkdownWriters, StressReportRows) {
  const json r = read_json_file(std::string(IDCOL_HARNESS_FIXTURES_DIR) + "/compare_stress.json");
  const std::string md = stress_markdown(r, "s.json");
  EXPECT_NE(md.find("| sphere_warm_jumps | S x S | shell | cold | 10000 | 100.0000% | 0 | 0 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| box_box_beta1000 | Box x Box | shell | warm | 10000 | 88.0400% | iteration_limit 185, line_search_failed 1011 | 0 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| 237.7 / 437 |"), std::string::npos) << md;
  EXPECT_NE(md.find("**Total: 37608 genuine of 40000 solves; 0 false convergences; 0 failure records.**"), std::string::npos) << md;
}

}  // namespace
}  // namespace idcol::harness

// The sweep's Markdown report: the paper's Table 1 layout (one grid per
// figure, cold / **warm** in each cell) and the baselines' Table 2 layout.
#include "studies/sweep/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/text.hpp"
#include "stats/stats.hpp"
#include "studies/sweep/agreement.hpp"
#include "studies/sweep/sweep_keys.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

using CellFn = std::function<std::string(const json& pass)>;

std::string grid(const json& results, const std::string& title, const CellFn& cell) {
  // Shape order as the scene lists them, taken from the pairs.
  std::vector<std::string> names;
  auto add = [&](const std::string& n) {
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  };
  std::map<std::pair<std::string, std::string>, const json*> at;
  for (const auto& p : results.at("pairs")) {
    add(p.at("body1").get<std::string>());
    add(p.at("body2").get<std::string>());
    at[{p.at("body1").get<std::string>(), p.at("body2").get<std::string>()}] = &p;
  }
  auto cell_text = [&](const json& pair) {
    const json& passes = pair.at("passes");
    std::string cold = passes.contains("cold") ? cell(passes.at("cold")) : "";
    std::string warm = passes.contains("warm") ? cell(passes.at("warm")) : "";
    return cold + (!cold.empty() && !warm.empty() ? " / " : "") + (warm.empty() ? "" : "**" + warm + "**");
  };
  std::ostringstream o;
  // A scene that lists a few explicit pairs reads better as one row per pair
  // than as a mostly empty matrix: the matrix only when the pairs fill at
  // least half of its upper triangle.
  const std::size_t n_names = names.size(), n_pairs = results.at("pairs").size();
  if (2 * n_pairs < n_names * (n_names + 1) / 2) {
    const json& ps = results.at("passes");
    const std::string head = ps.size() == 2 ? "cold / **warm**" : ps.at(0) == "cold" ? "cold" : "**warm**";
    o << "**" << title << "**\n\n| Body 1 | Body 2 | " << head << " |\n|---|---|---|\n";
    for (const auto& p : results.at("pairs"))
      o << "| " << md_text(p.at("body1").get<std::string>()) << " | " << md_text(p.at("body2").get<std::string>()) << " | " << cell_text(p)
        << " |\n";
    return o.str();
  }
  o << "**" << title << "**\n\n| Body 1 \\ Body 2 |";
  for (auto& n : names) o << " " << md_text(n) << " |";
  o << "\n|---|";
  for (std::size_t i = 0; i < names.size(); ++i) o << "---|";
  o << "\n";
  for (auto& r : names) {
    o << "| " << md_text(r) << " |";
    for (auto& c : names) {
      const auto it = at.find({r, c});
      o << " " << (it == at.end() ? std::string(kMissing) : cell_text(*it->second)) << " |";
    }
    o << "\n";
  }
  return o.str();
}
}  // namespace

namespace {

/// The paper's Table 2 layout (methods as rows, pairs as columns) and the
/// agreement figures, for the pairs that recorded baselines / derivatives.
// The header row of a table with one column per pair.
void pair_header(std::ostream& o, const std::vector<const json*>& ps, const char* first) {
  o << "| " << first << " |";
  for (auto* p : ps) o << " " << md_text((*p)["body1"].get<std::string>() + "-" + (*p)["body2"].get<std::string>()) << " |";
  o << "\n|---|";
  for (std::size_t i = 0; i < ps.size(); ++i) o << "---|";
  o << "\n";
}

// A row of figures: cell(pair[record]) for each pair.
template <class Cell>
void figure_row(std::ostream& o, const std::vector<const json*>& ps, const char* record, const std::string& label, Cell cell) {
  o << "| " << label << " |";
  for (auto* p : ps) o << " " << cell((*p)[record]) << " |";
  o << "\n";
}

// A time of a timing entry in us, 2 decimals ("n/a" if absent or null).
std::string us_of(const json& t, const char* k) {
  return t.contains(k) && t[k].is_number() ? fixed(t[k].get<double>() / 1e3, 2) : std::string(kMissing);
}

// The mean time per query (us) of method m on pair p, or NaN.
double mean_us(const json& p, const std::string& m) {
  const json& ms = p["baselines"]["timing"]["methods"];
  if (!ms.contains(m) || !ms[m]["mean_ns"].is_number() || ms[m][key::wrong].get<std::uint64_t>() > 0) return NAN;
  return ms[m]["mean_ns"].get<double>() / 1e3;
}

// The paper's own layout of its Table 2 where the scene gave the paper's
// figures ([reference]): each method's mean time per query on this machine
// beside the paper's (another machine: the ratios compare, the times do not),
// and the ratio of each method to iDCOL cold and warm.
void reference_table(std::ostream& o, const json& results, const std::vector<const json*>& bp) {
  if (!results.contains("reference")) return;
  const json& ref = results["reference"];
  const json& fig = ref["mean_us"];
  auto paper = [&](const std::string& m, const json* p) {
    const std::string pk = (*p)["body1"].get<std::string>() + "-" + (*p)["body2"].get<std::string>();
    return fig.contains(m) && fig[m].contains(pk) ? fig[m][pk].get<double>() : NAN;
  };
  o << "\n**The paper's Table 2, regenerated: mean time per query (us) here / in the paper** (" << md_text(ref["source"].get<std::string>())
    << "). The paper's figures come from another machine: compare the ratios below, not the times.\n\n";
  pair_header(o, bp, "Method");
  // The paper's methods, then iDCOL through the batch (which it did not time).
  std::vector<std::string> methods;
  for (const auto& [m, by_pair] : fig.items()) methods.push_back(m);
  const std::vector<std::string> idcol = {"idcol_cold", "idcol_warm", "idcol_batch_cold", "idcol_batch_warm"};
  for (const std::string& m : idcol)
    if (!fig.contains(m) && (*bp[0])["baselines"]["timing"]["methods"].contains(m)) methods.push_back(m);
  auto label = [](const std::string& m) {
    if (m == "idcol_cold") return std::string("iDCOL (cold)");
    if (m == "idcol_warm") return std::string("iDCOL (warm start)");
    if (m == "idcol_batch_cold") return std::string("iDCOL batch, one core (cold)");
    if (m == "idcol_batch_warm") return std::string("iDCOL batch, one core (warm start)");
    return method_label(m);
  };
  auto is_idcol = [&](const std::string& m) { return std::find(idcol.begin(), idcol.end(), m) != idcol.end(); };
  for (const std::string& m : methods) {
    o << "| " << label(m) << " |";
    for (auto* p : bp) o << " " << fixed(mean_us(*p, m), 2) << " / " << fixed(paper(m, p), 2) << " |";
    o << "\n";
  }
  for (const std::string& base : idcol) {
    if (std::find(methods.begin(), methods.end(), base) == methods.end()) continue;
    for (const std::string& m : methods) {
      if (is_idcol(m)) continue;
      o << "| " << label(m) << " / " << label(base) << " (time ratio) |";
      for (auto* p : bp) o << " " << fixed(mean_us(*p, m) / mean_us(*p, base), 2) << " / " << fixed(paper(m, p) / paper(base, p), 2) << " |";
      o << "\n";
    }
  }
}

// The paper's Table 2 layout: median time per query of each method, for the
// pairs that timed the baselines.
void timing_table(std::ostream& o, const std::vector<const json*>& bp) {
  auto header = [&](const std::vector<const json*>& ps, const char* first) { pair_header(o, ps, first); };
  const json& t0 = (*bp[0])["baselines"]["timing"];
  if (t0["poses"].get<std::uint64_t>() > 0) {
    o << "\n**Table 2 layout: time per query (us, timer overhead subtracted): median / mean / p99, on the first "
      << t0["poses"].get<std::uint64_t>()
      << " poses of each pair, the same poses for every method, one method after the other on one thread.** A method "
         "whose answer was wrong on any timed pose (genuine disagreement or library failure, checked before timing) "
         "shows \"wrong\" instead of a time.\n\n";
    header(bp, "Method");
    // The competitors' rows (labels from the competitor table) between
    // iDCOL's and the oracle's.
    std::vector<std::string> timed;  // in_report_order keeps each name once
    for (auto* p : bp)
      for (const auto& [key, t] : (*p)["baselines"]["timing"]["methods"].items())
        if (key.rfind("idcol_", 0) != 0 && key != "oracle") timed.push_back(key);
    std::vector<std::pair<std::string, std::string>> rows = {{"idcol_cold", "iDCOL (cold)"},
                                                             {"idcol_warm", "iDCOL (warm start)"},
                                                             {"idcol_batch_cold", "iDCOL batch, one core (cold)"},
                                                             {"idcol_batch_warm", "iDCOL batch, one core (warm start)"}};
    // A method the competitor table does not know (a hand-edited file) is labelled by its key, escaped.
    for (const std::string& m : in_report_order(timed)) rows.emplace_back(m, md_text(method_label(m)));
    rows.emplace_back("oracle", "exact oracle (PW / LP / support-function bracket)");
    for (const auto& [key, label] : rows) {
      bool any = false;
      for (auto* p : bp) any |= (*p)["baselines"]["timing"]["methods"].contains(key);
      if (!any) continue;
      o << "| " << label << " |";
      for (auto* p : bp) {
        const json& m = (*p)["baselines"]["timing"]["methods"];
        if (!m.contains(key)) {
          o << " " << kMissing << " |";
          continue;
        }
        const json& t = m[key];
        if (t[key::wrong].get<std::uint64_t>() > 0)
          o << " wrong (" << t[key::wrong].get<std::uint64_t>() << "/" << t["count"].get<std::uint64_t>() << ") |";
        else
          o << " " << us_of(t, key::median_ns) << " / " << us_of(t, "mean_ns") << " / " << us_of(t, key::p99_ns) << " |";
      }
      o << "\n";
    }
  }
}

// Agreement of the collision status (or gap sign) with each baseline, and
// alpha* and normals against the oracle.
void baselines_table(std::ostream& o, const std::vector<const json*>& bp) {
  auto header = [&](const std::vector<const json*>& ps, const char* first) { pair_header(o, ps, first); };
  o << "\n**Agreement with the baselines on every pose** (collision status alpha* < 1 vs each boolean; FCL distance: "
       "the sign of its signed distance vs the sign of d_D = (1 - 1/alpha*)|r|). Cells: agree / band / genuine / "
       "library failed. Band: the disagreement lies where the smoothing bracket widened by band_tolerance contains 1 "
       "(see harness/README.md, \"Baseline agreement\").\n\n";
  header(bp, "Figure");
  auto row = [&](const std::string& label, auto cell) { figure_row(o, bp, "baselines", label, cell); };
  row("poses", [](const json& b) { return std::to_string(b["poses"].get<std::uint64_t>()); });
  std::vector<std::string> statused;
  for (auto* p : bp)
    for (const auto& [m, st] : (*p)["baselines"]["status"].items()) statused.push_back(m);
  for (const std::string& m : in_report_order(statused)) {
    row(md_text(m) + (answers_gap(m) ? " (gap sign)" : " (status)"), [&](const json& b) {
      if (!b["status"].contains(m)) return std::string(kMissing);
      const json& s = b["status"][m];
      return std::to_string(s["agree"].get<std::uint64_t>()) + " / " + std::to_string(s[key::band].get<std::uint64_t>()) +
             " / **" + std::to_string(s[key::genuine].get<std::uint64_t>()) + "** / " +
             std::to_string(s[key::failed].get<std::uint64_t>());
    });
  }
  row("iDCOL alpha* outside the smoothing bracket", [](const json& b) { return std::to_string(b[key::idcol_outside_bracket].get<std::uint64_t>()); });
  row("oracle failed", [](const json& b) { return std::to_string(b[key::oracle_failed].get<std::uint64_t>()); });
  row("iDCOL not converged (cold)", [](const json& b) { return std::to_string(b["idcol_not_converged"].get<std::uint64_t>()); });
  for (const auto& err : {std::pair<const char*, const char*>{key::alpha_abs_err, "abs"}, {key::alpha_rel_err, "rel"}}) {
    const char* e = err.first;
    row(std::string(err.second) + " alpha* error vs oracle: mean / p99 / max",
        [e](const json& b) { return sci(b[e][key::mean]) + " / " + sci(b[e][key::p99]) + " / " + sci(b[e][key::max]); });
  }
  // What each method answers besides its boolean (MethodAnswerStats).
  std::vector<std::string> answering;
  // A file written before the per-method answers has no key::answers: its
  // methods have no rows (a const json's operator[] may not be given a
  // missing key).
  for (auto* p : bp)
    if ((*p)["baselines"].contains(key::answers))
      for (const auto& [m, a] : (*p)["baselines"][key::answers].items()) answering.push_back(m);
  auto summary = [](const json& h) { return sci(h["p50"]) + " / " + sci(h[key::p99]) + " / " + sci(h[key::max]); };
  for (const std::string& m : in_report_order(answering)) {
    auto of = [&](const json& b) -> const json* {
      return b.contains(key::answers) && b[key::answers].contains(m) ? &b[key::answers][m] : nullptr;
    };
    auto any = [&](const char* count) {
      for (auto* p : bp)
        if (const json* a = of((*p)["baselines"]); a && (*a)[count].get<std::uint64_t>() > 0) return true;
      return false;
    };
    const std::string label = method_label(m);
    if (any(key::alpha_poses)) {
      row(label + ": alpha outside the oracle's bracket, relative: p50 / p99 / max (beyond its own bound)", [&](const json& b) {
        const json* a = of(b);
        return a ? summary((*a)[key::alpha_rel_err]) + " (**" + std::to_string((*a)[key::alpha_outside_bound].get<std::uint64_t>()) + "**)"
                 : std::string(kMissing);
      });
      row(label + ": \\|alpha - iDCOL alpha*\\| / iDCOL alpha*: p50 / p99 / max", [&](const json& b) {
        const json* a = of(b);
        return a ? summary((*a)[key::alpha_rel_diff_idcol]) : std::string(kMissing);
      });
      row(label + ": iterations mean / p99 / max", [&](const json& b) {
        const json* a = of(b);
        if (!a) return std::string(kMissing);
        const json& it = (*a)[key::method_iterations];
        // Counts are integers: p99 (a bin's centre, 200 bins per decade) and max read rounded.
        auto whole = [](const json& v) { return v.is_number() ? fixed(std::round(v.get<double>()), 0) : std::string(kMissing); };
        return fixed(it[key::mean].is_number() ? it[key::mean].get<double>() : NAN, 2) + " / " + whole(it[key::p99]) + " / " +
               whole(it[key::max]);
      });
    }
    if (any(key::normal_poses))
      row("normal angle vs " + label + " (rad), near contact: p50 / p99 / max (poses)", [&](const json& b) {
        const json* a = of(b);
        return a ? summary((*a)[key::normal_angle_rad]) + " (" + std::to_string((*a)[key::normal_poses].get<std::uint64_t>()) + ")"
                 : std::string(kMissing);
      });
  }
  o << "\nPercentiles come from log-binned histograms (20 bins per decade: +-12% resolution; iterations 200 per decade).\n";
}

// Derivatives against finite differences, for the pairs that checked them.
void derivatives_table(std::ostream& o, const std::vector<const json*>& dp) {
  auto header = [&](const std::vector<const json*>& ps, const char* first) { pair_header(o, ps, first); };
  o << "\n**Derivative agreement** (`idcol::check_derivatives`: IFT sensitivities vs Richardson central differences "
       "through the SE(3) exponential, on poses k with k % every == 0).\n\n";
  header(dp, "Figure");
  auto row = [&](const std::string& label, auto cell) { figure_row(o, dp, "derivatives", label, cell); };
  row("poses checked", [](const json& d) { return std::to_string(d["poses"].get<std::uint64_t>()); });
  row("agreement (%)", [](const json& d) { return fixed(100.0 * d[key::agreement].get<double>(), 3); });
  row("disagree, flagged unreliable", [](const json& d) { return std::to_string(d["disagree_flagged"].get<std::uint64_t>()); });
  row("disagree, reported reliable", [](const json& d) { return "**" + std::to_string(d[key::disagree_unflagged].get<std::uint64_t>()) + "**"; });
  row("finite differences failed", [](const json& d) { return std::to_string(d["fd_failed"].get<std::uint64_t>()); });
  row("worst error (unflagged)", [](const json& d) { return sci(d[key::worst_error]); });
}

std::string agreement_tables(const json& results) {
  std::vector<const json*> bp, dp;
  for (const auto& p : results.at("pairs")) {
    if (p.contains("baselines")) bp.push_back(&p);
    if (p.contains("derivatives")) dp.push_back(&p);
  }
  std::ostringstream o;
  if (!bp.empty()) {
    reference_table(o, results, bp);
    timing_table(o, bp);
    baselines_table(o, bp);
  }
  if (!dp.empty()) derivatives_table(o, dp);
  return o.str();
}

/// The poses the file holds: "1000000 poses" for the whole sweep (a
/// single run, or shards merged), "10000 poses (poses 0 to 9999 of the
/// scene's 1000000: shard 0/100)" for a shard.
std::string poses_run(const json& results) {
  const std::uint64_t poses = results.at("sweep").at("poses").get<std::uint64_t>();
  // A file without a shard's pose range (written by hand) reads as the whole sweep.
  const json sh = results.value("shard", json::object());
  const json range = sh.value("poses", json::array());
  if (!range.is_array() || range.size() != 2 || !range[0].is_number_unsigned() || !range[1].is_number_unsigned())
    return std::to_string(poses) + " poses";
  const std::uint64_t lo = range[0].get<std::uint64_t>(), hi = range[1].get<std::uint64_t>();
  if (lo == 0 && hi == poses) return std::to_string(poses) + " poses";
  return std::to_string(hi > lo ? hi - lo : 0) + " poses (" + (hi > lo ? "poses " + std::to_string(lo) + " to " + std::to_string(hi - 1) : "none") +
         " of the scene's " + std::to_string(poses) + ": shard " + sh.value("index", json("?")).dump() + "/" +
         sh.value("count", json("?")).dump() + ")";
}

}  // namespace

std::string markdown_table(const json& results, const std::string& results_path) {
  const json& meta = results.at("metadata");
  const json& sweep = results.at("sweep");
  std::ostringstream o;
  o << "# " << md_text(results.at("scene").at("name").get<std::string>()) << "\n\n";
  o << "Made by " << md_code("idcol_harness table " + results_path) << " from that results file only.\n\n";
  const json& passes = results.at("passes");
  const bool both = passes.size() == 2;
  o << "Each cell: "
    << (both ? "without warm start / **with warm start**"
             : (passes.at(0) == "cold" ? "without warm start (cold pass only)" : "**with warm start** (warm pass only)"))
    << "; " << poses_run(results) << " per pair and pass (generator " << md_code(sweep.at("generator").get<std::string>())
    << ").\n";
  o << "CPU: " << md_text(meta.at("cpu_model").get<std::string>()) << "; compiler " << md_text(meta.at("compiler").get<std::string>())
    << ", flags " << md_code(meta.at("cxx_flags").get<std::string>()) << "; git "
    << md_text(meta.at("git_revision").is_null() ? meta.at("git_revision_configure").get<std::string>()
                                                 : meta.at("git_revision").get<std::string>())
    << "; " << md_text(meta.at("date_utc").get<std::string>()) << ".\n\n";
  const bool timed = [&] {
    for (const auto& p : results.at("pairs"))
      for (const auto& [k, v] : p.at("passes").items())
        if (v.contains(key::time)) return true;
    return false;
  }();
  if (timed) {
    // A per-solve time of the pass's "all" summary, in us.
    const auto us = [](const char* stat) -> CellFn {
      return [stat](const json& p) { return p.contains(key::time) ? fixed(p[key::time][key::all][stat].is_null() ? NAN : p[key::time][key::all][stat].get<double>() / 1e3, 2) : std::string(kMissing); };
    };
    o << grid(results, "Mean time per solve (us), all solves including failures", us("mean_ns")) << "\n";
    o << grid(results, "Median time per solve (us)", us(key::median_ns)) << "\n";
    o << grid(results, "Time the thread was descheduled during the pass (s; it inflates means and maxima)",
              [](const json& p) { return p.contains(key::time) ? fixed(descheduled_seconds(p[key::time]["loop"]["descheduled_seconds"].get<double>(), 0.0), 2) : std::string(kMissing); })
      << "\n";
    o << grid(results, "p99 time per solve (us)", us(key::p99_ns)) << "\n";
  }
  o << grid(results, "Convergence rate (%)",
            [](const json& p) { return fixed(100.0 * p.at(key::convergence_rate).get<double>(), 4); })
    << "\n";
  o << grid(results, "Failed solves (count)", [](const json& p) { return std::to_string(p.at(key::failures).get<std::uint64_t>()); })
    << "\n";
  o << grid(results, "Mean Newton iterations",
            [](const json& p) { return p.contains(key::iterations) ? fixed(p[key::iterations][key::mean].is_number() ? p[key::iterations][key::mean].get<double>() : NAN, 2) : std::string(kMissing); });
  o << agreement_tables(results);
  return o.str();
}

}  // namespace idcol::harness

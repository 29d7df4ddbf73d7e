#include "cli/history_cmd.hpp"

#include <cstdio>
#include <fstream>
#include <iostream>

#include "io/files.hpp"
#include "report/history.hpp"
#include "studies/results_file.hpp"

namespace idcol::harness {

using nlohmann::json;

const char* const kHistoryUsage =
    "  idcol_harness history add RESULTS.json --into HISTORY.jsonl [--thresholds T.toml] [--instructions IR.json]\n"
    "      appends one line (JSON, keys sorted) to HISTORY: the scene's identity and series, the machine, build and git\n"
    "      revision, and every metric a guard matches per pair (case, point) and pass (guards: T.toml, default: compare's\n"
    "      default guards); IR.json (scripts/callgrind_instructions.sh) adds instructions per solve\n"
    "  idcol_harness history show HISTORY.jsonl [--metric GLOB] [--pair GLOB] [--html OUT.html]\n"
    "      the trend of each metric over commits, per series (scenes that cannot be compared stay apart) and machine,\n"
    "      with each step beyond its guard at the first commit after which it stays; --html: one static page of SVG plots\n"
    "      exit: 0 done; 1 a file could not be read or written; 2 usage error or bad input\n";

namespace {

struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string value_of(const std::vector<std::string>& a, std::size_t& i) {
  if (i + 1 >= a.size()) throw BadInput(a[i] + " needs a value");
  return a[++i];
}

int add(const std::vector<std::string>& a) {
  std::string in, into, th, ir;
  for (std::size_t i = 2; i < a.size(); ++i) {
    if (a[i] == "--into") into = value_of(a, i);
    else if (a[i] == "--thresholds") th = value_of(a, i);
    else if (a[i] == "--instructions") ir = value_of(a, i);
    else if (!a[i].empty() && a[i][0] == '-') throw BadInput("history add: unknown option " + a[i]);
    else if (in.empty()) in = a[i];
    else throw BadInput("history add takes one results file");
  }
  if (in.empty() || into.empty()) throw BadInput("history add needs RESULTS.json and --into HISTORY.jsonl");
  try {
    require_distinct_files({{"the results file", in}, {"--thresholds", th}, {"--instructions", ir}}, {{"--into", into}});
  } catch (const std::invalid_argument& e) {
    throw BadInput(e.what());
  }
  const std::vector<Guard> guards = th.empty() ? default_guards() : guards_in_force(load_guards(th));
  json results;
  try {
    results = read_results_file(in);
  } catch (const std::exception& e) {
    throw HistoryError(e.what());
  }
  json instr;
  try {
    if (!ir.empty()) instr = read_json_file(ir);
  } catch (const std::exception& e) {
    throw HistoryError(std::string("--instructions: ") + e.what());
  }
  json rec;
  try {
    rec = history_record(results, guards, instr, in);
  } catch (const HistoryError& e) {
    throw HistoryError(in + ": " + e.what());
  } catch (const json::exception& e) {
    throw HistoryError(in + ": not a complete results file (" + e.what() + ")");
  }
  append_history(into, rec);
  std::size_t metrics = 0;
  for (const auto& [k, m] : rec.at("entries").items()) metrics += m.size();
  std::printf("%s\n", escaped(format("history %s: + git %s on %s, series %s: %zu entries, %zu metrics", into.c_str(),
                                      rec.at("run").value("git_revision", "?").substr(0, 12).c_str(),
                                      rec.at("run").value("machine", "?").c_str(), rec.at("series").get<std::string>().c_str(),
                                      rec.at("entries").size(), metrics)).c_str());
  return 0;
}

int show(const std::vector<std::string>& a) {
  std::string in, html;
  HistoryFilter f;
  for (std::size_t i = 2; i < a.size(); ++i) {
    if (a[i] == "--metric") f.metric = value_of(a, i);
    else if (a[i] == "--pair") f.pair = value_of(a, i);
    else if (a[i] == "--html") html = value_of(a, i);
    else if (!a[i].empty() && a[i][0] == '-') throw BadInput("history show: unknown option " + a[i]);
    else if (in.empty()) in = a[i];
    else throw BadInput("history show takes one history file");
  }
  if (in.empty()) throw BadInput("history show needs HISTORY.jsonl");
  if (!std::ifstream(in)) throw HistoryError(in + ": cannot be read");
  const std::vector<json> records = read_history(in);
  if (html.empty()) {
    std::cout << history_table(records, f);
    return 0;
  }
  try {
    require_distinct_files({{"the history", in}}, {{"--html", html}});
  } catch (const std::invalid_argument& e) {
    throw BadInput(e.what());
  }
  std::size_t plots = 0;
  write_file_atomically(html, history_html(records, f, &plots));
  std::printf("%s: %zu plots from %zu runs\n", html.c_str(), plots, records.size());
  return 0;
}

}  // namespace

int cmd_history(const std::vector<std::string>& a) {
  try {
    if (a.size() >= 2 && a[1] == "add") return add(a);
    if (a.size() >= 2 && a[1] == "show") return show(a);
    throw BadInput("history expects add or show");
  } catch (const BadInput& e) {
    std::fprintf(stderr, "idcol_harness history: %s (see idcol_harness history --help)\n", e.what());
    return 2;
  } catch (const HistoryError& e) {
    std::fprintf(stderr, "idcol_harness history: %s\n", e.what());
    return 2;
  } catch (const CompareError& e) {
    std::fprintf(stderr, "idcol_harness history: %s\n", e.what());
    return 2;
  }
}

}  // namespace idcol::harness

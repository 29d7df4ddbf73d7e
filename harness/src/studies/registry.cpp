// The table of study kinds (one StudyKind object per folder under studies/),
// and what is the same for every kind: loading a scene as its study, the cost line.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "io/text.hpp"
#include "scene/scene.hpp"
#include "studies/kinds.hpp"
#include "studies/study.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {
/// Seconds as the cost line writes them: "0.42 s", "4.1 min", "2.3 h".
std::string duration_text(double sec) {
  if (sec < 120) return format("%.2g s", sec);
  if (sec < 7200) return format("%.2g min", sec / 60);
  return format("%.2g h", sec / 3600);
}
}  // namespace

std::string cost_line(const Study& s, const StudyOptions& opt) {
  const std::vector<CostPart> parts = s.estimate(opt);
  const double sec = s.estimated_seconds(opt);
  const int threads = opt.threads > 0 ? opt.threads : s.kind().default_threads;
  const std::uint64_t solves = s.solves(opt);
  std::string t = solves == kCountSaturated ? format("cost: more than %llu solves (past what a 64-bit count holds)",
                                                     static_cast<unsigned long long>(kCountSaturated - 1))
                                            : format("cost: %llu solves", static_cast<unsigned long long>(solves));
  if (sec > 0.0) {
    t += ", roughly " + duration_text(sec) + format(" on %d core%s (", threads, threads > 1 ? "s" : "");
    for (std::size_t i = 0; i < parts.size(); ++i)
      t += (i ? ", " : "") + parts[i].name + " ~" + duration_text(parts[i].seconds);
    t += "; an estimate for this machine class, not a measurement)";
  }
  return t;
}

std::unique_ptr<Study> load_study(const std::string& path, const std::string& expected) {
  Scene s = parse_scene(read_scene_file(path), path);
  const StudyKind& k = *study_kind_named(s.kind->name);
  if (!expected.empty() && k.name != expected)
    throw SceneError(path, s.kind->section ? s.kind->section : "(file)",
                     std::string("a ") + k.name + " scene, not a " + expected + " scene (run it with `idcol_harness run`)");
  return k.make(std::move(s));
}

const std::vector<std::reference_wrapper<const StudyKind>>& study_kinds() {
  static const std::vector<std::reference_wrapper<const StudyKind>> kinds = [] {
    std::vector<std::reference_wrapper<const StudyKind>> v = {sweep_kind(), stress_kind(), smoothing_kind(), toi_kind()};
    // Each kind sets its names by name; one it forgot is caught here, at the
    // first use of the table, not as a null pointer in some command.
    for (const StudyKind& k : v)
      if (!k.name || !k.noun || !k.schema || !k.entries || !k.entry_word || k.full_entry.empty() || !k.scene_is ||
          !k.run_options || (!k.has_table() && !k.tables_from))
        throw std::logic_error(std::string("study kind ") + (k.name ? k.name : "(unnamed)") + ": a name of its row is not set");
    return v;
  }();
  return kinds;
}

const StudyKind* study_kind_named(const std::string& name) {
  for (const StudyKind& k : study_kinds())
    if (name == k.name) return &k;
  return nullptr;
}

const StudyKind* study_kind_of_schema(const std::string& schema) {
  for (const StudyKind& k : study_kinds())
    if (schema == k.schema) return &k;
  return nullptr;
}

}  // namespace idcol::harness

// The table of study kinds (kinds.def: one StudyKind object per folder under
// studies/), and what is the same for every kind: reading a scene, loading
// it as its study, the cost line.
#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "io/text.hpp"
#include "scene/scene.hpp"
#include "scene/scene_toml.hpp"
#include "studies/study.hpp"

namespace idcol::harness {

using nlohmann::json;

// Each row's kind object, defined in its folder (studies/<kind>/).
#define IDCOL_STUDY_KIND(kind) const StudyKind& kind##_kind();
#include "studies/kinds.def"
#undef IDCOL_STUDY_KIND

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

Scene parse_scene(const std::string& text, const std::string& file) {
  const toml::table root = parse_toml(text, file);
  const auto& kinds = study_kinds();
  auto kind = std::find_if(kinds.begin(), kinds.end(), [&](const StudyKind& k) { return k.section && root.contains(k.section); });
  if (kind == kinds.end()) kind = std::find_if(kinds.begin(), kinds.end(), [](const StudyKind& k) { return !k.section; });
  const StudyKind& k = *kind;
  Scene s;
  s.path = file;
  s.text = text;
  s.kind = k.name;
  Reader top(root, file, "");
  s.description = top.string("description", false);
  read_solver_table(top, file, s.solver);  // [solver] (optional): overrides of SolverOptions
  k.read_scene(top, file, s);
  top.finish();
  return s;
}

Scene load_scene(const std::string& path) { return parse_scene(read_scene_file(path), path); }

std::unique_ptr<Study> load_study(const std::string& path, const std::string& expected) {
  Scene s = load_scene(path);
  const StudyKind& k = *study_kind_named(s.kind);
  if (!expected.empty() && k.name != expected)
    throw SceneError(path, k.section ? k.section : "(file)",
                     std::string("a ") + k.name + " scene, not a " + expected + " scene (run it with `idcol_harness run`)");
  return k.make(std::move(s));
}

const std::vector<std::reference_wrapper<const StudyKind>>& study_kinds() {
  static const std::vector<std::reference_wrapper<const StudyKind>> kinds = [] {
    std::vector<std::reference_wrapper<const StudyKind>> v = {
#define IDCOL_STUDY_KIND(kind) kind##_kind(),
#include "studies/kinds.def"
#undef IDCOL_STUDY_KIND
    };
    // Each kind sets its names by name; one it forgot is caught here, at the
    // first use of the table, not as a null pointer in some command. A scene
    // file is one kind's by its section: no two kinds claim one, and one kind
    // (the sweep) takes a file with none of the others'.
    std::set<std::string> names, sections;
    int without_section = 0;
    for (const StudyKind& k : v) {
      if (!k.name || !k.noun || !k.schema || !k.entries || !k.entry_word || k.full_entry.empty() || !k.scene_is ||
          !k.run_options || (!k.has_table() && !k.tables_from) || k.identity.top.empty() || k.identity.entry.empty())
        throw std::logic_error(std::string("study kind ") + (k.name ? k.name : "(unnamed)") + ": a name of its row is not set");
      if (!names.insert(k.name).second) throw std::logic_error(std::string("study kind ") + k.name + ": named twice in kinds.def");
      if (!k.section) ++without_section;
      else if (!sections.insert(k.section).second)
        throw std::logic_error(std::string("study kind ") + k.name + ": its section [" + k.section + "] is another kind's");
    }
    if (without_section != 1)
      throw std::logic_error("kinds.def: exactly one study kind may have no section (it takes a scene with none of the others')");
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

// A sweep's own sections of its scene file, read and written back
// (sweep_spec.hpp).
#include "studies/sweep/sweep_spec.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "io/keys.hpp"
#include "referee/methods.hpp"
#include "scene/scene_toml.hpp"

namespace idcol::harness {

namespace {

/// The run.record items, in the scene's order.
const Names<bool RecordSpec::*> kRecordItems = {
    {"timing", &RecordSpec::timing},     {key::iterations, &RecordSpec::iterations},   {"residuals", &RecordSpec::residuals},
    {key::failures, &RecordSpec::failures}, {"per_pose", &RecordSpec::per_pose},       {"derivatives", &RecordSpec::derivatives},
    {"checks", &RecordSpec::checks},     {"baselines", &RecordSpec::baselines}};

/// A sweep's [run], [baselines] and [derivatives].
void read_run(Reader& top, const std::string& file, const Scene& s, SweepSpec& sw) {
  // [run]
  {
    Reader r(*top.table("run", true), file, "run");
    sw.all_pairs = read_pair_list(s, r, "pairs", "all", true, "expected \"all\" or an array of [name, name] arrays", sw.pairs);
    for (int i = 0; sw.all_pairs && i < static_cast<int>(s.shapes.size()); ++i)
      for (int j = i; j < static_cast<int>(s.shapes.size()); ++j) sw.pairs.emplace_back(i, j);
    // A set, not a search of the pairs before each: "all" of 1,000 shapes is
    // 500,500 pairs.
    std::set<std::pair<int, int>> seen;
    for (const auto& ij : sw.pairs)
      if (!seen.insert(ij).second)
        r.fail("pairs", "pair [" + s.shapes[ij.first].name + ", " + s.shapes[ij.second].name +
                            "] is given twice (it would run twice and show once)");
    // The generators draw radius^3 uniformly in [rmin^3, rmax^3]: a pair so
    // large (or so small) that those cubes are not normal doubles would give
    // non-finite poses (or a collapsed shell), and every solve would fail.
    for (const auto& [i1, i2] : sw.pairs) {
      const RadialRange rr = radial_range(*s.shapes[i1].shape, *s.shapes[i2].shape);
      const double lo3 = rr.rmin * rr.rmin * rr.rmin, hi3 = rr.rmax * rr.rmax * rr.rmax;
      if (!std::isfinite(hi3) || !(lo3 >= std::numeric_limits<double>::min()))
        r.fail("pairs", "pair [" + s.shapes[i1].name + ", " + s.shapes[i2].name + "]: the pose generators draw distances in [" +
                            fmt17(rr.rmin) + ", " + fmt17(rr.rmax) + "] (0.1 x the smaller inner radius, 2 x the larger outer radius) by their cubes, "
                            "which must be normal doubles: radii between about 1e-102 and 1e102 are representable");
    }
    sw.passes = read_passes(r);
    for (const std::string& w : r.strings("record", true)) {
      const auto item = std::find_if(kRecordItems.begin(), kRecordItems.end(), [&](const auto& i) { return w == i.first; });
      if (item == kRecordItems.end())
        r.fail("record", "unknown item \"" + w +
                             "\" (expected timing, iterations, residuals, failures, per_pose, derivatives, checks or baselines)");
      if (w == "baselines" && !baselines_available())
        r.fail("record", "\"baselines\" is not available in this build (configured with "
                         "-DIDCOL_BUILD_BASELINES=OFF); remove it from run.record");
      sw.record.*item->second = true;
    }
    const std::string path = r.string("timed_path", false, "loop");
    if (path != "loop" && path != "batch")
      r.fail("timed_path", "expected \"loop\" (each solve timed on its own) or \"batch\" (blocks of poses timed through "
                           "solve_batch on one thread), got \"" + path + "\"");
    sw.timed_batch = path == "batch";
    if (sw.timed_batch && !sw.record.timing)
      r.fail("timed_path", "\"batch\" chooses how the passes are timed: it needs \"timing\" in run.record");
    r.finish();
  }

  // A list of pairs: "run" (the run's pairs) or an array of [name, name].
  auto pair_list = [&](Reader& r, const std::string& key) {
    std::vector<std::pair<int, int>> out;
    if (read_pair_list(s, r, key, "run", false, "expected an array of [name, name] arrays", out)) return sw.pairs;
    const std::set<std::pair<int, int>> run_pairs(sw.pairs.begin(), sw.pairs.end());
    for (const auto& ij : out)
      if (!run_pairs.count(ij))
        r.fail(key, "pair [" + s.shapes[ij.first].name + ", " + s.shapes[ij.second].name + "] is not one of run.pairs");
    return out;
  };

  // [baselines]: required iff run.record has "baselines".
  if (const toml::table* bt = top.table("baselines", false)) {
    if (!sw.record.baselines) throw SceneError(file, "baselines", "given, but run.record does not ask for \"baselines\"");
    Reader r(*bt, file, "baselines");
    sw.baselines.methods = r.strings("methods", true);
    if (sw.baselines.methods.empty()) r.fail("methods", "expected at least one method");
    sw.baselines.pairs = pair_list(r, "pairs");
    sw.baselines.timing_poses = r.count("timing_poses", false, sw.baselines.timing_poses, true);
    sw.baselines.band_tolerance = r.number("band_tolerance", false, sw.baselines.band_tolerance);
    if (!(sw.baselines.band_tolerance >= 0.0 && sw.baselines.band_tolerance < 1.0))
      r.fail("band_tolerance", "expected a number in [0, 1), got " + fmt17(sw.baselines.band_tolerance));
    sw.baselines.near_contact = r.number("near_contact", false, sw.baselines.near_contact);
    if (!(sw.baselines.near_contact > 0.0 && sw.baselines.near_contact < 1.0))
      r.fail("near_contact", "expected a number in (0, 1), got " + fmt17(sw.baselines.near_contact));
    r.finish();
    for (const std::string& m : sw.baselines.methods)
      for (const auto& [i1, i2] : sw.baselines.pairs) {
        std::string why;
        if (!baseline_serves(m, *s.shapes[i1].shape, *s.shapes[i2].shape, &why))
          r.fail("methods", "\"" + m + "\" cannot serve the pair [" + s.shapes[i1].name + ", " + s.shapes[i2].name +
                                "]: " + why);
      }
  } else if (sw.record.baselines) {
    throw SceneError(file, "baselines", "missing; run.record asks for \"baselines\", so a [baselines] table must name "
                                        "the methods (" + known_methods() + ")");
  }

  // [reference] (optional): published figures to print beside the run's.
  if (const toml::table* rt = top.table("reference", false)) {
    if (!sw.record.baselines || !sw.record.timing)
      throw SceneError(file, "reference", "given, but it is printed beside the agreement pass's times: run.record must ask "
                                          "for \"baselines\" and \"timing\"");
    Reader r(*rt, file, "reference");
    sw.reference.source = r.string("source", true);
    if (sw.reference.source.empty()) r.fail("source", "expected where the figures come from, got an empty string");
    const toml::table* mt = r.typed<toml::table>("mean_us", true, "a table { method = { \"A-B\" = us, ... }, ... }");
    std::set<std::string> pairs;
    for (const auto& [i1, i2] : sw.baselines.pairs) pairs.insert(s.shapes[i1].name + "-" + s.shapes[i2].name);
    for (const auto& [mk, node] : *mt) {
      const std::string m(mk.str()), field = "mean_us." + m;
      if (m != "idcol_cold" && m != "idcol_warm" && !sw.baselines.has(m))
        throw SceneError(file, "reference." + field, "\"" + m + "\" is not a timed method of this scene (idcol_cold, idcol_warm "
                                                    "or one of [baselines] methods)");
      const toml::table* byp = node.as_table();
      if (!byp) throw SceneError(file, "reference." + field, "expected a table { \"A-B\" = us, ... }, got " + type_name(node));
      for (const auto& [pk, v] : *byp) {
        const std::string pair(pk.str()), at = "reference." + field + "." + pair;
        if (!pairs.count(pair)) throw SceneError(file, at, "\"" + pair + "\" is not one of [baselines] pairs, written \"Body1-Body2\"");
        const double us = v.is_floating_point() ? v.as_floating_point()->get()
                          : v.is_integer()      ? static_cast<double>(v.as_integer()->get())
                                                : NAN;
        if (!(us > 0.0) || !std::isfinite(us)) throw SceneError(file, at, "expected a time in us, finite and > 0");
        sw.reference.mean_us[m][pair] = us;
      }
    }
    r.finish();
  }

  // [derivatives] (optional; defaults apply) when run.record has "derivatives".
  if (const toml::table* dt = top.table("derivatives", false)) {
    if (!sw.record.derivatives)
      throw SceneError(file, "derivatives", "given, but run.record does not ask for \"derivatives\"");
    Reader r(*dt, file, "derivatives");
    sw.derivatives.every = r.count("every", false, sw.derivatives.every, false);
    sw.derivatives.pairs = pair_list(r, "pairs");
    sw.derivatives.h = r.number("h", false, sw.derivatives.h);
    sw.derivatives.tolerance = r.number("tolerance", false, sw.derivatives.tolerance);
    if (!(sw.derivatives.h > 0.0)) r.fail("h", "expected a number > 0, got " + fmt17(sw.derivatives.h));
    if (!(sw.derivatives.tolerance > 0.0)) r.fail("tolerance", "expected a number > 0, got " + fmt17(sw.derivatives.tolerance));
    r.finish();
  } else if (sw.record.derivatives) {
    sw.derivatives.pairs = sw.pairs;
  }
}

}  // namespace

void read_sweep_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file);
  read_shapes(top, file, s, true);
  read_sweep_table(top, file, s, true);
  read_run(top, file, s, s.spec.emplace<SweepSpec>());
}

bool BaselineSpec::has(const std::string& m) const { return std::find(methods.begin(), methods.end(), m) != methods.end(); }
bool BaselineSpec::covers(int i1, int i2) const { return std::find(pairs.begin(), pairs.end(), std::pair{i1, i2}) != pairs.end(); }
bool DerivativeSpec::covers(int i1, int i2) const { return std::find(pairs.begin(), pairs.end(), std::pair{i1, i2}) != pairs.end(); }

std::vector<std::string> record_names(const RecordSpec& r) {
  std::vector<std::string> v;
  for (const auto& [name, on] : kRecordItems)
    if (r.*on) v.emplace_back(name);
  return v;
}

std::string scene_to_toml(const Scene& s) {
  const SweepSpec& sw = s.spec.as<SweepSpec>();
  std::ostringstream o;
  // A TOML array of the items given, as written; of quoted strings; of shape pairs.
  auto array = [](const std::vector<std::string>& items) {
    std::string t = "[";
    for (std::size_t i = 0; i < items.size(); ++i) t += (i ? ", " : "") + items[i];
    return t + "]";
  };
  auto quoted = [&](std::vector<std::string> v) {
    for (std::string& x : v) x = quote(x);
    return array(v);
  };
  auto pair_text = [&](const std::vector<std::pair<int, int>>& ps) {
    std::vector<std::string> t;
    for (const auto& [i, j] : ps) t.push_back(quoted({s.shapes[i].name, s.shapes[j].name}));
    return array(t);
  };
  o << "name = " << quote(s.name) << "\n";
  if (!s.description.empty()) o << "description = " << quote(s.description) << "\n";
  o << "\n[shapes]\n";
  for (const ShapeSpec& sh : s.shapes) {
    o << sh.name << " = { family = " << quote(sh.family);
    auto vecs = [&](const char* key, const std::vector<Vec3>& v) {
      std::vector<std::string> t;
      for (const Vec3& x : v) t.push_back(array({fmt17(x.x()), fmt17(x.y()), fmt17(x.z())}));
      o << ", " << key << " = " << array(t);
    };
    if (!sh.vertices.empty()) vecs("vertices", sh.vertices);
    if (!sh.normals.empty()) {
      vecs("normals", sh.normals);
      std::vector<std::string> t;
      for (double b : sh.offsets) t.push_back(fmt17(b));
      o << ", offsets = " << array(t);
    }
    for (const auto& [k, v] : sh.scalars) o << ", " << k << " = " << fmt17(v);
    o << " }\n";
  }
  o << "\n[sweep]\ngenerator = " << quote(to_string(s.generator)) << "\nposes = " << s.poses << "\ndt = " << fmt17(s.dt)
    << "\nwarm_chain = " << s.warm_chain << "\nwarmup = " << s.warmup << "\n";
  std::vector<std::string> passes;
  for (const Pass p : sw.passes) passes.emplace_back(to_string(p));
  o << "\n[run]\npairs = " << (sw.all_pairs ? "\"all\"" : pair_text(sw.pairs)) << "\npasses = " << quoted(passes)
    << "\nrecord = " << quoted(record_names(sw.record)) << "\n";
  if (sw.timed_batch) o << "timed_path = \"batch\"\n";
  if (sw.record.baselines) {
    o << "\n[baselines]\nmethods = " << quoted(sw.baselines.methods) << "\npairs = " << pair_text(sw.baselines.pairs)
      << "\ntiming_poses = " << sw.baselines.timing_poses << "\nband_tolerance = " << fmt17(sw.baselines.band_tolerance)
      << "\nnear_contact = " << fmt17(sw.baselines.near_contact) << "\n";
  }
  if (!sw.reference.empty()) {
    o << "\n[reference]\nsource = " << quote(sw.reference.source) << "\n[reference.mean_us]\n";
    for (const auto& [m, byp] : sw.reference.mean_us) {
      o << m << " = {";
      bool first = true;
      for (const auto& [pair, us] : byp) o << (first ? " " : ", ") << quote(pair) << " = " << fmt17(us), first = false;
      o << " }\n";
    }
  }
  if (sw.record.derivatives)
    o << "\n[derivatives]\nevery = " << sw.derivatives.every << "\npairs = " << pair_text(sw.derivatives.pairs)
      << "\nh = " << fmt17(sw.derivatives.h) << "\ntolerance = " << fmt17(sw.derivatives.tolerance) << "\n";
  o << "\n" << solver_toml(s.solver);
  return o.str();
}


}  // namespace idcol::harness

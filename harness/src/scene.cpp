#include "idcol_harness/scene.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include "idcol_harness/agreement.hpp"
#include "idcol_harness/scene_toml.hpp"

namespace idcol::harness {

std::vector<std::string> keys_in_file_order(const toml::table& t) {
  std::vector<std::pair<std::pair<int, int>, std::string>> ks;
  for (const auto& [k, v] : t)
    ks.push_back({{static_cast<int>(v.source().begin.line), static_cast<int>(v.source().begin.column)}, std::string(k.str())});
  std::sort(ks.begin(), ks.end());
  std::vector<std::string> out;
  for (auto& k : ks) out.push_back(k.second);
  return out;
}

const std::vector<FamilyDoc>& shape_families() {
  static const std::vector<FamilyDoc> docs = {
      {"sphere", "a ball", {{"R", "radius, > 0"}}, "{ family = \"sphere\", R = 1.0 }"},
      {"superellipsoid",
       "|x/a|^2n + |y/b|^2n + |z/c|^2n <= 1 in the paper's form; n = 1 is an exact ellipsoid",
       {{"a", "semi-axis along x, > 0"}, {"b", "semi-axis along y, > 0"}, {"c", "semi-axis along z, > 0"}, {"n", "exponent, 1 <= n <= 64"}},
       "{ family = \"superellipsoid\", a = 0.5, b = 1.0, c = 1.5, n = 8 }"},
      {"superelliptic_cylinder",
       "a cylinder along z whose section is a superellipse of exponent n",
       {{"R", "radius of the section, > 0"}, {"h", "half-height, > 0"}, {"n", "exponent, 1 <= n <= 64"}},
       "{ family = \"superelliptic_cylinder\", R = 1.0, h = 2.0, n = 8 }"},
      {"smooth_polytope",
       "LogSumExp of the half-spaces a_i.x <= b_i; give normals and offsets, or vertices (their convex hull)",
       {{"normals", "[[ax, ay, az], ...] (normalised), or"},
        {"offsets", "[b_0, ...], one per normal (> 0: the origin inside)"},
        {"vertices", "[[x, y, z], ...], instead of normals and offsets"},
        {"beta", "sharpness, > 0 (up to 1e4 h/L)"},
        {"L", "length scale of the smoothing, > 0 (default 1)"}},
       "{ family = \"smooth_polytope\", vertices = [[1,1,1],[1,1,-1],[1,-1,1],[1,-1,-1],[-1,1,1],[-1,1,-1],[-1,-1,1],[-1,-1,-1]], beta = 20 }"},
      {"smooth_truncated_cone",
       "a truncated cone along z with smoothed rim, LogSumExp of its side and caps",
       {{"Rb", "base radius, > 0"}, {"Rt", "top radius, > 0"}, {"a", "height below the origin, > 0"},
        {"b", "height above the origin, > 0"}, {"beta", "sharpness, > 0"}},
       "{ family = \"smooth_truncated_cone\", Rb = 1.0, Rt = 1.5, a = 1.5, b = 1.5, beta = 20 }"},
  };
  return docs;
}

namespace {
const FamilyDoc* family_doc(const std::string& family) {
  for (const FamilyDoc& d : shape_families())
    if (family == d.family) return &d;
  return nullptr;
}
}  // namespace

ShapeSpec read_shape(const toml::table& t, const std::string& file, const std::string& field, const std::string& name) {
  Reader r(t, file, field);
  ShapeSpec s;
  s.name = name;
  s.family = r.string("family");
  const FamilyDoc* doc = family_doc(s.family);
  if (!doc) {
    std::string known;
    for (const FamilyDoc& d : shape_families()) known += (known.empty() ? "" : ", ") + std::string(d.family);
    r.fail("family", "unknown family \"" + s.family + "\" (expected one of " + known + ")");
  }
  // The scalar parameters, in the family's order (the polytope's arrays apart).
  for (const FamilyParam& p : doc->params) {
    const std::string k = p.key;
    if (k == "normals" || k == "offsets" || k == "vertices") continue;
    if (k == "L") s.scalars.emplace_back(k, r.number(k, false, 1.0));
    else s.scalars.emplace_back(k, r.number(k));
  }
  auto sc = [&](const char* k) {
    for (auto& [key, v] : s.scalars)
      if (key == k) return v;
    return 0.0;
  };
  try {
    if (s.family == "sphere") {
      r.finish();
      s.shape.emplace(Sphere(sc("R")));
    } else if (s.family == "superellipsoid") {
      r.finish();
      s.shape.emplace(Superellipsoid(sc("a"), sc("b"), sc("c"), sc("n")));
    } else if (s.family == "superelliptic_cylinder") {
      r.finish();
      s.shape.emplace(SuperellipticCylinder(sc("R"), sc("h"), sc("n")));
    } else if (s.family == "smooth_truncated_cone") {
      r.finish();
      s.shape.emplace(SmoothTruncatedCone(sc("Rb"), sc("Rt"), sc("a"), sc("b"), sc("beta")));
    } else {  // smooth_polytope
      const bool has_v = t.contains("vertices"), has_h = t.contains("normals") || t.contains("offsets");
      if (has_v == has_h)
        r.fail("family", "a smooth_polytope needs either normals and offsets, or vertices (exactly one form)");
      if (has_v) {
        s.vertices = r.vec3s("vertices");
        r.finish();
        s.shape.emplace(SmoothPolytope::from_vertices(s.vertices, sc("beta"), sc("L")));
      } else {
        s.normals = r.vec3s("normals");
        s.offsets = r.numbers("offsets");
        r.finish();
        if (s.normals.size() != s.offsets.size())
          r.fail("offsets", "expected as many offsets as normals (" + std::to_string(s.normals.size()) + "), got " +
                                std::to_string(s.offsets.size()));
        s.shape.emplace(SmoothPolytope(s.normals, s.offsets, sc("beta"), sc("L")));
      }
    }
  } catch (const std::invalid_argument& e) {
    throw SceneError(file, field, std::string("bad shape parameters: ") + e.what());
  }
  return s;
}

toml::table parse_toml(const std::string& text, const std::string& file) {
  prescan_toml(text, file);
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << "line " << e.source().begin.line << ", column " << e.source().begin.column;
    throw SceneError(file, os.str(), std::string("not valid TOML: ") + std::string(e.description()));
  }
}


const char* to_string(Pass p) { return p == Pass::Cold ? "cold" : "warm"; }

bool Scene::has_pass(Pass p) const { return std::find(passes.begin(), passes.end(), p) != passes.end(); }

ShapeSpec parse_shape_inline(const std::string& inline_table, const std::string& file, const std::string& field) {
  toml::table t = parse_toml("shape = " + inline_table, file);
  auto st = t["shape"].as_table();
  if (!st) throw SceneError(file, field, "expected an inline table { family = ..., ... }");
  return read_shape(*st, file, field, field);
}

Scene parse_scene(const std::string& text, const std::string& file) {
  const toml::table root = parse_toml(text, file);
  Scene s;
  s.path = file;
  s.text = text;
  Reader top(root, file, "");
  s.name = top.string("name");
  s.description = top.string("description", false);

  // [shapes]
  const toml::table* shapes = top.table("shapes", true);
  for (const std::string& key : keys_in_file_order(*shapes)) {
    const toml::node* n = shapes->get(key);
    auto t = n->as_table();
    if (!t) throw SceneError(file, "shapes." + key, "expected an inline table { family = ..., ... }, got " + type_name(*n));
    s.shapes.push_back(read_shape(*t, file, "shapes." + key, key));
  }
  if (s.shapes.empty()) throw SceneError(file, "shapes", "expected at least one shape");

  // [sweep]
  {
    Reader r(*top.table("sweep", true), file, "sweep");
    const std::string g = r.string("generator");
    try {
      s.generator = generator_from_string(g);
    } catch (const std::invalid_argument& e) {
      r.fail("generator", e.what());
    }
    s.poses = r.count("poses", true, 0, false);
    s.dt = r.number("dt", false, 1e-4);
    if (!(s.dt > 0.0) || !std::isfinite(s.dt)) r.fail("dt", "expected a finite number > 0, got " + fmt17(s.dt));
    s.warm_chain = r.count("warm_chain", false, s.warm_chain, false);
    s.warmup = r.count("warmup", false, s.warmup, true);
    r.finish();
  }

  // [run]
  {
    Reader r(*top.table("run", true), file, "run");
    const toml::node* pn = r.get("pairs", true, "\"all\" or an array of [name, name] arrays");
    auto index_of = [&](const std::string& name) {
      for (std::size_t i = 0; i < s.shapes.size(); ++i)
        if (s.shapes[i].name == name) return static_cast<int>(i);
      r.fail("pairs", "unknown shape \"" + name + "\" (not in [shapes])");
    };
    if (auto str = pn->as_string()) {
      if (str->get() != "all") r.fail("pairs", "expected \"all\" or an array of [name, name] arrays, got \"" + str->get() + "\"");
      s.all_pairs = true;
      for (int i = 0; i < static_cast<int>(s.shapes.size()); ++i)
        for (int j = i; j < static_cast<int>(s.shapes.size()); ++j) s.pairs.emplace_back(i, j);
    } else if (auto arr = pn->as_array()) {
      for (const auto& e : *arr) {
        auto p = e.as_array();
        if (!p || p->size() != 2 || !p->get(0)->is_string() || !p->get(1)->is_string())
          r.fail("pairs", "expected \"all\" or an array of [name, name] arrays");
        s.pairs.emplace_back(index_of(p->get(0)->as_string()->get()), index_of(p->get(1)->as_string()->get()));
      }
      if (s.pairs.empty()) r.fail("pairs", "expected at least one pair");
      for (std::size_t i = 0; i < s.pairs.size(); ++i)
        if (std::find(s.pairs.begin(), s.pairs.begin() + i, s.pairs[i]) != s.pairs.begin() + i)
          r.fail("pairs", "pair [" + s.shapes[s.pairs[i].first].name + ", " + s.shapes[s.pairs[i].second].name +
                              "] is given twice (it would run twice and show once)");
    } else {
      r.fail("pairs", "expected \"all\" or an array of [name, name] arrays, got " + type_name(*pn));
    }
    // The generators draw radius^3 uniformly in [rmin^3, rmax^3]: a pair so
    // large (or so small) that those cubes are not normal doubles would give
    // non-finite poses (or a collapsed shell), and every solve would fail.
    for (const auto& [i1, i2] : s.pairs) {
      const RadialRange rr = radial_range(*s.shapes[i1].shape, *s.shapes[i2].shape);
      const double lo3 = rr.rmin * rr.rmin * rr.rmin, hi3 = rr.rmax * rr.rmax * rr.rmax;
      if (!std::isfinite(hi3) || !(lo3 >= std::numeric_limits<double>::min()))
        r.fail("pairs", "pair [" + s.shapes[i1].name + ", " + s.shapes[i2].name + "]: the pose generators draw distances in [" +
                            fmt17(rr.rmin) + ", " + fmt17(rr.rmax) + "] (0.1 x the smaller inner radius, 2 x the larger outer radius) by their cubes, "
                            "which must be normal doubles: radii between about 1e-102 and 1e102 are representable");
    }
    for (const std::string& p : r.strings("passes", true)) {
      Pass pass;
      if (p == "cold") pass = Pass::Cold;
      else if (p == "warm") pass = Pass::Warm;
      else r.fail("passes", "unknown pass \"" + p + "\" (expected \"cold\" or \"warm\")");
      if (s.has_pass(pass)) r.fail("passes", "pass \"" + p + "\" given twice");
      s.passes.push_back(pass);
    }
    if (s.passes.empty()) r.fail("passes", "expected at least one of \"cold\", \"warm\"");
    for (const std::string& w : r.strings("record", true)) {
      if (w == "timing") s.record.timing = true;
      else if (w == "iterations") s.record.iterations = true;
      else if (w == "residuals") s.record.residuals = true;
      else if (w == "failures") s.record.failures = true;
      else if (w == "per_pose") s.record.per_pose = true;
      else if (w == "derivatives") s.record.derivatives = true;
      else if (w == "checks") s.record.checks = true;
      else if (w == "baselines") {
        if (!baselines_available())
          r.fail("record", "\"baselines\" is not available in this build (configured with "
                           "-DIDCOL_BUILD_BASELINES=OFF); remove it from run.record");
        s.record.baselines = true;
      }
      else
        r.fail("record", "unknown item \"" + w +
                             "\" (expected timing, iterations, residuals, failures, per_pose, derivatives, checks or baselines)");
    }
    r.finish();
  }

  // A list of pairs: "run" (the run's pairs) or an array of [name, name].
  auto pair_list = [&](Reader& r, const std::string& key) {
    std::vector<std::pair<int, int>> out;
    const toml::node* pn = r.get(key, false, "\"run\" or an array of [name, name] arrays");
    if (!pn) return s.pairs;
    if (auto str = pn->as_string()) {
      if (str->get() != "run") r.fail(key, "expected \"run\" or an array of [name, name] arrays, got \"" + str->get() + "\"");
      return s.pairs;
    }
    auto arr = pn->as_array();
    if (!arr) r.fail(key, "expected \"run\" or an array of [name, name] arrays, got " + type_name(*pn));
    for (const auto& e : *arr) {
      auto p = e.as_array();
      if (!p || p->size() != 2 || !p->get(0)->is_string() || !p->get(1)->is_string())
        r.fail(key, "expected an array of [name, name] arrays");
      std::pair<int, int> ij{-1, -1};
      for (int side = 0; side < 2; ++side) {
        const std::string name = p->get(side)->as_string()->get();
        int idx = -1;
        for (std::size_t i = 0; i < s.shapes.size(); ++i)
          if (s.shapes[i].name == name) idx = static_cast<int>(i);
        if (idx < 0) r.fail(key, "unknown shape \"" + name + "\" (not in [shapes])");
        (side ? ij.second : ij.first) = idx;
      }
      if (std::find(s.pairs.begin(), s.pairs.end(), ij) == s.pairs.end())
        r.fail(key, "pair [" + s.shapes[ij.first].name + ", " + s.shapes[ij.second].name + "] is not one of run.pairs");
      out.push_back(ij);
    }
    if (out.empty()) r.fail(key, "expected at least one pair");
    return out;
  };

  // [baselines]: required iff run.record has "baselines".
  if (const toml::table* bt = top.table("baselines", false)) {
    if (!s.record.baselines) throw SceneError(file, "baselines", "given, but run.record does not ask for \"baselines\"");
    Reader r(*bt, file, "baselines");
    s.baselines.methods = r.strings("methods", true);
    if (s.baselines.methods.empty()) r.fail("methods", "expected at least one method");
    s.baselines.pairs = pair_list(r, "pairs");
    s.baselines.timing_poses = r.count("timing_poses", false, s.baselines.timing_poses, true);
    s.baselines.band_tolerance = r.number("band_tolerance", false, s.baselines.band_tolerance);
    if (!(s.baselines.band_tolerance >= 0.0 && s.baselines.band_tolerance < 1.0))
      r.fail("band_tolerance", "expected a number in [0, 1), got " + fmt17(s.baselines.band_tolerance));
    s.baselines.near_contact = r.number("near_contact", false, s.baselines.near_contact);
    if (!(s.baselines.near_contact > 0.0 && s.baselines.near_contact < 1.0))
      r.fail("near_contact", "expected a number in (0, 1), got " + fmt17(s.baselines.near_contact));
    r.finish();
    for (const std::string& m : s.baselines.methods)
      for (const auto& [i1, i2] : s.baselines.pairs) {
        std::string why;
        if (!baseline_serves(m, *s.shapes[i1].shape, *s.shapes[i2].shape, &why))
          r.fail("methods", "\"" + m + "\" cannot serve the pair [" + s.shapes[i1].name + ", " + s.shapes[i2].name +
                                "]: " + why);
      }
  } else if (s.record.baselines) {
    throw SceneError(file, "baselines", "missing; run.record asks for \"baselines\", so a [baselines] table must name "
                                        "the methods (" + known_methods() + ")");
  }

  // [derivatives] (optional; defaults apply) when run.record has "derivatives".
  if (const toml::table* dt = top.table("derivatives", false)) {
    if (!s.record.derivatives)
      throw SceneError(file, "derivatives", "given, but run.record does not ask for \"derivatives\"");
    Reader r(*dt, file, "derivatives");
    s.derivatives.every = r.count("every", false, s.derivatives.every, false);
    s.derivatives.pairs = pair_list(r, "pairs");
    s.derivatives.h = r.number("h", false, s.derivatives.h);
    s.derivatives.tolerance = r.number("tolerance", false, s.derivatives.tolerance);
    if (!(s.derivatives.h > 0.0)) r.fail("h", "expected a number > 0, got " + fmt17(s.derivatives.h));
    if (!(s.derivatives.tolerance > 0.0)) r.fail("tolerance", "expected a number > 0, got " + fmt17(s.derivatives.tolerance));
    r.finish();
  } else if (s.record.derivatives) {
    s.derivatives.pairs = s.pairs;
  }

  // [solver] (optional): overrides of SolverOptions.
  read_solver_table(top, file, s.solver);
  top.finish();
  return s;
}

std::string read_scene_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw SceneError(path, "(file)", "is a directory; expected a scene file (.toml)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, "(file)", std::string("cannot be read: ") + std::strerror(errno));
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

Scene load_scene(const std::string& path) { return parse_scene(read_scene_file(path), path); }

std::vector<std::string> record_names(const RecordSpec& r) {
  std::vector<std::string> v;
  for (const auto& [on, name] : {std::pair{r.timing, "timing"}, {r.iterations, "iterations"}, {r.residuals, "residuals"},
                                 {r.failures, "failures"}, {r.per_pose, "per_pose"}, {r.derivatives, "derivatives"},
                                 {r.checks, "checks"}, {r.baselines, "baselines"}})
    if (on) v.emplace_back(name);
  return v;
}

std::string scene_to_toml(const Scene& s) {
  std::ostringstream o;
  o << "name = " << quote(s.name) << "\n";
  if (!s.description.empty()) o << "description = " << quote(s.description) << "\n";
  o << "\n[shapes]\n";
  for (const ShapeSpec& sh : s.shapes) {
    o << sh.name << " = { family = " << quote(sh.family);
    auto vecs = [&](const char* key, const std::vector<Vec3>& v) {
      o << ", " << key << " = [";
      for (std::size_t i = 0; i < v.size(); ++i)
        o << (i ? ", " : "") << "[" << fmt17(v[i].x()) << ", " << fmt17(v[i].y()) << ", " << fmt17(v[i].z()) << "]";
      o << "]";
    };
    if (!sh.vertices.empty()) vecs("vertices", sh.vertices);
    if (!sh.normals.empty()) {
      vecs("normals", sh.normals);
      o << ", offsets = [";
      for (std::size_t i = 0; i < sh.offsets.size(); ++i) o << (i ? ", " : "") << fmt17(sh.offsets[i]);
      o << "]";
    }
    for (const auto& [k, v] : sh.scalars) o << ", " << k << " = " << fmt17(v);
    o << " }\n";
  }
  o << "\n[sweep]\ngenerator = " << quote(to_string(s.generator)) << "\nposes = " << s.poses << "\ndt = " << fmt17(s.dt)
    << "\nwarm_chain = " << s.warm_chain << "\nwarmup = " << s.warmup << "\n";
  o << "\n[run]\npairs = ";
  if (s.all_pairs) {
    o << "\"all\"";
  } else {
    o << "[";
    for (std::size_t i = 0; i < s.pairs.size(); ++i)
      o << (i ? ", " : "") << "[" << quote(s.shapes[s.pairs[i].first].name) << ", " << quote(s.shapes[s.pairs[i].second].name) << "]";
    o << "]";
  }
  o << "\npasses = [";
  for (std::size_t i = 0; i < s.passes.size(); ++i) o << (i ? ", " : "") << quote(to_string(s.passes[i]));
  o << "]\nrecord = [";
  const std::vector<std::string> rec = record_names(s.record);
  for (std::size_t i = 0; i < rec.size(); ++i) o << (i ? ", " : "") << quote(rec[i]);
  o << "]\n";
  auto pair_text = [&](const std::vector<std::pair<int, int>>& ps) {
    std::string t = "[";
    for (std::size_t i = 0; i < ps.size(); ++i)
      t += (i ? ", [" : "[") + quote(s.shapes[ps[i].first].name) + ", " + quote(s.shapes[ps[i].second].name) + "]";
    return t + "]";
  };
  if (s.record.baselines) {
    o << "\n[baselines]\nmethods = [";
    for (std::size_t i = 0; i < s.baselines.methods.size(); ++i) o << (i ? ", " : "") << quote(s.baselines.methods[i]);
    o << "]\npairs = " << pair_text(s.baselines.pairs) << "\ntiming_poses = " << s.baselines.timing_poses
      << "\nband_tolerance = " << fmt17(s.baselines.band_tolerance) << "\nnear_contact = " << fmt17(s.baselines.near_contact)
      << "\n";
  }
  if (s.record.derivatives)
    o << "\n[derivatives]\nevery = " << s.derivatives.every << "\npairs = " << pair_text(s.derivatives.pairs)
      << "\nh = " << fmt17(s.derivatives.h) << "\ntolerance = " << fmt17(s.derivatives.tolerance) << "\n";
  o << "\n" << solver_toml(s.solver);
  return o.str();
}

}  // namespace idcol::harness

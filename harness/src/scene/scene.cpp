#include "scene/scene.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include <toml++/toml.h>

#include "idcol/shape_params.hpp"
#include "scene/scene_toml.hpp"

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

namespace {
/// A parameter of a generated shape (the harness's own, not core's).
idcol::FamilyParam generated_param(const char* key, const char* meaning) {
  return {key, meaning, 0.0, true, std::numeric_limits<double>::quiet_NaN(), 0, 0.0, false};
}

/// Core's family as the catalogue shows it: its table's entry, its example
/// inline table and the example's shape.
FamilyDoc core_family(const idcol::FamilyInfo& f) {
  FamilyDoc d;
  d.family = f.name;
  d.summary = f.summary;
  if (*f.smooth_form_of) d.summary += "; the smooth form of " + std::string(f.smooth_form_of);
  d.axes = f.axes;
  d.params = f.params;
  std::ostringstream ex;
  ex << "{ family = \"" << f.name << "\"";
  VecX theta(static_cast<Eigen::Index>(f.scalars().size()));
  Eigen::Index i = 0;
  for (const idcol::FamilyParam* p : f.scalars()) {
    ex << ", " << p->key << " = " << p->example;
    theta[i++] = p->example;
  }
  ex << " }";
  d.example = ex.str();
  if (std::string(f.name) == SmoothPolytope::kName)
    d.example =
        "{ family = \"smooth_polytope\", vertices = [[1,1,1],[1,1,-1],[1,-1,1],[1,-1,-1],[-1,1,1],[-1,1,-1],[-1,-1,1],[-1,-1,-1]], "
        "beta = 20 }";
  else
    d.prototype.emplace(idcol::scalar_family_shape(f, theta.data()));
  return d;
}
}  // namespace

const std::vector<FamilyDoc>& scene_families() {
  static const std::vector<FamilyDoc> docs = [] {
    std::vector<FamilyDoc> d;
    for (const idcol::FamilyInfo& f : idcol::shape_families()) d.push_back(core_family(f));
    // The generated polytopes: the harness's own shapes, built as smooth_polytope.
    const idcol::FamilyParam beta = generated_param("beta", "sharpness, > 0"),
                             L = generated_param("L", "length scale of the smoothing, > 0 (default 1)");
    d.push_back({"box", "generated: a smooth_polytope of the box's 6 faces", "faces normal to y1, y2, y3 (the frame's x, y, z)",
                 {generated_param("half", "[hx, hy, hz], the half-extents, > 0"),
                  generated_param("origin", "[ox, oy, oz], the frame origin in the box (default the centre; |o_i| < h_i)"), beta, L},
                 "{ family = \"box\", half = [1.0, 0.5, 0.25], beta = 20 }", std::nullopt, true});
    d.push_back({"facet_sphere", "generated: a smooth_polytope of `facets` planes tangent to a sphere (Fibonacci directions)",
                 "centred at the frame origin",
                 {generated_param("facets", "number of planes, 4 <= facets <= 20000"),
                  generated_param("radius", "radius of the tangent sphere, > 0"), beta, L},
                 "{ family = \"facet_sphere\", facets = 200, radius = 1.0, beta = 20 }", std::nullopt, true});
    d.push_back({"vertex_sphere", "generated: a smooth_polytope, the convex hull of `vertices` points on a sphere (Fibonacci directions)",
                 "centred at the frame origin",
                 {generated_param("vertices", "number of points, 4 <= vertices <= 5000"), generated_param("radius", "radius of the sphere, > 0"),
                  beta, L},
                 "{ family = \"vertex_sphere\", vertices = 200, radius = 1.0, beta = 20 }", std::nullopt, true});
    return d;
  }();
  return docs;
}

namespace {
const FamilyDoc* family_doc(const std::string& family) {
  for (const FamilyDoc& d : scene_families())
    if (family == d.family) return &d;
  return nullptr;
}

// The names of the choices every kind's scene may make, each listed once for
// reading and writing (a kind's own choices are listed beside its reader).
const Names<Pass> kPasses = {{"cold", Pass::Cold}, {"warm", Pass::Warm}};
const Names<OracleChoice> kOracles = {{"auto", OracleChoice::Auto},          {"none", OracleChoice::None},
                                      {"closed_form", OracleChoice::ClosedForm}, {"pw", OracleChoice::PerramWertheim},
                                      {"lp", OracleChoice::PolytopeLP},          {"support", OracleChoice::SupportFunction}};
/// The generated polytope families (stress.hpp), as smooth_polytope specs,
/// and their sizes: a vertex costs as much as kMaxFacets / kMaxVertices
/// half-spaces (its hull and the dual's), the budget of read_shapes.
constexpr int kMaxFacets = 20000, kMaxVertices = 5000;
bool is_generated(const std::string& family) {
  const FamilyDoc* d = family_doc(family);
  return d && d->generated;
}
ShapeSpec read_generated_shape(Reader& r, const toml::table& t, const std::string& file, const std::string& field,
                               const std::string& name, const std::string& family) {
  ShapeSpec s;
  s.name = name;
  s.family = "smooth_polytope";
  const double beta = r.number("beta");
  const double L = r.number("L", false, 1.0);
  auto positive_int = [&](const char* key, std::uint64_t most) {
    const auto n = r.count(key, true, 0, false);
    if (n < 4 || n > most) r.fail(key, "expected an integer in [4, " + std::to_string(most) + "], got " + std::to_string(n));
    return static_cast<int>(n);
  };
  try {
    if (family == "box") {
      const std::vector<double> h = r.numbers("half");
      std::vector<double> o{0.0, 0.0, 0.0};
      if (t.contains("origin")) o = r.numbers("origin");
      if (h.size() != 3) r.fail("half", "expected [hx, hy, hz]");
      if (o.size() != 3) r.fail("origin", "expected [ox, oy, oz]");
      for (int i = 0; i < 3; ++i) {
        if (!(h[i] > 0.0) || !std::isfinite(h[i])) r.fail("half", "expected three finite numbers > 0");
        if (!(std::abs(o[i]) < h[i])) r.fail("origin", "expected |origin_i| < half_i (the frame origin inside the box)");
        Vec3 e = Vec3::Zero();
        e[i] = 1.0;
        s.normals.push_back(e);
        s.offsets.push_back(h[i] - o[i]);
        s.normals.push_back(-e);
        s.offsets.push_back(h[i] + o[i]);
      }
      r.finish();
    } else if (family == "facet_sphere") {
      const int m = positive_int("facets", kMaxFacets);
      const double R = r.number("radius");
      r.finish();
      for (const Vec3& n : fibonacci_sphere(m)) {
        s.normals.push_back(n);
        s.offsets.push_back(R);
      }
    } else {  // vertex_sphere
      const int m = positive_int("vertices", kMaxVertices);
      const double R = r.number("radius");
      r.finish();
      for (const Vec3& n : fibonacci_sphere(m)) s.vertices.push_back(R * n);
    }
    s.scalars = {{"beta", beta}, {"L", L}};
    if (!s.vertices.empty()) {
      // Keep the vertex form's hull as half-spaces, so that the shape prints
      // (describe) exactly as it is solved and a replay rebuilds it bit for bit.
      const SmoothPolytope p = SmoothPolytope::from_vertices(s.vertices, beta, L);
      s.shape.emplace(p);
    } else {
      s.shape.emplace(SmoothPolytope(s.normals, s.offsets, beta, L));
    }
  } catch (const std::invalid_argument& e) {
    throw SceneError(file, field, std::string("bad shape parameters: ") + e.what());
  }
  return s;
}

}  // namespace

ShapeSpec read_shape(const toml::table& t, const std::string& file, const std::string& field, const std::string& name) {
  Reader r(t, file, field);
  ShapeSpec s;
  s.name = name;
  s.family = r.string("family");
  if (is_generated(s.family)) return read_generated_shape(r, t, file, field, name, s.family);
  const FamilyDoc* doc = family_doc(s.family);
  if (!doc) {
    std::string known, generated;
    for (const FamilyDoc& d : scene_families()) (d.generated ? generated : known) += d.family + ", ";
    generated.resize(generated.size() - 2);
    r.fail("family", "unknown family \"" + s.family + "\" (expected one of " + known + "or a generated polytope: " + generated + ")");
  }
  // The scalar parameters, in the family's order (the polytope's arrays apart).
  for (const idcol::FamilyParam& p : doc->params) {
    if (p.array) continue;
    const std::string k = p.key;
    if (std::isnan(p.fallback)) s.scalars.emplace_back(k, r.number(k));
    else s.scalars.emplace_back(k, r.number(k, false, p.fallback));
  }
  auto sc = [&](const char* k) {
    for (auto& [key, v] : s.scalars)
      if (key == k) return v;
    return 0.0;
  };
  try {
    if (doc->prototype) {
      r.finish();
      VecX theta(s.scalars.size());
      for (std::size_t i = 0; i < s.scalars.size(); ++i) theta[static_cast<Eigen::Index>(i)] = s.scalars[i].second;
      s.shape.emplace(shape_with_params(*doc->prototype, theta));
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

const char* to_string(Pass p) { return name_of(kPasses, p); }
const char* to_string(OracleChoice o) { return name_of(kOracles, o); }
OracleChoice oracle_named(const Reader& r, const std::string& key, const std::string& text) { return named(r, key, text, kOracles); }

ShapeSpec parse_shape_inline(const std::string& inline_table, const std::string& file, const std::string& field) {
  toml::table t = parse_toml("shape = " + inline_table, file);
  auto st = t["shape"].as_table();
  if (!st) throw SceneError(file, field, "expected an inline table { family = ..., ... }");
  return read_shape(*st, file, field, field);
}

void require_safe_name(const std::string& file, const std::string& field, const std::string& name, NameOf of) {
  const bool shape = of == NameOf::Shape;
  const std::size_t most = shape ? 64 : 128;
  std::string bad;
  for (char c : name) {
    const bool ok = shape ? ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
                             c == '.' || c == '+')
                          : (c >= 0x20 && c <= 0x7E && c != '|');
    if (!ok) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
      bad = hex;
      break;
    }
  }
  const std::string set = shape ? "1 to 64 of the characters A-Z a-z 0-9 _ - . +"
                                : "1 to 128 printable ASCII characters other than '|', without a leading or trailing space";
  const char* noun = shape ? "shape" : of == NameOf::Case ? "case" : "scene";
  if (name.empty() || name.size() > most || !bad.empty() || (!shape && (name.front() == ' ' || name.back() == ' ')))
    throw SceneError(file, field, std::string(noun) + " name \"" + escaped(name.substr(0, 100)) + (name.size() > 100 ? "...\"" : "\"") +
                                      " is not " + set + (bad.empty() ? std::string() : " (it holds the byte " + bad + ")") +
                                      ": names are printed as they are in tables, CSV rows, failure records and histories");
}

std::string read_scene_name(Reader& top, const std::string& file, const char* def) {
  const std::string name = top.string("name", def == nullptr, def ? def : "");
  require_safe_name(file, "name", name, NameOf::Scene);
  return name;
}

int shape_index(const Scene& s, const Reader& r, const std::string& key, const std::string& name) {
  for (std::size_t i = 0; i < s.shapes.size(); ++i)
    if (s.shapes[i].name == name) return static_cast<int>(i);
  r.fail(key, "unknown shape \"" + name + "\" (not in [shapes])");
}

bool read_pair_list(const Scene& s, Reader& r, const std::string& key, const std::string& word, bool required,
                    const std::string& bad_entry, std::vector<std::pair<int, int>>& out) {
  const std::string expected = "\"" + word + "\" or an array of [name, name] arrays";
  const toml::node* pn = r.get(key, required, expected);
  if (!pn) return true;
  if (auto str = pn->as_string()) {
    if (str->get() != word) r.fail(key, "expected " + expected + ", got \"" + str->get() + "\"");
    return true;
  }
  auto arr = pn->as_array();
  if (!arr) r.fail(key, "expected " + expected + ", got " + type_name(*pn));
  for (const auto& e : *arr) {
    auto p = e.as_array();
    if (!p || p->size() != 2 || !p->get(0)->is_string() || !p->get(1)->is_string()) r.fail(key, bad_entry);
    out.emplace_back(shape_index(s, r, key, p->get(0)->as_string()->get()), shape_index(s, r, key, p->get(1)->as_string()->get()));
  }
  if (out.empty()) r.fail(key, "expected at least one pair");
  return false;
}

std::vector<Pass> read_passes(Reader& r) {
  std::vector<Pass> out;
  for (const std::string& p : r.strings("passes", true)) {
    const Pass pass = named(r, "passes", p, kPasses, "pass");
    if (std::find(out.begin(), out.end(), pass) != out.end()) r.fail("passes", "pass \"" + p + "\" given twice");
    out.push_back(pass);
  }
  if (out.empty()) r.fail("passes", "expected at least one of \"cold\", \"warm\"");
  return out;
}

void read_shapes(Reader& top, const std::string& file, Scene& s, bool required) {
  static const toml::table kNoShapes;
  const toml::table* shapes = top.table("shapes", required);
  const std::vector<std::string> keys = keys_in_file_order(shapes ? *shapes : kNoShapes);
  constexpr std::int64_t kBudget = kMaxFacets, kVertexCost = kMaxFacets / kMaxVertices;
  std::int64_t cost = 0;
  for (const std::string& key : keys) {
    const toml::table* t = shapes->get(key)->as_table();
    if (!t) continue;  // reported below
    const auto* facets = t->get_as<std::int64_t>("facets");
    const auto* vertices = t->get_as<std::int64_t>("vertices");
    std::int64_t c = 0;
    if (facets) c = facets->get();
    if (vertices) c = kVertexCost * std::min<std::int64_t>(vertices->get(), kBudget);
    if (c < 0 || c > kBudget) continue;  // out of the shape's own range: read_shape says so
    cost += c;
    if (cost > kBudget)
      throw SceneError(file, "shapes." + key,
                       "the generated polytopes up to here have " + std::to_string(cost) + " half-spaces in all (a vertex counts as " +
                           std::to_string(kVertexCost) + "); a scene may have at most " + std::to_string(kBudget));
  }
  for (const std::string& key : keys) {
    require_safe_name(file, "shapes", key, NameOf::Shape);
    const toml::node* n = shapes->get(key);
    auto t = n->as_table();
    if (!t) throw SceneError(file, "shapes." + key, "expected an inline table { family = ..., ... }, got " + type_name(*n));
    s.shapes.push_back(read_shape(*t, file, "shapes." + key, key));
  }
  if (shapes && s.shapes.empty()) throw SceneError(file, "shapes", "expected at least one shape");
}

void read_sweep_table(Reader& top, const std::string& file, Scene& s, bool sweep) {
  const toml::table* t = top.table("sweep", sweep);
  if (!t) return;
  Reader r(*t, file, "sweep");
  if (sweep) {
    try {
      s.generator = generator_from_string(r.string("generator"));
    } catch (const std::invalid_argument& e) {
      r.fail("generator", e.what());
    }
  }
  s.poses = r.count("poses", sweep, s.poses, false);
  s.dt = r.number("dt", false, 1e-4);
  if (!(s.dt > 0.0) || !std::isfinite(s.dt)) r.fail("dt", "expected a finite number > 0, got " + fmt17(s.dt));
  if (sweep) s.warm_chain = r.count("warm_chain", false, s.warm_chain, false);
  s.warmup = r.count("warmup", false, s.warmup, true);
  r.finish();
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

}  // namespace idcol::harness

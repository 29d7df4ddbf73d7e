#include "scene/scene.hpp"

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

#include "idcol/shape_params.hpp"
#include "io/keys.hpp"
#include "referee/lp_oracle.hpp"
#include "referee/methods.hpp"
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

const std::vector<FamilyDoc>& shape_families() {
  // The axes as core defines the families (core/include/idcol/shapes.hpp):
  // y1, y2, y3 are the body frame's x, y, z.
  static const std::vector<FamilyDoc> docs = {
      {"sphere", "a ball", "centred at the frame origin", {{"R", "radius, > 0"}}, "{ family = \"sphere\", R = 1.0 }", Sphere(1.0)},
      {"superellipsoid",
       "|y1/a|^2n + |y2/b|^2n + |y3/c|^2n <= 1 in the paper's form; n = 1 is an exact ellipsoid",
       "semi-axes a, b, c along y1, y2, y3 (the frame's x, y, z)",
       {{"a", "semi-axis along y1 (x), > 0"}, {"b", "semi-axis along y2 (y), > 0"}, {"c", "semi-axis along y3 (z), > 0"}, {"n", "exponent, 1 <= n <= 64"}},
       "{ family = \"superellipsoid\", a = 0.5, b = 1.0, c = 1.5, n = 8 }", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
      {"superelliptic_cylinder",
       "a cylinder of circular section whose caps are rounded by the exponent n: ((y1/h)^2n + ((y2^2 + y3^2)/R^2)^n)^(1/2n) <= 1",
       "axis along y1 (the frame's x), centred at the origin",
       {{"R", "radius of the circular section, > 0"}, {"h", "half-length along the axis y1, > 0"}, {"n", "exponent, 1 <= n <= 64"}},
       "{ family = \"superelliptic_cylinder\", R = 1.0, h = 2.0, n = 8 }", SuperellipticCylinder(1.0, 2.0, 8.0)},
      {"smooth_polytope",
       "LogSumExp of the half-spaces a_i.y <= b_i; give normals and offsets, or vertices (their convex hull)",
       "as its normals or vertices give it; the frame origin inside",
       {{"normals", "[[ax, ay, az], ...] (normalised), or"},
        {"offsets", "[b_0, ...], one per normal (> 0: the origin inside)"},
        {"vertices", "[[x, y, z], ...], instead of normals and offsets"},
        {"beta", "sharpness, > 0 (up to 1e4 h/L)"},
        {"L", "length scale of the smoothing, > 0 (default 1)"}},
       "{ family = \"smooth_polytope\", vertices = [[1,1,1],[1,1,-1],[1,-1,1],[1,-1,-1],[-1,1,1],[-1,1,-1],[-1,-1,1],[-1,-1,-1]], beta = 20 }",
       std::nullopt},
      {"smooth_truncated_cone",
       "a truncated cone with smoothed rim, LogSumExp of its side and caps",
       "axis along y1 (the frame's x): base (radius Rb) at y1 = -a, top (radius Rt) at y1 = b",
       {{"Rb", "base radius, > 0"}, {"Rt", "top radius, > 0"}, {"a", "length of the axis below the origin, > 0"},
        {"b", "length of the axis above the origin, > 0"}, {"beta", "sharpness, > 0"}},
       "{ family = \"smooth_truncated_cone\", Rb = 1.0, Rt = 1.5, a = 1.5, b = 1.5, beta = 20 }",
       SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
      {"box",
       "generated: a smooth_polytope of the box's 6 faces",
       "faces normal to y1, y2, y3 (the frame's x, y, z)",
       {{"half", "[hx, hy, hz], the half-extents, > 0"},
        {"origin", "[ox, oy, oz], the frame origin in the box (default the centre; |o_i| < h_i)"},
        {"beta", "sharpness, > 0"},
        {"L", "length scale of the smoothing, > 0 (default 1)"}},
       "{ family = \"box\", half = [1.0, 0.5, 0.25], beta = 20 }", std::nullopt, true},
      {"facet_sphere",
       "generated: a smooth_polytope of `facets` planes tangent to a sphere (Fibonacci directions)",
       "centred at the frame origin",
       {{"facets", "number of planes, 4 <= facets <= 20000"}, {"radius", "radius of the tangent sphere, > 0"},
        {"beta", "sharpness, > 0"}, {"L", "length scale of the smoothing, > 0 (default 1)"}},
       "{ family = \"facet_sphere\", facets = 200, radius = 1.0, beta = 20 }", std::nullopt, true},
      {"vertex_sphere",
       "generated: a smooth_polytope, the convex hull of `vertices` points on a sphere (Fibonacci directions)",
       "centred at the frame origin",
       {{"vertices", "number of points, 4 <= vertices <= 5000"}, {"radius", "radius of the sphere, > 0"},
        {"beta", "sharpness, > 0"}, {"L", "length scale of the smoothing, > 0 (default 1)"}},
       "{ family = \"vertex_sphere\", vertices = 200, radius = 1.0, beta = 20 }", std::nullopt, true},
  };
  return docs;
}

namespace {
const FamilyDoc* family_doc(const std::string& family) {
  for (const FamilyDoc& d : shape_families())
    if (family == d.family) return &d;
  return nullptr;
}

// The names of the scene's choices, each listed once for reading and writing.
// A new pose kind adds its name here, its generator in poses.hpp and a line in stress_pose_with.
template <class E>
using Names = std::initializer_list<std::pair<const char*, E>>;
const Names<StressKind> kKinds = {{"shell", StressKind::Shell}, {"touching", StressKind::Touching}, {"explicit", StressKind::Explicit},
                                {"random_bodies", StressKind::RandomBodies}};
const Names<TouchOrientation> kOrientations = {{"uniform", TouchOrientation::Uniform}, {"face", TouchOrientation::Face},
                                               {"edge", TouchOrientation::Edge}, {"vertex", TouchOrientation::Vertex}};
const Names<Pass> kPasses = {{"cold", Pass::Cold}, {"warm", Pass::Warm}};
const Names<OracleChoice> kOracles = {{"auto", OracleChoice::Auto},          {"none", OracleChoice::None},
                                      {"closed_form", OracleChoice::ClosedForm}, {"pw", OracleChoice::PerramWertheim},
                                      {"lp", OracleChoice::PolytopeLP},          {"support", OracleChoice::SupportFunction}};
/// The run.record items, in the scene's order.
const Names<bool RecordSpec::*> kRecordItems = {
    {"timing", &RecordSpec::timing},     {key::iterations, &RecordSpec::iterations},   {"residuals", &RecordSpec::residuals},
    {key::failures, &RecordSpec::failures}, {"per_pose", &RecordSpec::per_pose},       {"derivatives", &RecordSpec::derivatives},
    {"checks", &RecordSpec::checks},     {"baselines", &RecordSpec::baselines}};
template <class E>
const char* name_of(Names<E> names, E v) {
  for (const auto& [n, e] : names)
    if (e == v) return n;
  return "?";
}
/// The value that `text` names; else fails with `unknown <what> "<text>" (expected "a", "b" or "c")`.
template <class E>
E named(const Reader& r, const std::string& key, const std::string& text, Names<E> names, const char* what = nullptr) {
  std::string known;
  std::size_t i = 0;
  for (const auto& [n, e] : names) {
    if (text == n) return e;
    known += std::string(i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + "\"" + n + "\"";
    ++i;
  }
  r.fail(key, "unknown " + (what ? std::string(what) : key) + " \"" + text + "\" (expected " + known + ")");
}
/// The generated polytope families (stress.hpp), as smooth_polytope specs,
/// and their sizes: a vertex costs as much as kMaxFacets / kMaxVertices
/// half-spaces (its hull and the dual's), the budget of read_shapes.
constexpr int kMaxFacets = 20000, kMaxVertices = 5000;
/// The most samples a scene may ask for where each is kept in memory or
/// costs several solves: derivative_samples, hausdorff_directions,
/// oracle_check_poses (500 times the default hausdorff_directions).
constexpr std::int64_t kMaxSamples = 10000000;
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
    for (const FamilyDoc& d : shape_families()) (d.generated ? generated : known) += std::string(d.family) + ", ";
    generated.resize(generated.size() - 2);
    r.fail("family", "unknown family \"" + s.family + "\" (expected one of " + known + "or a generated polytope: " + generated + ")");
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
const char* to_string(StressKind k) { return name_of(kKinds, k); }
const char* to_string(TouchOrientation o) { return name_of(kOrientations, o); }
const char* to_string(OracleChoice o) { return name_of(kOracles, o); }

ShapeSpec parse_shape_inline(const std::string& inline_table, const std::string& file, const std::string& field) {
  toml::table t = parse_toml("shape = " + inline_table, file);
  auto st = t["shape"].as_table();
  if (!st) throw SceneError(file, field, "expected an inline table { family = ..., ... }");
  return read_shape(*st, file, field, field);
}

namespace {

/// What a name names, which decides the characters it may hold.
enum class NameOf { Shape, Case, Scene };

/// Names that tables, CSV rows, failure records, `info` and the history's
/// series keys print as they are. A shape's: 1 to 64 of A-Z a-z 0-9 _ - . +
/// (what a bare TOML key allows, with '.' and '+'). A case's or a scene's: 1
/// to 128 printable ASCII characters (space included) other than '|', not
/// starting or ending with a space. None may hold '|' (a Markdown table's
/// column), a newline, a tab, NUL or any byte outside ASCII (a TOML escape
/// such as \u202E, which shows the text after it reversed). The name is
/// shown escaped in the error (io/text.hpp: escaped).
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

/// The scene's `name` (`def` where it may be left out), checked as above.
std::string read_scene_name(Reader& top, const std::string& file, const char* def = nullptr) {
  const std::string name = top.string("name", def == nullptr, def ? def : "");
  require_safe_name(file, "name", name, NameOf::Scene);
  return name;
}

/// The index in [shapes] of the shape `name` given at `key`.
int shape_index(const Scene& s, const Reader& r, const std::string& key, const std::string& name) {
  for (std::size_t i = 0; i < s.shapes.size(); ++i)
    if (s.shapes[i].name == name) return static_cast<int>(i);
  r.fail(key, "unknown shape \"" + name + "\" (not in [shapes])");
}

/// `key`: the string `word` (then true), or an array of [name, name] arrays
/// naming shapes of [shapes], read into `out` (then false); `bad_entry` is
/// the message for an entry of another form. Absent and not required: true.
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

/// "passes": some of "cold", "warm", each once.
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

Pose read_explicit_pose(const toml::node& n, const std::string& file, const std::string& field) {
  auto t = n.as_table();
  if (!t) throw SceneError(file, field, "expected { R = [[...], [...], [...]], p = [x, y, z] }, got " + type_name(n));
  Reader r(*t, file, field);
  Pose X;
  const toml::node* Rn = r.get("R", true, "a 3x3 rotation [[..], [..], [..]]");
  const toml::node* pn = r.get("p", true, "a translation [x, y, z]");
  r.finish();
  // Each entry a finite number, named as R[i][c] or p[i] in errors.
  auto entry = [&](const toml::node& e, const std::string& key) {
    const double v = r.as_number(e, key);
    if (!std::isfinite(v)) r.fail(key, "expected a finite number, got " + fmt17(v));
    return v;
  };
  auto Ra = Rn->as_array();
  if (!Ra || Ra->size() != 3) r.fail("R", "expected a 3x3 rotation [[..], [..], [..]]");
  for (int i = 0; i < 3; ++i) {
    auto row = Ra->get(i)->as_array();
    if (!row || row->size() != 3) r.fail("R", "expected a 3x3 rotation [[..], [..], [..]]");
    for (int c = 0; c < 3; ++c) X.R(i, c) = entry(*row->get(c), "R[" + std::to_string(i) + "][" + std::to_string(c) + "]");
  }
  auto pa = pn->as_array();
  if (!pa || pa->size() != 3) r.fail("p", "expected a translation [x, y, z]");
  for (int i = 0; i < 3; ++i) X.p[i] = entry(*pa->get(i), "p[" + std::to_string(i) + "]");
  const double orth = (X.R.transpose() * X.R - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (orth > 1e-9) r.fail("R", "not orthonormal: max |R^T R - I| = " + fmt17(orth) + " (expected a rotation matrix, to 1e-9)");
  const double det = X.R.determinant();
  if (det < 0.0) r.fail("R", "det R = " + fmt17(det) + ": a reflection, not a rotation (expected det R = +1)");
  return X;
}

/// The fields of a kind = "random_bodies" case (random_bodies.hpp), after the common ones.
void read_random_bodies_case(Reader& r, const toml::table& t, StressCase& c) {
  auto family = [&](const char* key) {
    try {
      return body_family_from_string(r.string(key));
    } catch (const std::invalid_argument& e) {
      r.fail(key, e.what());
    }
  };
  c.random.family1 = family("family1");
  c.random.family2 = family("family2");
  try {
    c.random.range = body_range_from_string(r.string("range", false, "normal"));
  } catch (const std::invalid_argument& e) {
    r.fail("range", e.what());
  }
  c.random.seed = r.count("seed", false, 1, true);
  c.poses = r.count("poses", true, 0, false);
  // The bodies change with every pose: no derivative subsample (it needs one
  // pair), no warm chain (a warm solve starts from the same pair's answer).
  if (t.contains("derivative_samples")) r.fail("derivative_samples", "not used by kind \"random_bodies\" (remove it)");
  if (t.contains("warm_chain")) r.fail("warm_chain", "not used by kind \"random_bodies\": each warm solve starts from the answer at its own pose");
  c.derivative_samples = 0;
  const std::string o = r.string("oracle", false, "support");
  if (o != "support" && o != "auto") r.fail("oracle", "kind \"random_bodies\" is checked by the support-function bracket: expected \"support\", got \"" + o + "\"");
  c.oracle = OracleChoice::SupportFunction;
  r.finish();
}

StressCase read_case(const toml::table& t, const std::string& file, const std::string& field, const Scene& s) {
  Reader r(t, file, field);
  StressCase c;
  c.name = r.string("name");
  require_safe_name(file, field + ".name", c.name, NameOf::Case);
  c.kind = named(r, "kind", r.string("kind"), kKinds);
  if (c.kind != StressKind::RandomBodies) {  // random_bodies cases draw their own bodies
    c.body1 = shape_index(s, r, "body1", r.string("body1"));
    c.body2 = shape_index(s, r, "body2", r.string("body2"));
  }

  c.passes = read_passes(r);
  c.warm_chain = r.count("warm_chain", false, c.warm_chain, false);
  c.oracle_every = r.count("oracle_every", false, c.oracle_every, false);
  c.derivative_samples = r.bounded_int("derivative_samples", false, 64, 0, kMaxSamples);
  (void)r.string("covers", false);  // documentation only: the regime the case stands for
  if (c.kind == StressKind::RandomBodies) {
    read_random_bodies_case(r, t, c);
    return c;
  }

  if (c.kind == StressKind::Explicit) {
    const toml::node* pn = r.get("poses", true, "an array of { R = ..., p = ... } tables");
    auto arr = pn->as_array();
    if (!arr || arr->empty()) r.fail("poses", "expected a non-empty array of { R = ..., p = ... } tables");
    for (std::size_t i = 0; i < arr->size(); ++i)
      c.explicit_poses.push_back(read_explicit_pose(*arr->get(i), file, field + ".poses[" + std::to_string(i) + "]"));
    c.poses = c.explicit_poses.size();
  } else {
    c.poses = r.count("poses", true, 0, false);
  }
  if (c.kind == StressKind::Shell) {
    c.rmin = r.number("rmin", false, c.rmin);
    c.rmax = r.number("rmax", false, c.rmax);
    if (!(c.rmin > 0.0) || !std::isfinite(c.rmin)) r.fail("rmin", "expected a finite number > 0, got " + fmt17(c.rmin));
    if (!(c.rmax >= c.rmin) || !std::isfinite(c.rmax))
      r.fail("rmax", "expected a finite number >= rmin (" + fmt17(c.rmin) + "), got " + fmt17(c.rmax));
    c.zero_every = r.count("zero_every", false, 0, true);
  }
  if (c.kind == StressKind::Touching) {
    c.orientation = named(r, "orientation", r.string("orientation", false, "uniform"), kOrientations);
    if (t.contains("touch_eps")) {
      c.touch_eps = r.numbers("touch_eps");
      if (c.touch_eps.empty()) r.fail("touch_eps", "expected a non-empty array of numbers");
      for (double e : c.touch_eps)
        if (!std::isfinite(e) || !(std::abs(e) < 0.5)) r.fail("touch_eps", "expected finite numbers with |eps| < 0.5, got " + fmt17(e));
    }
  }

  const Shape& b1 = *s.shapes[c.body1].shape;
  const Shape& b2 = *s.shapes[c.body2].shape;
  const std::string pair = "\"" + s.shapes[c.body1].name + "\" (" + family_name(b1) + ") x \"" + s.shapes[c.body2].name +
                           "\" (" + family_name(b2) + ")";
  using O = OracleChoice;
  const std::string o = r.string("oracle", false, "auto");
  c.oracle = named(r, "oracle", o, kOracles);
  if (c.oracle == O::ClosedForm && (!is_sphere(b1) || !is_sphere(b2)))
    r.fail("oracle", "\"closed_form\" serves sphere x sphere only, not " + pair);
  if (c.oracle == O::PerramWertheim && (!is_exact_ellipsoid(b1) || !is_exact_ellipsoid(b2)))
    r.fail("oracle", "\"pw\" (Perram-Wertheim) serves exact ellipsoids only (sphere, or superellipsoid with n = 1), not " + pair);
  if (c.oracle == O::PolytopeLP && (!is_polytope(b1) || !is_polytope(b2)))
    r.fail("oracle", "\"lp\" serves smooth_polytope x smooth_polytope only, not " + pair);
  if (c.oracle == OracleChoice::PolytopeLP && !have_polytope_lp())
    r.fail("oracle", "\"lp\" needs GLPK, and this build has none (configure with -DIDCOL_BUILD_BASELINES=ON)");
  if (c.oracle == OracleChoice::Auto) c.oracle = AnswerChecker::resolve_oracle(b1, b2);
  r.finish();
  return c;
}

/// A sweep's [run], [baselines] and [derivatives].
void read_run(Reader& top, const std::string& file, Scene& s) {
  // [run]
  {
    Reader r(*top.table("run", true), file, "run");
    s.all_pairs = read_pair_list(s, r, "pairs", "all", true, "expected \"all\" or an array of [name, name] arrays", s.pairs);
    for (int i = 0; s.all_pairs && i < static_cast<int>(s.shapes.size()); ++i)
      for (int j = i; j < static_cast<int>(s.shapes.size()); ++j) s.pairs.emplace_back(i, j);
    // A set, not a search of the pairs before each: "all" of 1,000 shapes is
    // 500,500 pairs.
    std::set<std::pair<int, int>> seen;
    for (const auto& ij : s.pairs)
      if (!seen.insert(ij).second)
        r.fail("pairs", "pair [" + s.shapes[ij.first].name + ", " + s.shapes[ij.second].name +
                            "] is given twice (it would run twice and show once)");
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
    s.passes = read_passes(r);
    for (const std::string& w : r.strings("record", true)) {
      const auto item = std::find_if(kRecordItems.begin(), kRecordItems.end(), [&](const auto& i) { return w == i.first; });
      if (item == kRecordItems.end())
        r.fail("record", "unknown item \"" + w +
                             "\" (expected timing, iterations, residuals, failures, per_pose, derivatives, checks or baselines)");
      if (w == "baselines" && !baselines_available())
        r.fail("record", "\"baselines\" is not available in this build (configured with "
                         "-DIDCOL_BUILD_BASELINES=OFF); remove it from run.record");
      s.record.*item->second = true;
    }
    const std::string path = r.string("timed_path", false, "loop");
    if (path != "loop" && path != "batch")
      r.fail("timed_path", "expected \"loop\" (each solve timed on its own) or \"batch\" (blocks of poses timed through "
                           "solve_batch on one thread), got \"" + path + "\"");
    s.timed_batch = path == "batch";
    if (s.timed_batch && !s.record.timing)
      r.fail("timed_path", "\"batch\" chooses how the passes are timed: it needs \"timing\" in run.record");
    r.finish();
  }

  // A list of pairs: "run" (the run's pairs) or an array of [name, name].
  auto pair_list = [&](Reader& r, const std::string& key) {
    std::vector<std::pair<int, int>> out;
    if (read_pair_list(s, r, key, "run", false, "expected an array of [name, name] arrays", out)) return s.pairs;
    const std::set<std::pair<int, int>> run_pairs(s.pairs.begin(), s.pairs.end());
    for (const auto& ij : out)
      if (!run_pairs.count(ij))
        r.fail(key, "pair [" + s.shapes[ij.first].name + ", " + s.shapes[ij.second].name + "] is not one of run.pairs");
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

  // [reference] (optional): published figures to print beside the run's.
  if (const toml::table* rt = top.table("reference", false)) {
    if (!s.record.baselines || !s.record.timing)
      throw SceneError(file, "reference", "given, but it is printed beside the agreement pass's times: run.record must ask "
                                          "for \"baselines\" and \"timing\"");
    Reader r(*rt, file, "reference");
    s.reference.source = r.string("source", true);
    if (s.reference.source.empty()) r.fail("source", "expected where the figures come from, got an empty string");
    const toml::table* mt = r.typed<toml::table>("mean_us", true, "a table { method = { \"A-B\" = us, ... }, ... }");
    std::set<std::string> pairs;
    for (const auto& [i1, i2] : s.baselines.pairs) pairs.insert(s.shapes[i1].name + "-" + s.shapes[i2].name);
    for (const auto& [mk, node] : *mt) {
      const std::string m(mk.str()), field = "mean_us." + m;
      if (m != "idcol_cold" && m != "idcol_warm" && !s.baselines.has(m))
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
        s.reference.mean_us[m][pair] = us;
      }
    }
    r.finish();
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
}

/// A smoothing study's [grid] and [study].
void read_grid(Reader& top, const std::string& file, GridSpec& c) {
  Reader g(*top.table("grid", true), file, "grid");
  const toml::table* shape = g.table("shape", true);
  c.parameter = g.string("parameter");
  if (c.parameter != "beta" && c.parameter != "n") g.fail("parameter", "expected \"beta\" or \"n\", got \"" + c.parameter + "\"");
  c.values = g.numbers("values");
  if (c.values.empty()) g.fail("values", "expected a non-empty array of numbers");
  c.partner_radius = g.number("partner_radius", false, c.partner_radius);
  if (!(c.partner_radius > 0.0) || !std::isfinite(c.partner_radius))
    g.fail("partner_radius", "expected a finite number > 0, got " + fmt17(c.partner_radius));
  g.finish();
  // The shape at each value, as text for the harness's shape parser (so a
  // scene and the grid accept the same text).
  for (double v : c.values) {
    toml::table t = *shape;
    t.insert_or_assign(c.parameter, v);
    t.is_inline(true);
    std::ostringstream st;
    st << t;
    c.shape_texts.push_back(st.str());
  }
  if (const toml::table* t = top.table("study", false)) {
    Reader s(*t, file, "study");
    c.directions = s.bounded_int("hausdorff_directions", false, c.directions, 1, kMaxSamples);
    c.oracle_check_poses = s.bounded_int("oracle_check_poses", false, c.oracle_check_poses, 1, kMaxSamples);
    c.recommend_error_below = s.number("recommend_error_below", false, c.recommend_error_below);
    if (!(c.recommend_error_below > 0.0 && c.recommend_error_below < 1.0))
      s.fail("recommend_error_below", "expected a number in (0, 1), the alpha* p99 relative error below which a value may be "
                                      "recommended (default 0.01), got " + fmt17(c.recommend_error_below));
    s.finish();
  }
}

/// [shapes], in file order; `required` unless the kind can do without.
/// The generated polytopes, where a few bytes ask for many half-spaces, are
/// bounded in all as one is alone (kMaxFacets half-spaces, a vertex costing
/// kMaxFacets / kMaxVertices), before any is built, so that no scene takes
/// long to read.
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

/// [sweep]: all of it for a sweep; a smoothing grid's is optional, and
/// always the paper's trajectory.
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
}  // namespace

void read_sweep_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file);
  read_shapes(top, file, s, true);
  read_sweep_table(top, file, s, true);
  read_run(top, file, s);
}

void read_stress_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file);
  // [shapes] may be absent when every case draws its own bodies
  // (random_bodies): a case naming a shape that is not there is rejected
  // as an unknown shape.
  read_shapes(top, file, s, false);
  const toml::node* cn = top.get("case", true, "an array of [[case]] tables");
  auto cases = cn->as_array();
  if (!cases || cases->empty()) throw SceneError(file, "case", "expected at least one [[case]] table");
  for (std::size_t i = 0; i < cases->size(); ++i) {
    const std::string field = "case[" + std::to_string(i) + "]";
    auto t = cases->get(i)->as_table();
    if (!t) throw SceneError(file, field, "expected a [[case]] table, got " + type_name(*cases->get(i)));
    s.cases.push_back(read_case(*t, file, field, s));
    for (std::size_t j = 0; j + 1 < s.cases.size(); ++j)
      if (s.cases[j].name == s.cases.back().name)
        throw SceneError(file, field + ".name", "case name \"" + s.cases.back().name + "\" given twice");
  }
  // The stress suite reports the KKT conditioning of every answer, which
  // reads the factorisation at the solution.
  s.solver.derivatives = true;
}

void read_smoothing_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file, "smoothing");
  // No [shapes]: the grid gives its one shape.
  read_grid(top, file, s.grid.emplace());
  s.poses = 10000;
  s.warmup = 500;
  read_sweep_table(top, file, s, false);
}

void read_toi_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file);
  read_shapes(top, file, s, true);
  ToiSpec& t = s.toi.emplace();
  Reader r(*top.table("toi", true), file, "toi");
  read_pair_list(s, r, "pairs", "", true, "expected an array of [name, name] arrays", t.pairs);
  if (t.pairs.empty()) r.fail("pairs", "expected an array of [name, name] arrays");
  t.motions = r.count("motions", true, t.motions, false);
  if (r.get("models", false, "an array of strings")) t.models = r.strings("models", true);
  if (t.models.empty()) r.fail("models", "expected some of \"translation\", \"screw\"");
  for (std::size_t i = 0; i < t.models.size(); ++i) {
    if (t.models[i] != "translation" && t.models[i] != "screw")
      r.fail("models", "expected \"translation\" or \"screw\", got \"" + t.models[i] + "\"");
    for (std::size_t j = 0; j < i; ++j)
      if (t.models[i] == t.models[j]) r.fail("models", "\"" + t.models[i] + "\" given twice");
  }
  t.seed = r.count("seed", false, t.seed, true);
  if (t.seed > (1u << 20)) r.fail("seed", "expected an integer in [0, 1048576], got " + std::to_string(t.seed));
  if (t.motions > (1u << 20)) r.fail("motions", "expected at most 1048576, got " + std::to_string(t.motions));
  t.oracle_samples = r.bounded_int("oracle_samples", false, t.oracle_samples, 10, 1000000);
  auto in_range = [&](const char* key, double& v, double lo, double hi) {
    v = r.number(key, false, v);
    if (!(v >= lo && v <= hi)) r.fail(key, "expected a number in [" + fmt17(lo) + ", " + fmt17(hi) + "], got " + fmt17(v));
  };
  in_range("graze", t.graze, 0.0, 0.5);
  in_range("spread", t.spread, 0.0, 10.0);
  in_range("offset", t.offset, 0.0, 10.0);
  in_range("turn_min", t.turn_min, 0.0, 3.14159);
  in_range("turn_max", t.turn_max, t.turn_min, 3.14159);
  in_range("end_inside", t.end_inside, 0.0, 1.0);
  if (r.get("fcl", false, "an array of strings")) t.fcl = r.strings("fcl", true);
  for (const std::string& m : t.fcl)
    if (m != "naive" && m != "conservative_advancement")
      r.fail("fcl", "expected \"naive\" or \"conservative_advancement\", got \"" + m + "\"");
  t.fcl_naive_steps = r.bounded_int("fcl_naive_steps", false, t.fcl_naive_steps, 2, 100000);
  r.finish();
}

bool BaselineSpec::has(const std::string& m) const { return std::find(methods.begin(), methods.end(), m) != methods.end(); }
bool BaselineSpec::covers(int i1, int i2) const { return std::find(pairs.begin(), pairs.end(), std::pair{i1, i2}) != pairs.end(); }
bool DerivativeSpec::covers(int i1, int i2) const { return std::find(pairs.begin(), pairs.end(), std::pair{i1, i2}) != pairs.end(); }

const std::vector<SceneKind>& scene_kinds() {
  static const std::vector<SceneKind> kinds = {
      {"sweep", nullptr, read_sweep_scene}, {"stress", "case", read_stress_scene}, {"smoothing", "grid", read_smoothing_scene},
      {"toi", "toi", read_toi_scene}};
  return kinds;
}

Scene parse_scene(const std::string& text, const std::string& file) {
  const toml::table root = parse_toml(text, file);
  Scene s;
  s.path = file;
  s.text = text;
  const std::vector<SceneKind>& kinds = scene_kinds();
  auto kind = std::find_if(kinds.begin(), kinds.end(), [&](const SceneKind& k) { return k.section && root.contains(k.section); });
  if (kind == kinds.end()) kind = std::find_if(kinds.begin(), kinds.end(), [](const SceneKind& k) { return !k.section; });
  s.kind = &*kind;
  Reader top(root, file, "");
  s.description = top.string("description", false);
  read_solver_table(top, file, s.solver);  // [solver] (optional): overrides of SolverOptions
  s.kind->read(top, file, s);
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
  for (const auto& [name, on] : kRecordItems)
    if (r.*on) v.emplace_back(name);
  return v;
}

std::string scene_to_toml(const Scene& s) {
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
  for (const Pass p : s.passes) passes.emplace_back(to_string(p));
  o << "\n[run]\npairs = " << (s.all_pairs ? "\"all\"" : pair_text(s.pairs)) << "\npasses = " << quoted(passes)
    << "\nrecord = " << quoted(record_names(s.record)) << "\n";
  if (s.timed_batch) o << "timed_path = \"batch\"\n";
  if (s.record.baselines) {
    o << "\n[baselines]\nmethods = " << quoted(s.baselines.methods) << "\npairs = " << pair_text(s.baselines.pairs)
      << "\ntiming_poses = " << s.baselines.timing_poses << "\nband_tolerance = " << fmt17(s.baselines.band_tolerance)
      << "\nnear_contact = " << fmt17(s.baselines.near_contact) << "\n";
  }
  if (!s.reference.empty()) {
    o << "\n[reference]\nsource = " << quote(s.reference.source) << "\n[reference.mean_us]\n";
    for (const auto& [m, byp] : s.reference.mean_us) {
      o << m << " = {";
      bool first = true;
      for (const auto& [pair, us] : byp) o << (first ? " " : ", ") << quote(pair) << " = " << fmt17(us), first = false;
      o << " }\n";
    }
  }
  if (s.record.derivatives)
    o << "\n[derivatives]\nevery = " << s.derivatives.every << "\npairs = " << pair_text(s.derivatives.pairs)
      << "\nh = " << fmt17(s.derivatives.h) << "\ntolerance = " << fmt17(s.derivatives.tolerance) << "\n";
  o << "\n" << solver_toml(s.solver);
  return o.str();
}

}  // namespace idcol::harness

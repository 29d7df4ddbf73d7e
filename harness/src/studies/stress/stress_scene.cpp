// A stress scene's own sections, the [[case]] tables (stress_spec.hpp).
#include "studies/stress/stress_spec.hpp"

#include <algorithm>
#include <cmath>

#include "referee/lp_oracle.hpp"
#include "scene/scene_toml.hpp"

namespace idcol::harness {

namespace {

// The names of a case's choices, each listed once for reading and writing.
// A new pose kind adds its name here, its generator in poses.hpp and a line in stress_pose_with.
const Names<StressKind> kKinds = {{"shell", StressKind::Shell}, {"touching", StressKind::Touching}, {"explicit", StressKind::Explicit},
                                {"random_bodies", StressKind::RandomBodies}};
const Names<TouchOrientation> kOrientations = {{"uniform", TouchOrientation::Uniform}, {"face", TouchOrientation::Face},
                                               {"edge", TouchOrientation::Edge}, {"vertex", TouchOrientation::Vertex}};

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
  c.oracle = oracle_named(r, "oracle", o);
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

}  // namespace

const char* to_string(StressKind k) { return name_of(kKinds, k); }
const char* to_string(TouchOrientation o) { return name_of(kOrientations, o); }

void read_stress_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file);
  // [shapes] may be absent when every case draws its own bodies
  // (random_bodies): a case naming a shape that is not there is rejected
  // as an unknown shape.
  read_shapes(top, file, s, false);
  std::vector<StressCase>& cases = s.spec.emplace<StressSpec>().cases;
  const toml::node* cn = top.get("case", true, "an array of [[case]] tables");
  auto tables = cn->as_array();
  if (!tables || tables->empty()) throw SceneError(file, "case", "expected at least one [[case]] table");
  for (std::size_t i = 0; i < tables->size(); ++i) {
    const std::string field = "case[" + std::to_string(i) + "]";
    auto t = tables->get(i)->as_table();
    if (!t) throw SceneError(file, field, "expected a [[case]] table, got " + type_name(*tables->get(i)));
    cases.push_back(read_case(*t, file, field, s));
    for (std::size_t j = 0; j + 1 < cases.size(); ++j)
      if (cases[j].name == cases.back().name)
        throw SceneError(file, field + ".name", "case name \"" + cases.back().name + "\" given twice");
  }
  // The stress suite reports the KKT conditioning of every answer, which
  // reads the factorisation at the solution.
  s.solver.derivatives = true;
}

}  // namespace idcol::harness

// Python bindings of the contact-physics layer: WarmStarts (solve_batch's
// per-row warm states), broad_phase, Scene and its Contacts, MassProperties,
// MultibodySystem with simulate(), and the example scenes.
#include <chrono>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "idcol/broad_phase.hpp"
#include "idcol/multibody_scenes.hpp"
#include "idcol/rigid_body.hpp"
#include "idcol/scene.hpp"

namespace idcol::python {

namespace {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

BroadPhaseMethod broad_method(const std::string& s) {
  for (BroadPhaseMethod m : {BroadPhaseMethod::Auto, BroadPhaseMethod::AllPairs, BroadPhaseMethod::SweepAndPrune,
                             BroadPhaseMethod::Tree})
    if (s == to_string(m)) return m;
  throw py::value_error("broad_phase must be 'auto', 'all_pairs', 'sweep_and_prune' or 'tree', got '" + s + "'");
}

std::vector<Shape> shape_list(py::handle shapes, const char* name) {
  if (!py::isinstance<py::sequence>(shapes) || py::isinstance<py::str>(shapes))
    throw py::type_error(std::string(name) + " must be a sequence of idcol shapes, got " + type_name(shapes));
  std::vector<Shape> out;
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(shapes);
  for (std::size_t k = 0; k < seq.size(); ++k)
    out.push_back(*as_shape(seq[k], std::string(name) + "[" + std::to_string(k) + "]").shape);
  return out;
}

/// The scene's options from the Python keywords: SolverOptions (None: the
/// scene's default, alpha_max = 1), HertzModel (None: HertzModel()).
SceneOptions scene_options(const py::object& options, const py::object& contact, const std::string& broad_phase,
                           bool warm_start, int threads) {
  SceneOptions o;
  if (!options.is_none()) o.solver = options_or_default(options);
  o.contact = hertz_model(contact);
  o.broad_phase = broad_method(broad_phase);
  o.warm_start = warm_start;
  if (threads < 0) throw py::value_error("threads must be >= 0 (0 = all CPUs), got " + std::to_string(threads));
  o.threads = threads;
  o.validate();
  return o;
}

/// N world poses from R (N, 3, 3) and p (N, 3), each checked (ValueError
/// naming R[k] / p[k]).
std::vector<Pose> world_pose_list(py::handle R, py::handle p, std::size_t n) {
  const CArray Ra = rotations(R, "R", true), pa = float_array(p, "p");
  if (pa.ndim() != 2 || pa.shape(1) != 3) throw py::value_error("p must have shape (N, 3), got " + shape_str(pa));
  if (static_cast<std::size_t>(Ra.shape(0)) != n || static_cast<std::size_t>(pa.shape(0)) != n)
    throw py::value_error("R and p must hold one pose per body (" + std::to_string(n) + "), got " +
                          std::to_string(Ra.shape(0)) + " and " + std::to_string(pa.shape(0)));
  std::vector<Pose> X(n);
  for (std::size_t k = 0; k < n; ++k) {
    X[k].R = Eigen::Map<const RowMat3>(Ra.data() + 9 * k);
    X[k].p = Eigen::Map<const Vec3>(pa.data() + 3 * k);
    const std::string at = "[" + std::to_string(k) + "]";
    const std::string bad = pose_problem(X[k].R, X[k].p, "R" + at, "p" + at);
    if (!bad.empty()) throw py::value_error(bad);
  }
  return X;
}

py::tuple poses_to_numpy(const std::vector<Pose>& X) {
  const auto n = static_cast<py::ssize_t>(X.size());
  py::array_t<double> R({n, py::ssize_t{3}, py::ssize_t{3}}), p({n, py::ssize_t{3}});
  for (py::ssize_t k = 0; k < n; ++k) {
    Eigen::Map<RowMat3>(R.mutable_data() + 9 * k) = X[k].R;
    Eigen::Map<Vec3>(p.mutable_data() + 3 * k) = X[k].p;
  }
  return py::make_tuple(frozen(R), frozen(p));
}

Eigen::VectorXd state_vector(py::handle y, int size) {
  const CArray a = float_array(y, "y");
  if (a.ndim() != 1 || a.shape(0) != size)
    throw py::value_error("y must have shape (" + std::to_string(size) + ",) (12 per body), got " + shape_str(a));
  return Eigen::Map<const Eigen::VectorXd>(a.data(), size);
}

// ---------------------------------------------------------------------------
// Scene contacts as arrays.

struct PyContacts : Guarded {
  py::dict arrays;
};

const char* const kContactFields[][2] = {
    {"body1", "(K,) int32 index i of each candidate pair (i < j)"},
    {"body2", "(K,) int32 index j"},
    {"status", "(K,) int32 SolveStatus codes"},
    {"iterations", "(K,) int32 Newton steps"},
    {"warm_started", "(K,) bool: the pair had a warm state from the last update"},
    {"ok", "(K,) bool: the solve answered (Converged, or Separated with alpha_max >= 1)"},
    {"active", "(K,) bool: converged with gap < 0, a force acts"},
    {"alpha", "(K,) alpha* (Separated: the certified bound)"},
    {"gap", "(K,) gap = (1 - 1/alpha*)|r| (NaN unless converged)"},
    {"x_W", "(K, 3) x*, where the force acts, world frame (NaN unless converged)"},
    {"normal_W", "(K, 3) body i's outward unit normal, world frame (NaN unless converged)"},
    {"f_n", "(K,) f_n = k (-gap)^p (0 when inactive, NaN when not ok)"},
    {"F1", "(K, 6) wrench on body i, body-i frame about its origin, (moment, force)"},
    {"F2", "(K, 6) wrench on body j, body-j frame about its origin"},
    {"dF1", "(K, 6, 12) d F1 / d(xi_i, xi_j), body twists of both world poses (derivatives=True; zeros when inactive)"},
    {"dF2", "(K, 6, 12) d F2 / d(xi_i, xi_j) (derivatives=True)"},
};

PyContacts contacts_to_numpy(const Scene& scene, bool derivatives) {
  const std::vector<Contact>& cs = scene.contacts();
  const auto K = static_cast<py::ssize_t>(cs.size());
  py::array_t<std::int32_t> b1(K), b2(K), st(K), it(K);
  py::array_t<bool> warm(K), ok(K), active(K);
  py::array_t<double> alpha(K), gap(K), x({K, py::ssize_t{3}}), n({K, py::ssize_t{3}}), fn(K);
  py::array_t<double> F1({K, py::ssize_t{6}}), F2({K, py::ssize_t{6}});
  for (py::ssize_t k = 0; k < K; ++k) {
    const Contact& c = cs[static_cast<std::size_t>(k)];
    b1.mutable_data()[k] = c.body1, b2.mutable_data()[k] = c.body2;
    st.mutable_data()[k] = static_cast<std::int32_t>(c.status), it.mutable_data()[k] = c.iterations;
    warm.mutable_data()[k] = c.warm_started, ok.mutable_data()[k] = c.ok, active.mutable_data()[k] = c.active;
    alpha.mutable_data()[k] = c.alpha, gap.mutable_data()[k] = c.gap, fn.mutable_data()[k] = c.f_n;
    Eigen::Map<Vec3>(x.mutable_data() + 3 * k) = c.x_W;
    Eigen::Map<Vec3>(n.mutable_data() + 3 * k) = c.normal_W;
    Eigen::Map<Vec6>(F1.mutable_data() + 6 * k) = c.F1_1;
    Eigen::Map<Vec6>(F2.mutable_data() + 6 * k) = c.F2_2;
  }
  PyContacts r;
  r.arrays["body1"] = frozen(b1), r.arrays["body2"] = frozen(b2), r.arrays["status"] = frozen(st);
  r.arrays["iterations"] = frozen(it), r.arrays["warm_started"] = frozen(warm), r.arrays["ok"] = frozen(ok);
  r.arrays["active"] = frozen(active), r.arrays["alpha"] = frozen(alpha), r.arrays["gap"] = frozen(gap);
  r.arrays["x_W"] = frozen(x), r.arrays["normal_W"] = frozen(n), r.arrays["f_n"] = frozen(fn);
  r.arrays["F1"] = frozen(F1), r.arrays["F2"] = frozen(F2);
  r.arrays["dF1"] = py::none(), r.arrays["dF2"] = py::none();
  if (derivatives) {
    using RowMat612 = Eigen::Matrix<double, 6, 12, Eigen::RowMajor>;
    py::array_t<double> d1({K, py::ssize_t{6}, py::ssize_t{12}}), d2({K, py::ssize_t{6}, py::ssize_t{12}});
    for (py::ssize_t k = 0; k < K; ++k) {
      const Contact& c = cs[static_cast<std::size_t>(k)];
      Eigen::Map<RowMat612> m1(d1.mutable_data() + 72 * k), m2(d2.mutable_data() + 72 * k);
      if (c.jacobian < 0) {
        m1.setZero(), m2.setZero();
        continue;
      }
      const ContactJacobian& J = scene.jacobians()[static_cast<std::size_t>(c.jacobian)];
      m1 = J.dF1, m2 = J.dF2;
    }
    r.arrays["dF1"] = frozen(d1), r.arrays["dF2"] = frozen(d2);
  }
  return r;
}

// ---------------------------------------------------------------------------
// The Python side of a Scene and of a MultibodySystem.

struct PyScene : Guarded {
  Scene scene;
  explicit PyScene(SceneOptions o) : scene(o) {}
};

struct PyMultibody : Guarded {
  MultibodySystem system;
  PyMultibody(std::vector<Shape> s, std::vector<MassProperties> m, SceneOptions o)
      : system(std::move(s), std::move(m), o) {}
};

}  // namespace
}  // namespace idcol::python

// An instance made by the base class's __new__ (no __init__) reaches no
// method: its argument caster raises TypeError (bindings.hpp, "Objects made
// with __new__ and no __init__").
namespace pybind11::detail {
template <>
class type_caster<idcol::python::PyContacts> : public idcol::python::GuardedCaster<idcol::python::PyContacts> {};
template <>
class type_caster<idcol::python::PyScene> : public idcol::python::GuardedCaster<idcol::python::PyScene> {};
template <>
class type_caster<idcol::python::PyMultibody> : public idcol::python::GuardedCaster<idcol::python::PyMultibody> {};
template <>
class type_caster<idcol::MassProperties> : public idcol::python::BuiltCaster<idcol::MassProperties> {};
}  // namespace pybind11::detail

namespace idcol::python {
namespace {

py::dict stats_dict(const SceneUpdateStats& s) {
  py::dict d;
  d["candidates"] = s.candidates, d["active"] = s.active, d["failed"] = s.failed, d["separated"] = s.separated;
  d["newton_iterations"] = s.newton_iterations, d["broad_seconds"] = s.broad_seconds;
  d["narrow_seconds"] = s.narrow_seconds;
  return d;
}

py::dict run_dict(const MultibodyRun& r) {
  py::dict d;
  d["status"] = to_string(r.status);
  d["t_reached"] = r.t_reached;
  d["wall_seconds"] = r.wall_seconds;
  const auto m = static_cast<py::ssize_t>(r.t.size());
  const py::ssize_t n = m ? static_cast<py::ssize_t>(r.y.front().size()) : 0;
  py::array_t<double> t(m), y({m, n});
  for (py::ssize_t k = 0; k < m; ++k) {
    t.mutable_data()[k] = r.t[static_cast<std::size_t>(k)];
    Eigen::Map<Eigen::VectorXd>(y.mutable_data() + n * k, n) = r.y[static_cast<std::size_t>(k)];
  }
  d["t"] = frozen(t), d["y"] = frozen(y);
  const StiffOdeStats& o = r.ode;
  d["steps"] = o.steps, d["error_failures"] = o.error_failures, d["newton_failures"] = o.newton_failures;
  d["function_failures"] = o.function_failures, d["rhs_evaluations"] = o.rhs_evaluations;
  d["jacobian_evaluations"] = o.jacobian_evaluations, d["lu_decompositions"] = o.lu_decompositions;
  d["restarts"] = o.restarts, d["max_order"] = o.max_order_used;
  const MultibodySystem::Counters& c = r.counters;
  d["broad_seconds"] = c.broad_seconds, d["narrow_seconds"] = c.narrow_seconds;
  d["narrow_rows"] = c.narrow_rows, d["active_contacts"] = c.active_contacts;
  d["contacts_per_step_mean"] = r.step_contacts_mean, d["contacts_per_step_max"] = r.step_contacts_max;
  return d;
}

py::object body_scene(const BodyScene& sc) {
  py::list shapes, masses;
  for (const Shape& s : sc.shapes) shapes.append(wrap_shape(s));
  for (const MassProperties& m : sc.masses) masses.append(py::cast(m));
  const auto n = static_cast<py::ssize_t>(sc.eta.size());
  py::array_t<double> eta({n, py::ssize_t{6}});
  for (py::ssize_t k = 0; k < n; ++k) Eigen::Map<Vec6>(eta.mutable_data() + 6 * k) = sc.eta[static_cast<std::size_t>(k)];
  const py::tuple Rp = poses_to_numpy(sc.X_W);
  py::object ns = py::module_::import("types").attr("SimpleNamespace")();
  ns.attr("names") = name_list(sc.names);
  ns.attr("shapes") = shapes, ns.attr("masses") = masses;
  ns.attr("R") = Rp[0], ns.attr("p") = Rp[1], ns.attr("eta") = frozen(eta);
  return ns;
}

void bind_warm_starts(py::module_& m) {
  py::class_<PyWarmStarts> cls(
      m, "WarmStarts",
      "One warm-start state per row of solve_batch(..., warm=ws), in and out (C++ BatchOutput::warm): row k starts "
      "from ws[k] when it holds a solution and leaves its own there, so that the rows of one call may be N "
      "different pairs each carried from its last call (a simulator's contact pairs). Rows are independent: the "
      "answers do not depend on threads. Pickles (as its items).");
  cls.def(py::init([](long long n) {
            if (n < 0) throw py::value_error("WarmStarts: n must be >= 0, got " + std::to_string(n));
            PyWarmStarts w;
            w.states.resize(static_cast<std::size_t>(n));
            return w;
          }),
          py::arg("n"))
      .def("__len__", [](const PyWarmStarts& w) { return w.states.size(); })
      .def("reset", [](PyWarmStarts& w) { for (WarmStart& s : w.states) s.reset(); }, "Forget every state.")
      .def_property_readonly("valid", [](const PyWarmStarts& ws) {
        const std::vector<WarmStart>& w = ws.states;
        py::array_t<bool> a(static_cast<py::ssize_t>(w.size()));
        for (std::size_t k = 0; k < w.size(); ++k) a.mutable_data()[k] = w[k].valid;
        return frozen(a);
      }, "(N,) bool: which rows hold a solution to start from.")
      .def("__getitem__", [](const PyWarmStarts& ws, long long k) {
        const std::vector<WarmStart>& w = ws.states;
        if (k < 0) k += static_cast<long long>(w.size());
        if (k < 0 || k >= static_cast<long long>(w.size())) throw py::index_error("WarmStarts index out of range");
        return w[static_cast<std::size_t>(k)];
      }, "A copy of row k's state (a WarmStart).")
      .def("__setitem__", [](PyWarmStarts& ws, long long k, const WarmStart& s) {
        std::vector<WarmStart>& w = ws.states;
        if (k < 0) k += static_cast<long long>(w.size());
        if (k < 0 || k >= static_cast<long long>(w.size())) throw py::index_error("WarmStarts index out of range");
        w[static_cast<std::size_t>(k)] = s;
      })
      .def("__repr__", [](const PyWarmStarts& w) {
        std::size_t v = 0;
        for (const WarmStart& s : w.states) v += s.valid ? 1 : 0;
        return "WarmStarts(n=" + std::to_string(w.states.size()) + ", valid=" + std::to_string(v) + ")";
      })
      .def(py::pickle(
          [](const PyWarmStarts& w) {
            py::list items;
            for (const WarmStart& s : w.states) items.append(py::cast(s));
            return items;
          },
          [](const py::list& items) {
            PyWarmStarts w;
            for (std::size_t k = 0; k < items.size(); ++k) {
              if (!py::isinstance<WarmStart>(items[k]))
                throw py::value_error("WarmStarts state: item " + std::to_string(k) + " is not a WarmStart");
              w.states.push_back(items[k].cast<WarmStart>());
            }
            return w;
          }));
  pickle_at_every_protocol(cls);
}

void bind_scene(py::module_& m) {
  py::class_<PyContacts> contacts(m, "Contacts",
                                  "The contacts of Scene.update: one row per candidate pair of the broad phase, "
                                  "sorted by (body1, body2), arrays read-only.");
  for (const auto& f : kContactFields) {
    const std::string name = f[0];
    contacts.def_property_readonly(f[0], [name](const PyContacts& c) -> py::object { return c.arrays[name.c_str()]; },
                                   f[1]);
  }
  contacts.def("__len__", [](const PyContacts& c) { return py::len(c.arrays["body1"]); })
      .def("__repr__", [](const PyContacts& c) {
        const auto a = c.arrays["active"].cast<py::array_t<bool>>();
        std::size_t active = 0;
        for (py::ssize_t k = 0; k < a.size(); ++k) active += a.data()[k] ? 1 : 0;
        return "Contacts(candidates=" + std::to_string(a.size()) + ", active=" + std::to_string(active) + ")";
      });
  forbid_new(contacts);
  forbid_pickle(contacts, "its arrays (np.asarray(contacts.f_n), ...)");

  py::class_<PyScene> cls(
      m, "Scene",
      "Many bodies: world poses in, contacts out (C++ idcol::Scene). update() runs the broad phase (outer "
      "spheres), the narrow phase as one batch (each pair warm-started from its last update, keyed by the pair) "
      "and returns Contacts: both bodies' Hertz wrenches and, with derivatives=True, their Jacobians w.r.t. both "
      "bodies' world poses (body twists, perturbed on the right).");
  cls.def(py::init([](py::handle shapes, const py::object& contact, const py::object& options,
                      const std::string& broad_phase, bool warm_start, int threads) {
            auto s = std::make_unique<PyScene>(scene_options(options, contact, broad_phase, warm_start, threads));
            for (Shape& sh : shape_list(shapes, "shapes")) s->scene.add_body(std::move(sh));
            return s;
          }),
          py::arg("shapes"), py::kw_only(), py::arg("contact") = py::none(), py::arg("options") = py::none(),
          py::arg("broad_phase") = "auto", py::arg("warm_start") = true, py::arg("threads") = 1,
          "shapes: the bodies (body k = shapes[k]); contact: HertzModel (None: HertzModel()); options: "
          "SolverOptions of the narrow phase (None: the defaults with alpha_max = 1: a pair certified apart stops "
          "before any Newton step); broad_phase: 'auto', 'all_pairs', 'sweep_and_prune' or 'tree'.")
      .def_property_readonly("num_bodies", [](const PyScene& s) { return s.scene.num_bodies(); })
      .def("update", [](PyScene& s, py::handle R, py::handle p, bool derivatives) {
            const std::vector<Pose> X = world_pose_list(R, p, static_cast<std::size_t>(s.scene.num_bodies()));
            {
              py::gil_scoped_release release;
              s.scene.update(X, derivatives);
            }
            return contacts_to_numpy(s.scene, derivatives);
          },
          py::arg("R"), py::arg("p"), py::kw_only(), py::arg("derivatives") = false,
          "R (N, 3, 3), p (N, 3): every body's world pose. Returns Contacts.")
      .def("body_wrenches", [](const PyScene& s) {
            std::vector<Vec6> F;
            s.scene.body_wrenches(F);
            py::array_t<double> a({static_cast<py::ssize_t>(F.size()), py::ssize_t{6}});
            for (std::size_t k = 0; k < F.size(); ++k) Eigen::Map<Vec6>(a.mutable_data() + 6 * k) = F[k];
            return frozen(a);
          },
          "(N, 6): the total contact wrench on each body at the last update, in its frame about its origin.")
      .def_property_readonly("last_stats", [](const PyScene& s) { return stats_dict(s.scene.last_stats()); })
      .def("reset_warm_starts", [](PyScene& s) { s.scene.reset_warm_starts(); });
  forbid_pickle(cls, "its shapes and options");

  m.def("broad_phase", [](py::handle centers, py::handle radii_, const std::string& method) {
        const CArray c = float_array(centers, "centers"), r = float_array(radii_, "radii");
        if (c.ndim() != 2 || c.shape(1) != 3) throw py::value_error("centers must have shape (N, 3), got " + shape_str(c));
        if (r.ndim() != 1 || r.shape(0) != c.shape(0))
          throw py::value_error("radii must have shape (" + std::to_string(c.shape(0)) + ",), got " + shape_str(r));
        std::vector<BoundingSphere> s(static_cast<std::size_t>(c.shape(0)));
        for (std::size_t k = 0; k < s.size(); ++k) s[k] = {Eigen::Map<const Vec3>(c.data() + 3 * k), r.data()[k]};
        BroadPhase bp(broad_method(method));
        const std::vector<BodyPair>& pairs = bp.find(s);
        py::array_t<std::int32_t> out({static_cast<py::ssize_t>(pairs.size()), py::ssize_t{2}});
        for (std::size_t k = 0; k < pairs.size(); ++k) out.mutable_data()[2 * k] = pairs[k].i, out.mutable_data()[2 * k + 1] = pairs[k].j;
        return frozen(out);
      },
      py::arg("centers"), py::arg("radii"), py::arg("method") = "auto",
      "The pairs (i, j), i < j, of spheres that overlap (|c_i - c_j| <= r_i + r_j), sorted: a (K, 2) int32 array. "
      "Every method gives the same pairs.");
}

// Long: the module's declarations for the multibody scenes, one statement a
// binding.
void bind_multibody(py::module_& m) {
  py::class_<MassProperties>(m, "MassProperties", "Mass, centre of mass (body frame) and rotational inertia about it.")
      .def(py::init([](double mass, py::handle com, py::handle inertia) {
             MassProperties p;
             p.mass = mass;
             p.com_B = to_vec3(com, "com");
             p.inertia_com_B = to_mat3(inertia, "inertia");
             p.validate();
             return p;
           }),
           py::arg("mass"), py::arg("com"), py::arg("inertia"))
      .def_property_readonly("mass", [](const MassProperties& p) { return p.mass; })
      .def_property_readonly("com", [](const MassProperties& p) { return frozen(to_numpy(p.com_B)); })
      .def_property_readonly("inertia", [](const MassProperties& p) { return frozen(to_numpy(p.inertia_com_B)); })
      .def("spatial_inertia", [](const MassProperties& p) { return frozen(to_numpy(p.spatial_inertia())); },
           "(6, 6) about the frame origin, for twists (w, v).")
      .def("__repr__", [](const MassProperties& p) { return "MassProperties(mass=" + num(p.mass) + ")"; });
  zero_new<MassProperties>();
  forbid_pickle(m.attr("MassProperties"), "its mass, com and inertia");
  m.def("mass_properties", [](py::handle shape, double density, int cells) {
        return mass_properties(*as_shape(shape, "shape").shape, density, cells);
      },
      py::arg("shape"), py::arg("density") = 1.0, py::arg("cells") = 64,
      "Mass properties of the body phi <= 0 at uniform density, by the midpoint rule on cells^3 cells.");

  py::class_<PyMultibody> cls(
      m, "MultibodySystem",
      "Free rigid bodies in frictionless Hertz contact (C++ idcol::MultibodySystem). State y (12 N,): q_i = "
      "(theta_i, p_i) for every body (rotation vector, world position of the frame origin), then eta_i = (w_i, v_i) "
      "(body twists). rhs(y) and jacobian(y) suit any stiff integrator (scipy.integrate.solve_ivp(method='BDF', "
      "jac=...)); simulate() runs the library's NDF integrator.");
  cls.def(py::init([](py::handle shapes, py::handle masses, const py::object& contact, const py::object& options,
                      const std::string& broad_phase, int threads) {
            std::vector<MassProperties> ms;
            std::size_t k = 0;
            for (py::handle h : masses) {
              if (!py::isinstance<MassProperties>(h))
                throw py::type_error("masses[" + std::to_string(k) + "] must be an idcol.MassProperties, got " + type_name(h));
              ms.push_back(h.cast<MassProperties>());
              ++k;
            }
            return std::make_unique<PyMultibody>(shape_list(shapes, "shapes"), std::move(ms),
                                                 scene_options(options, contact, broad_phase, true, threads));
          }),
          py::arg("shapes"), py::arg("masses"), py::kw_only(), py::arg("contact") = py::none(),
          py::arg("options") = py::none(), py::arg("broad_phase") = "auto", py::arg("threads") = 1)
      .def_property_readonly("num_bodies", [](const PyMultibody& s) { return s.system.num_bodies(); })
      .def("state", [](const PyMultibody& s, py::handle R, py::handle p, py::handle eta) {
            const std::size_t n = static_cast<std::size_t>(s.system.num_bodies());
            const std::vector<Pose> X = world_pose_list(R, p, n);
            const CArray e = float_array(eta, "eta", {static_cast<py::ssize_t>(n), 6});
            std::vector<Vec6> tw(n);
            for (std::size_t k = 0; k < n; ++k) tw[k] = Eigen::Map<const Vec6>(e.data() + 6 * k);
            return to_numpy_1d(s.system.state(X, tw));
          },
          py::arg("R"), py::arg("p"), py::arg("eta"), "y from world poses R (N, 3, 3), p (N, 3) and body twists eta (N, 6).")
      .def("poses", [](const PyMultibody& s, py::handle y) {
            return poses_to_numpy(s.system.poses(state_vector(y, s.system.state_size())));
          },
          py::arg("y"), "(R (N, 3, 3), p (N, 3)) of y.")
      .def("rhs", [](PyMultibody& s, py::handle y) {
            const Eigen::VectorXd x = state_vector(y, s.system.state_size());
            Eigen::VectorXd f;
            bool ok;
            {
              py::gil_scoped_release release;
              ok = s.system.rhs(x, f);
            }
            if (!ok) throw py::value_error("rhs: a contact's narrow phase failed at this state (its force is unknown)");
            return to_numpy_1d(f);
          },
          py::arg("y"), "y' (12 N,).")
      .def("jacobian", [](PyMultibody& s, py::handle y) {
            const Eigen::VectorXd x = state_vector(y, s.system.state_size());
            Eigen::MatrixXd J;
            bool ok;
            {
              py::gil_scoped_release release;
              ok = s.system.jacobian(x, J);
            }
            if (!ok) throw py::value_error("jacobian: a contact's narrow phase failed at this state");
            return to_numpy_2d(J);
          },
          py::arg("y"), "dy'/dy (12 N, 12 N), the contact wrenches' Jacobians in it.")
      .def("rechart", [](const PyMultibody& s, py::handle y) {
            Eigen::VectorXd x = state_vector(y, s.system.state_size());
            const bool changed = s.system.rechart(x);
            return py::make_tuple(to_numpy_1d(x), changed);
          },
          py::arg("y"), "(y', changed): every rotation vector longer than pi replaced by the shorter one.")
      .def("momentum", [](const PyMultibody& s, py::handle y) {
            return to_numpy_1d(s.system.momentum(state_vector(y, s.system.state_size())));
          },
          py::arg("y"), "(6,) total momentum in the world: (angular about the origin, linear).")
      .def("kinetic_energy", [](const PyMultibody& s, py::handle y) {
            return s.system.kinetic_energy(state_vector(y, s.system.state_size()));
          },
          py::arg("y"))
      .def("simulate", [](PyMultibody& s, py::handle y0, double t_end, const py::object& outputs, double rtol,
                          double atol, double max_step, bool analytic_jacobian) {
            const Eigen::VectorXd x = state_vector(y0, s.system.state_size());
            std::vector<double> outs;
            if (!outputs.is_none()) {
              const CArray o = float_array(outputs, "outputs");
              outs.assign(o.data(), o.data() + o.size());
            }
            StiffOdeOptions oo;
            oo.rtol = rtol, oo.atol = atol, oo.max_step = max_step;
            MultibodyRun run;
            {
              py::gil_scoped_release release;
              run = simulate(s.system, x, t_end, outs, oo, analytic_jacobian);
            }
            return run_dict(run);
          },
          py::arg("y0"), py::arg("t_end"), py::kw_only(), py::arg("outputs") = py::none(), py::arg("rtol") = 1e-6,
          py::arg("atol") = 1e-8, py::arg("max_step") = INFINITY, py::arg("analytic_jacobian") = true,
          "Integrates from y0 at t = 0 to t_end (NDF orders 1-5, ode15s's method); a dict: status, t (M,), y (M, 12 N) "
          "at 0 and each output time, steps, evaluations, Jacobians, seconds, contacts per step.");
  forbid_pickle(cls, "its shapes and masses");

  m.def("paper_ten_bodies", [](unsigned seed, double radius, double speed) { return body_scene(paper_ten_bodies(seed, radius, speed)); },
        py::arg("seed") = 1, py::arg("radius") = 6.0, py::arg("speed") = 2.0,
        "The paper's ten bodies (cone, cube, cuboid, cylinder, ellipsoid, frustum, polytope, pyramid, sphere, "
        "tetrahedron) on a sphere of `radius`, thrown at the origin at `speed`: a namespace of names, shapes, masses, "
        "R (10, 3, 3), p (10, 3), eta (10, 6).");
  m.def("box_of_bodies", [](int n, unsigned seed, double scale, double jitter, double speed) {
        return body_scene(box_of_bodies(n, seed, scale, jitter, speed));
      },
      py::arg("n"), py::arg("seed") = 1, py::arg("scale") = 0.8, py::arg("jitter") = 0.2, py::arg("speed") = 1.0,
      "n bodies of the ten kinds on a jittered unit lattice (the scaling study's scene), as paper_ten_bodies.");
}

}  // namespace

void bind_physics(py::module_& m) {
  bind_warm_starts(m);
  bind_scene(m);
  bind_multibody(m);
}

}  // namespace idcol::python

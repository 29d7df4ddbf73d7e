// Python bindings of the time of impact (idcol/toi.hpp): the options, the
// status, one query and a batch over many motions that releases the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "bindings.hpp"
#include "idcol/toi.hpp"

namespace py = pybind11;
using namespace idcol;

namespace idcol::python {
namespace {
/// The C++ shape behind a Python idcol shape; a TypeError naming `name` for anything else.
const Shape& idcol_python_shape(py::handle obj, const std::string& name) { return *as_shape(obj, name).shape; }
}  // namespace

namespace {

using CArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string dims(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

CArray as_array(py::handle obj, const std::string& name) {
  py::array a = py::module_::import("numpy").attr("asarray")(obj);
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::value_error(name + " must hold real numbers (float64), got dtype " + std::string(py::str(a.dtype())));
  return CArray::ensure(a);
}

Pose pose_of(py::handle R, py::handle p, const std::string& rn, const std::string& pn) {
  const CArray Ra = as_array(R, rn), pa = as_array(p, pn);
  if (Ra.ndim() != 2 || Ra.shape(0) != 3 || Ra.shape(1) != 3)
    throw py::value_error(rn + " must have shape (3, 3), got " + dims(Ra));
  if (pa.ndim() != 1 || pa.shape(0) != 3) throw py::value_error(pn + " must have shape (3,), got " + dims(pa));
  Pose X;
  X.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(Ra.data());
  X.p = Vec3(pa.data()[0], pa.data()[1], pa.data()[2]);
  return X;
}

ToiOptions toi_options(const py::object& options) {
  if (options.is_none()) return ToiOptions{};
  if (!py::isinstance<ToiOptions>(options))
    throw py::type_error("options must be an idcol.ToiOptions or None, got " +
                         std::string(py::str(py::type::handle_of(options).attr("__name__"))));
  ToiOptions o = options.cast<ToiOptions>();
  o.validate();
  return o;
}

py::array_t<double> row6(const Row6& r) {
  py::array_t<double> a(6);
  std::copy(r.data(), r.data() + 6, a.mutable_data());
  return a;
}

/// Arrays of a batch, one row per motion.
struct PyToiBatch {
  py::array_t<std::int32_t> status, solves;
  py::array_t<double> t, t_free, alpha, dt_dX0, dt_dX1;
  py::array_t<bool> has_derivatives;
};

}  // namespace

void bind_toi(py::module_& m) {
  py::enum_<ToiStatus>(m, "ToiStatus", py::arithmetic(),
                       "How a time-of-impact query ended (C++ idcol::ToiStatus). Batch results hold these as int32 "
                       "codes: idcol.ToiStatus(code).")
      .value("Impact", ToiStatus::Impact, "alpha* reaches 1 at t in (0, 1]; t is the first such time (to t_tolerance).")
      .value("NoImpact", ToiStatus::NoImpact, "alpha* > 1 is certified on the whole of [0, 1].")
      .value("InitiallyInContact", ToiStatus::InitiallyInContact, "alpha*(0) <= 1 + alpha_tolerance.")
      .value("NumericalFailure", ToiStatus::NumericalFailure,
             "A solve failed or t could not resolve the step; certified free up to t_free.")
      .value("IterationLimit", ToiStatus::IterationLimit, "max_solves spent; certified free up to t_free.");

  py::class_<ToiOptions>(m, "ToiOptions",
                         "Options of time_of_impact (C++ idcol::ToiOptions): t_tolerance, alpha_tolerance, max_solves, "
                         "derivatives, solver (an idcol.SolverOptions). Validated when the query runs.")
      .def(py::init([](double t_tolerance, double alpha_tolerance, int max_solves, bool derivatives,
                       const py::object& solver) {
             ToiOptions o;
             o.t_tolerance = t_tolerance;
             o.alpha_tolerance = alpha_tolerance;
             o.max_solves = max_solves;
             o.derivatives = derivatives;
             if (!solver.is_none()) o.solver = solver.cast<SolverOptions>();
             o.validate();
             return o;
           }),
           py::kw_only(), py::arg("t_tolerance") = ToiOptions{}.t_tolerance,
           py::arg("alpha_tolerance") = ToiOptions{}.alpha_tolerance, py::arg("max_solves") = ToiOptions{}.max_solves,
           py::arg("derivatives") = ToiOptions{}.derivatives, py::arg("solver") = py::none())
      .def_readwrite("t_tolerance", &ToiOptions::t_tolerance)
      .def_readwrite("alpha_tolerance", &ToiOptions::alpha_tolerance)
      .def_readwrite("max_solves", &ToiOptions::max_solves)
      .def_readwrite("derivatives", &ToiOptions::derivatives)
      .def_readwrite("solver", &ToiOptions::solver);

  py::class_<ToiResult>(m, "ToiResult",
                        "The first time of contact along a motion. contact is the SolveResult at t (Impact, "
                        "InitiallyInContact), R and p the relative pose there; dt_dX0, dt_dX1 are dt*/d(eta0, eta1) for "
                        "body twists (w, v) applied on the right of the end poses.")
      .def_readonly("status", &ToiResult::status)
      .def_readonly("t", &ToiResult::t)
      .def_readonly("contact", &ToiResult::contact)
      .def_property_readonly("R", [](const ToiResult& r) {
        py::array_t<double> a({3, 3});
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) a.mutable_at(i, j) = r.X_12.R(i, j);
        return a;
      })
      .def_property_readonly("p", [](const ToiResult& r) {
        py::array_t<double> a(3);
        for (int i = 0; i < 3; ++i) a.mutable_at(i) = r.X_12.p[i];
        return a;
      })
      .def_readonly("t_free", &ToiResult::t_free, "alpha* > 1 is certified on [0, t_free].")
      .def_readonly("alpha_rate", &ToiResult::alpha_rate, "d alpha*/dt at t.")
      .def_readonly("has_derivatives", &ToiResult::has_derivatives)
      .def_property_readonly("dt_dX0", [](const ToiResult& r) { return row6(r.dt_dX0); })
      .def_property_readonly("dt_dX1", [](const ToiResult& r) { return row6(r.dt_dX1); })
      .def_readonly("solves", &ToiResult::solves)
      .def_readonly("probes", &ToiResult::probes)
      .def("__repr__", [](const ToiResult& r) {
        return std::string("ToiResult(status=") + to_string(r.status) + ", t=" + std::to_string(r.t) +
               ", solves=" + std::to_string(r.solves) + ")";
      });

  m.def(
      "time_of_impact",
      [](py::handle a, py::handle b, py::handle R0, py::handle p0, py::handle R1, py::handle p1,
         const py::object& options) {
        const Shape& s1 = idcol_python_shape(a, "a");
        const Shape& s2 = idcol_python_shape(b, "b");
        const Pose X0 = pose_of(R0, p0, "R0", "p0"), X1 = pose_of(R1, p1, "R1", "p1");
        const ToiOptions o = toi_options(options);
        py::gil_scoped_release release;
        return time_of_impact(s1, s2, X0, X1, o);
      },
      py::arg("a"), py::arg("b"), py::arg("R0"), py::arg("p0"), py::arg("R1"), py::arg("p1"),
      py::arg("options") = py::none(),
      "First time of contact of body b moving relative to body a from X0 = (R0, p0) at t = 0 to X1 = (R1, p1) at "
      "t = 1 along the screw motion X(t) = X0 exp(t log(X0^-1 X1)) (exactly p0 + t (p1 - p0) when R0 == R1). "
      "Certified: alpha* > 1 on [0, t) is proven, not sampled. Returns a ToiResult; bad poses raise ValueError.");

  py::class_<PyToiBatch>(m, "ToiBatchResult", "Arrays of a time_of_impact_batch, one row per motion.")
      .def_readonly("status", &PyToiBatch::status, "int32 codes of idcol.ToiStatus")
      .def_readonly("t", &PyToiBatch::t)
      .def_readonly("t_free", &PyToiBatch::t_free)
      .def_readonly("alpha", &PyToiBatch::alpha, "alpha* of the contact solve at t (NaN when none)")
      .def_readonly("solves", &PyToiBatch::solves)
      .def_readonly("has_derivatives", &PyToiBatch::has_derivatives)
      .def_readonly("dt_dX0", &PyToiBatch::dt_dX0, "(N, 6)")
      .def_readonly("dt_dX1", &PyToiBatch::dt_dX1, "(N, 6)");

  m.def(
      "time_of_impact_batch",
      [](py::handle a, py::handle b, py::handle R0, py::handle p0, py::handle R1, py::handle p1,
         const py::object& options, int threads) {
        const Shape& s1 = idcol_python_shape(a, "a");
        const Shape& s2 = idcol_python_shape(b, "b");
        const ToiOptions o = toi_options(options);
        const CArray R0a = as_array(R0, "R0"), p0a = as_array(p0, "p0"), R1a = as_array(R1, "R1"),
                     p1a = as_array(p1, "p1");
        for (const auto& [arr, name] : {std::pair<const CArray*, const char*>{&R0a, "R0"}, {&R1a, "R1"}})
          if (arr->ndim() != 3 || arr->shape(1) != 3 || arr->shape(2) != 3)
            throw py::value_error(std::string(name) + " must have shape (N, 3, 3), got " + dims(*arr));
        for (const auto& [arr, name] : {std::pair<const CArray*, const char*>{&p0a, "p0"}, {&p1a, "p1"}})
          if (arr->ndim() != 2 || arr->shape(1) != 3)
            throw py::value_error(std::string(name) + " must have shape (N, 3), got " + dims(*arr));
        const py::ssize_t n = R0a.shape(0);
        if (p0a.shape(0) != n || R1a.shape(0) != n || p1a.shape(0) != n)
          throw py::value_error("R0, p0, R1, p1 must hold the same number of motions, got " + dims(R0a) + ", " +
                                dims(p0a) + ", " + dims(R1a) + ", " + dims(p1a));
        if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores), got " + std::to_string(threads));
        std::vector<ToiResult> res(static_cast<std::size_t>(n));
        std::vector<std::string> errors(static_cast<std::size_t>(n));
        const double *R0d = R0a.data(), *p0d = p0a.data(), *R1d = R1a.data(), *p1d = p1a.data();
        {
          py::gil_scoped_release release;
          auto run = [&](py::ssize_t begin, py::ssize_t end) {
            for (py::ssize_t k = begin; k < end; ++k) {
              Pose X0, X1;
              X0.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R0d + 9 * k);
              X1.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R1d + 9 * k);
              X0.p = Eigen::Map<const Vec3>(p0d + 3 * k);
              X1.p = Eigen::Map<const Vec3>(p1d + 3 * k);
              try {
                res[static_cast<std::size_t>(k)] = time_of_impact(s1, s2, X0, X1, o);
              } catch (const std::exception& e) {
                errors[static_cast<std::size_t>(k)] = e.what();
              }
            }
          };
          int nt = threads == 0 ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency())) : threads;
          nt = static_cast<int>(std::min<py::ssize_t>(nt, std::max<py::ssize_t>(n, 1)));
          if (nt <= 1) {
            run(0, n);
          } else {
            std::vector<std::thread> pool;
            for (int i = 0; i < nt; ++i) pool.emplace_back(run, n * i / nt, n * (i + 1) / nt);
            for (auto& th : pool) th.join();
          }
        }
        for (py::ssize_t k = 0; k < n; ++k)
          if (!errors[static_cast<std::size_t>(k)].empty())
            throw py::value_error("motion " + std::to_string(k) + ": " + errors[static_cast<std::size_t>(k)]);
        PyToiBatch out;
        out.status = py::array_t<std::int32_t>(n);
        out.solves = py::array_t<std::int32_t>(n);
        out.t = py::array_t<double>(n);
        out.t_free = py::array_t<double>(n);
        out.alpha = py::array_t<double>(n);
        out.has_derivatives = py::array_t<bool>(n);
        out.dt_dX0 = py::array_t<double>({n, static_cast<py::ssize_t>(6)});
        out.dt_dX1 = py::array_t<double>({n, static_cast<py::ssize_t>(6)});
        for (py::ssize_t k = 0; k < n; ++k) {
          const ToiResult& r = res[static_cast<std::size_t>(k)];
          out.status.mutable_at(k) = static_cast<std::int32_t>(r.status);
          out.solves.mutable_at(k) = r.solves;
          out.t.mutable_at(k) = r.t;
          out.t_free.mutable_at(k) = r.t_free;
          const bool has_contact = r.status == ToiStatus::Impact || r.status == ToiStatus::InitiallyInContact;
          out.alpha.mutable_at(k) = has_contact ? r.contact.alpha : std::nan("");
          out.has_derivatives.mutable_at(k) = r.has_derivatives;
          for (int i = 0; i < 6; ++i) {
            out.dt_dX0.mutable_at(k, i) = r.has_derivatives ? r.dt_dX0[i] : std::nan("");
            out.dt_dX1.mutable_at(k, i) = r.has_derivatives ? r.dt_dX1[i] : std::nan("");
          }
        }
        return out;
      },
      py::arg("a"), py::arg("b"), py::arg("R0"), py::arg("p0"), py::arg("R1"), py::arg("p1"),
      py::arg("options") = py::none(), py::arg("threads") = 1,
      "time_of_impact over N motions: R0, R1 (N, 3, 3), p0, p1 (N, 3). The GIL is released; threads > 1 splits the "
      "rows in contiguous chunks (0: all cores); each row's answer does not depend on the thread count. A bad row "
      "raises ValueError naming its index. Returns a ToiBatchResult of arrays.");
}

}  // namespace idcol::python

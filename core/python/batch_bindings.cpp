// Python bindings: solve_batch and BatchResult.
#include <sstream>
#include <string>

#include "bindings.hpp"
#include "idcol/batch.hpp"

namespace idcol::python {

namespace {

/// One shape for every row, or a sequence (list, tuple, NumPy object array)
/// of N shapes.
/// `keep` holds a reference to every shape used, so that no shape can be
/// freed while the GIL is released (another thread emptying the list).
void gather(py::handle obj, const char* name, std::size_t n, std::vector<const Shape*>& out,
            std::vector<std::shared_ptr<const Shape>>& keep) {
  if (py::isinstance<PyShape>(obj)) {
    keep.push_back(obj.cast<const PyShape&>().shape);
    out.assign(1, keep.back().get());
    return;
  }
  if (!py::isinstance<py::sequence>(obj) || py::isinstance<py::str>(obj))
    throw py::type_error(std::string(name) + " must be an idcol shape or a sequence of one shape per pose, got " +
                         std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(obj);
  if (seq.size() != n)
    throw py::value_error(std::string(name) + " holds " + std::to_string(seq.size()) + " shapes but R and p hold " +
                          std::to_string(n) + " poses");
  out.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::shared_ptr<const Shape>& s = as_shape(seq[k], std::string(name) + "[" + std::to_string(k) + "]").shape;
    if (keep.empty() || keep.back() != s) keep.push_back(s);
    out[k] = s.get();
  }
}

std::pair<CArray, CArray> batch_poses(py::handle R, py::handle p) {
  CArray Ra = rotations(R, "R", true), pa = float_array(p, "p");
  if (pa.ndim() != 2 || pa.shape(1) != 3) throw py::value_error("p must have shape (N, 3), got " + shape_str(pa));
  if (Ra.shape(0) != pa.shape(0))
    throw py::value_error("R holds " + std::to_string(Ra.shape(0)) + " poses but p holds " + std::to_string(pa.shape(0)));
  return {Ra, pa};
}

PyBatchResult run_batch(const std::vector<const Shape*>& b1, const std::vector<const Shape*>& b2, const CArray& R,
                        const CArray& p, bool warm_start, bool derivatives, int threads, const py::object& options,
                        long long warm_chain) {
  BatchOptions o;
  o.solver = options_or_default(options);
  o.warm_start = warm_start;
  o.derivatives = derivatives;
  o.threads = threads;
  if (warm_chain < 1) throw py::value_error("warm_chain must be >= 1, got " + std::to_string(warm_chain));
  o.warm_chain = static_cast<std::size_t>(warm_chain);
  o.validate();
  const auto n = static_cast<py::ssize_t>(p.shape(0));
  PyBatchResult r;
  r.alpha = py::array_t<double>(n);
  r.x = py::array_t<double>({n, py::ssize_t(3)});
  r.status = py::array_t<std::int32_t>(n);
  r.iterations = py::array_t<std::int32_t>(n);
  py::array_t<double> d;
  if (derivatives) d = py::array_t<double>({n, py::ssize_t(6)});
  const std::size_t N = static_cast<std::size_t>(n);
  BatchOutput out{{r.alpha.mutable_data(), N},
                  {r.x.mutable_data(), 3 * N},
                  {r.status.mutable_data(), N},
                  {r.iterations.mutable_data(), N},
                  {derivatives ? d.mutable_data() : nullptr, derivatives ? 6 * N : 0}};
  const Span<const Shape* const> s1(b1.data(), b1.size()), s2(b2.data(), b2.size());
  const Span<const double> Rs(R.data(), 9 * N), ps(p.data(), 3 * N);
  {
    py::gil_scoped_release release;
    solve_batch(s1, s2, Rs, ps, o, out);
  }
  r.converged = py::array_t<bool>(n);
  for (std::size_t k = 0; k < N; ++k)
    r.converged.mutable_data()[k] = r.status.data()[k] == static_cast<std::int32_t>(SolveStatus::Converged);
  if (derivatives) r.dalpha_dxi = d;
  return r;
}

}  // namespace

void bind_batch(py::module_& m) {
  // --- Batch ----------------------------------------------------------------
  py::class_<PyBatchResult>(
      m, "BatchResult",
      "Arrays of a batch, one row per pose: alpha (N,), x (N, 3) body-1 frame, status (N,) int32 codes of "
      "SolveStatus, iterations (N,) int32, converged (N,) bool, and dalpha_dxi (N, 6) (w, v) with "
      "derivatives=True (None otherwise; zero rows where not converged).")
      .def_readonly("alpha", &PyBatchResult::alpha)
      .def_readonly("x", &PyBatchResult::x)
      .def_readonly("status", &PyBatchResult::status)
      .def_readonly("iterations", &PyBatchResult::iterations)
      .def_readonly("converged", &PyBatchResult::converged)
      .def_readonly("dalpha_dxi", &PyBatchResult::dalpha_dxi)
      .def("__len__", [](const PyBatchResult& r) { return r.alpha.shape(0); });

  const char* batch_doc =
      "Solve N queries in one call, with the GIL released, over `threads` worker threads (0 = every CPU this "
      "process may use) in contiguous chunks (C++ idcol::solve_batch). R: (N, 3, 3) rotations R_12, p: (N, 3) "
      "translations p_12 (length units of the shapes), body 2 in body 1's frame, any layout and any real dtype: "
      "float32/float16 rotations are re-orthonormalised within 16 epsilons of their type (ValueError naming the "
      "row beyond it), integers converted; complex, bool and object arrays are a TypeError. Bodies: `a` and "
      "`b` are each one shape for every row or a sequence of N shapes (mixed families are fine); or give "
      "`pairs`, a sequence of N (a, b) tuples.\n\n"
      "warm_start=True warm-starts each row from the previous one inside chains of `warm_chain` rows (reset at "
      "each chain start and where the pair changes), so results never depend on `threads`: they equal the serial "
      "loop of idcol.solve (cold) or of ContactPair.solve restarted every warm_chain rows (warm), bit for bit. "
      "derivatives=True also returns dalpha_dxi (N, 6). Returns a BatchResult.";
  m.def(
      "solve_batch",
      [](py::handle pairs, py::handle R, py::handle p, bool warm_start, bool derivatives, int threads,
         const py::object& options, long long warm_chain) {
        const auto [Ra, pa] = batch_poses(R, p);
        const std::size_t n = static_cast<std::size_t>(pa.shape(0));
        if (!py::isinstance<py::sequence>(pairs))
          throw py::type_error("pairs must be a sequence of (a, b) shape tuples");
        const py::sequence seq = py::reinterpret_borrow<py::sequence>(pairs);
        if (seq.size() != n)
          throw py::value_error("pairs holds " + std::to_string(seq.size()) + " pairs but R and p hold " +
                                std::to_string(n) + " poses");
        std::vector<const Shape*> b1(n), b2(n);
        std::vector<std::shared_ptr<const Shape>> keep;  // alive while the GIL is released
        for (std::size_t k = 0; k < n; ++k) {
          const py::object item = seq[k];
          const std::string at = "pairs[" + std::to_string(k) + "]";
          if (!py::isinstance<py::sequence>(item) || py::len(item) != 2)
            throw py::type_error(at + " must be an (a, b) tuple of shapes");
          const auto& s1 = as_shape(item[py::int_(0)], at + "[0]").shape;
          const auto& s2 = as_shape(item[py::int_(1)], at + "[1]").shape;
          if (keep.size() < 2 || keep[keep.size() - 2] != s1 || keep.back() != s2) keep.push_back(s1), keep.push_back(s2);
          b1[k] = s1.get();
          b2[k] = s2.get();
        }
        return run_batch(b1, b2, Ra, pa, warm_start, derivatives, threads, options, warm_chain);
      },
      py::arg("pairs"), py::arg("R"), py::arg("p"), py::arg("warm_start") = false, py::arg("derivatives") = false,
      py::arg("threads") = 0, py::arg("options") = py::none(), py::arg("warm_chain") = 1024, batch_doc);
  m.def(
      "solve_batch",
      [](py::handle a, py::handle b, py::handle R, py::handle p, bool warm_start, bool derivatives, int threads,
         const py::object& options, long long warm_chain) {
        const auto [Ra, pa] = batch_poses(R, p);
        const std::size_t n = static_cast<std::size_t>(pa.shape(0));
        std::vector<const Shape*> b1, b2;
        std::vector<std::shared_ptr<const Shape>> keep;  // alive while the GIL is released
        gather(a, "a", n, b1, keep);
        gather(b, "b", n, b2, keep);
        return run_batch(b1, b2, Ra, pa, warm_start, derivatives, threads, options, warm_chain);
      },
      py::arg("a"), py::arg("b"), py::arg("R"), py::arg("p"), py::arg("warm_start") = false,
      py::arg("derivatives") = false, py::arg("threads") = 0, py::arg("options") = py::none(),
      py::arg("warm_chain") = 1024, batch_doc);
}

}  // namespace idcol::python

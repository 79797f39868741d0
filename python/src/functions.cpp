// vitri.Rbf and vitri.LocalRbf: the variational implicit functions (rbf/), fitted to constraints,
// evaluated on (n, 3) arrays with the GIL released, edited in place.
#include "common.hpp"

#include "vitri/rbf/editable_function.hpp"
#include "vitri/rbf/local_rbf.hpp"
#include "vitri/rbf/rbf.hpp"

#include <memory>

namespace vitri::python {
namespace {

/// A fitted function and the mutex of its long calls.
template <class F>
struct Function {
  std::unique_ptr<F> f;
  std::unique_ptr<std::mutex> mutex = std::make_unique<std::mutex>();
};

Constraints constraints_arg(py::handle points, py::handle values) {
  Constraints c;
  c.points = points_arg(points, "points");
  c.values = values_arg(values, "values", c.points.size(), true);
  return c;
}

/// f at one point (3,) -> float, or at (n, 3) points -> (n,) array.
template <class F>
py::object value(Function<F>& s, py::handle x) {
  const py::array a = py::array(py::module_::import("numpy").attr("asarray")(x));
  if (a.ndim() == 1) {
    const Point3 p = point_arg(a, "x");
    return py::float_(without_gil(*s.mutex, [&] { return s.f->value(p); }));
  }
  std::vector<Point3> pts = points_arg(a, "x", true);
  std::vector<double> out(pts.size());
  without_gil(*s.mutex, [&] { s.f->values(pts.data(), pts.size(), out.data()); });
  return values_out(std::move(out));
}

/// (value, gradient) at one point or (n,) and (n, 3) arrays at n points.
template <class F>
py::tuple value_gradient(Function<F>& s, py::handle x) {
  const py::array a = py::array(py::module_::import("numpy").attr("asarray")(x));
  if (a.ndim() == 1) {
    const Point3 p = point_arg(a, "x");
    Point3 g;
    const double v = without_gil(*s.mutex, [&] { return s.f->value_gradient(p, g); });
    return py::make_tuple(v, points_out({g}).attr("reshape")(3));
  }
  std::vector<Point3> pts = points_arg(a, "x", true);
  std::vector<double> v(pts.size());
  std::vector<Point3> g(pts.size());
  without_gil(*s.mutex, [&] { s.f->values_gradients(pts.data(), pts.size(), v.data(), g.data()); });
  return py::make_tuple(values_out(std::move(v)), points_out(std::move(g)));
}

template <class F>
py::tuple constraints_of(Function<F>& s) {
  Constraints c = without_gil(*s.mutex, [&] { return s.f->constraints(); });
  return py::make_tuple(points_out(std::move(c.points)), values_out(std::move(c.values)));
}

template <class F, class Cls>
void bind_common(Cls& cls) {
  using S = Function<F>;
  cls.def("__call__", &value<F>, py::arg("x"), "f(x): value at one point (3,) or at (n, 3) points -> (n,).")
      .def("value", &value<F>, py::arg("x"), "The value at one point (3,) -> float or at (n, 3) points -> (n,).")
      .def("gradient", [](S& s, py::handle x) { return py::object(value_gradient<F>(s, x)[1]); }, py::arg("x"),
           "The gradient at one point (3,) -> (3,) or at (n, 3) points -> (n, 3).")
      .def("value_gradient", &value_gradient<F>, py::arg("x"),
           "(value, gradient) at one point, or ((n,), (n, 3)) at n points, in one pass.")
      .def("__len__", [](S& s) { return s.f->size(); }, "The number of constraints.")
      .def("constraints", &constraints_of<F>, "The current constraints as (points (n, 3), values (n,)).")
      .def("add",
           [](S& s, py::handle p, double v) {
             const Point3 q = point_arg(p, "point");
             return without_gil(*s.mutex, [&] {
               const ConstraintId id = s.f->next_id();
               s.f->add_constraint(q, v);
               return id;
             });
           },
           py::arg("point"), py::arg("value"),
           "Adds the constraint f(point) = value; returns its stable id (one more than the last given out).")
      .def("move",
           [](S& s, ConstraintId i, py::handle p) {
             const Point3 q = point_arg(p, "point");
             without_gil(*s.mutex, [&] { s.f->move_constraint(i, q); });
           },
           py::arg("id"), py::arg("point"), "Moves constraint `id` to `point` (keeps its value and id).")
      .def("remove", [](S& s, ConstraintId i) { without_gil(*s.mutex, [&] { s.f->remove_constraint(i); }); },
           py::arg("id"), "Removes constraint `id`; every other id stays as it was.")
      .def("set_value",
           [](S& s, ConstraintId i, double v) { without_gil(*s.mutex, [&] { s.f->set_value(i, v); }); },
           py::arg("id"), py::arg("value"), "Changes the value of constraint `id`.")
      .def("ids",
           [](S& s) {
             const std::vector<ConstraintId> ids = without_gil(*s.mutex, [&] { return s.f->constraint_ids(); });
             return py::array_t<std::uint64_t>(py::ssize_t(ids.size()), ids.data());
           },
           "The ids of the live constraints (n,) uint64, increasing: the rows of constraints(). fit() numbers "
           "the constraints 0..n-1 in the order given; an id is valid until removed, never reused.")
      .def("__contains__", [](S& s, ConstraintId id) { return s.f->contains(id); }, py::arg("id"))
      .def("constraint",
           [](S& s, ConstraintId id) {
             const auto pv = without_gil(*s.mutex, [&] { return std::make_pair(s.f->point(id), s.f->value_of(id)); });
             return py::make_tuple(points_out({pv.first}).attr("reshape")(3), pv.second);
           },
           py::arg("id"), "(point (3,), value) of constraint `id`. UnknownConstraint if it names none.");
}

}  // namespace

void bind_functions(py::module_& m) {
  using G = Function<Rbf>;
  py::class_<G> rbf(m, "Rbf",
                    "The global variational implicit function (vitri::Rbf): the cubic RBF interpolant with a "
                    "linear polynomial through the constraints f(points[i]) = values[i] (f < 0 inside). "
                    "O(n^2) memory, O(n^3) fit; exact edits in O(n^2).");
  rbf.def(py::init([](py::handle points, py::handle values, unsigned threads, const std::string& solver) {
            Constraints c = constraints_arg(points, values);
            RbfOptions o;
            o.threads = threads;
            if (solver == "cholesky") o.solver = RbfSolver::Cholesky;
            else if (solver == "lu") o.solver = RbfSolver::FullLu;
            else throw InvalidArgument("solver must be 'cholesky' or 'lu', got '" + solver + "'");
            G g;
            {
              py::gil_scoped_release release;
              g.f = std::make_unique<Rbf>(c, o);
            }
            return g;
          }),
          py::arg("points"), py::arg("values"), py::kw_only(), py::arg("threads") = 0u,
          py::arg("solver") = "cholesky",
          "Fits the function to (n, 3) points and their (n,) values (or one value for all).\n"
          "threads: 0 = every available CPU. Raises InvalidPoint (duplicates, non-finite), NumericalError.");
  bind_common<Rbf>(rbf);
  rbf.def("weights", [](G& s) { return values_out(s.f->weights()); }, "The RBF weights (n,).")
      .def("polynomial",
           [](G& s) {
             const Point3 l = s.f->polynomial_linear();
             return py::make_tuple(s.f->polynomial_constant(), points_out({l}).attr("reshape")(3));
           },
           "The polynomial part (c, l): f(x) = sum w_i |x - p_i|^3 + c + l . x.");

  using L = Function<LocalRbf>;
  py::class_<L> local(m, "LocalRbf",
                      "The local variational implicit function (vitri::LocalRbf): a partition of unity of small "
                      "RBF patches over an octree (docs/local_rbf.md). O(n) memory and fit, local edits; "
                      "for 10^4 to 10^6+ constraints.");
  local.def(py::init([](py::handle points, py::handle values, double smoothing, std::size_t max_per_patch,
                        std::size_t min_per_patch, double overlap, unsigned threads) {
              Constraints c = constraints_arg(points, values);
              LocalRbfOptions o;
              o.smoothing = smoothing;
              o.max_per_patch = max_per_patch;
              o.min_per_patch = min_per_patch;
              o.overlap = overlap;
              o.threads = threads;
              L l;
              {
                py::gil_scoped_release release;
                l.f = std::make_unique<LocalRbf>(c, o);
              }
              return l;
            }),
            py::arg("points"), py::arg("values"), py::kw_only(), py::arg("smoothing") = 0.0,
            py::arg("max_per_patch") = std::size_t(48), py::arg("min_per_patch") = std::size_t(16),
            py::arg("overlap") = 1.2, py::arg("threads") = 0u,
            "Fits the local function to (n, 3) points and (n,) values. smoothing > 0 approximates "
            "instead of interpolating (every patch regularized); threads: 0 = every available CPU.");
  bind_common<LocalRbf>(local);
}

}  // namespace vitri::python

// tspline.poisson and tspline.Solution: the adaptive IGA Poisson solver
// (tspline/analysis/poisson.h) on every map, one patch or many, as `tspline
// poisson` with the direct solver.
#include "tspline/analysis/poisson.h"

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <memory>

#include "expression.h"
#include "maps.h"
#include "tspline/analysis/manufactured_problems.h"
#include "tspline/errors.h"

namespace tspline_python {
namespace {

using namespace pybind11::literals;

/// f, g, exact: an expression string (muParser, as on the command line) or a
/// Python callable f(x, y) -> float (called with the GIL held).
tspline::ScalarField field(const char* name, const py::object& f) {
  if (f.is_none()) return {};
  if (py::isinstance<py::str>(f)) return tspline_app::make_field(name, f.cast<std::string>());
  if (!PyCallable_Check(f.ptr()))
    throw py::type_error(std::string(name) + ": expected a string or a callable");
  auto fn = std::make_shared<py::function>(f.cast<py::function>());
  return [fn](double x, double y) {
    py::gil_scoped_acquire gil;
    return (*fn)(x, y).cast<double>();
  };
}

/// The maps a solve runs on: a tspline.Map, or every patch of a T-spline file (version 1 or 2).
std::shared_ptr<Map> solve_map(const py::object& m) {
  if (py::isinstance<Map>(m)) return m.cast<std::shared_ptr<Map>>();
  if (!path_of(m)) throw py::type_error("poisson: map must be a tspline.Map or the path of a T-spline file");
  return py::module_::import("tspline").attr("load")(m).cast<std::shared_ptr<Map>>();
}

struct Solution {
  std::shared_ptr<Map> map;  // keeps the geometry alive
  tspline::AnalysisGeometry geometry;
  tspline::PoissonSolution solution;
  py::list steps;
  py::object problem;  // the built-in problem's formulas, or None
};

py::dict step_dict(const tspline::PoissonStep& s) {
  return py::dict("step"_a = s.step, "dofs"_a = s.dofs, "cells"_a = s.cells, "eta"_a = s.eta,
                  "l2"_a = s.has_errors ? py::cast(s.errors.l2) : py::none(),
                  "h1"_a = s.has_errors ? py::cast(s.errors.h1) : py::none(), "solver"_a = s.solver.kind,
                  "relative_residual"_a = s.solver.relative_residual, "seconds"_a = s.seconds,
                  "marked"_a = s.marked, "refined"_a = s.refined,
                  "max_interface_jump"_a = s.max_interface_jump);
}

std::shared_ptr<Solution> poisson(const py::object& map, const py::object& f, const py::object& g,
                                  const py::object& exact, const py::object& problem_name, int steps,
                                  const std::string& refine, double gamma, std::size_t max_dofs) {
  auto out = std::make_shared<Solution>();
  out->map = solve_map(map);
  out->geometry = tspline::AnalysisGeometry(out->map->maps, out->map->interfaces);
  out->problem = py::none();
  tspline::PoissonProblem problem;
  if (!problem_name.is_none()) {
    if (!f.is_none() || !g.is_none() || !exact.is_none())
      throw tspline::InputError("poisson: give problem= or f=, g= (and exact=), not both");
    const tspline::ManufacturedProblem mp =
        tspline::manufactured_problem(problem_name.cast<std::string>(), out->geometry);
    problem = mp.problem;
    out->problem =
        py::dict("name"_a = mp.name, "u"_a = mp.u, "f"_a = mp.f, "g"_a = mp.g, "choice"_a = mp.choice);
  } else {
    problem.f = field("f", f);
    problem.g = field("g", g);
    problem.exact = field("exact", exact);
    if (!problem.f || !problem.g) throw tspline::InputError("poisson: f and g are required (or problem=)");
  }
  tspline::AdaptiveSolveOptions opt;
  if (refine == "uniform")
    opt.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
  else if (refine != "adaptive")
    throw tspline::InputError("refine: expected 'adaptive' or 'uniform', got '" + refine + "'");
  opt.steps = steps, opt.gamma = gamma, opt.max_dofs = max_dofs;
  std::vector<tspline::PoissonStep> records;
  {
    py::gil_scoped_release release;
    records = tspline::solve_adaptive(out->geometry, problem, opt,
                                      [&](const tspline::PoissonStep&, const tspline::PoissonSolution& sol,
                                          const std::vector<double>&) { out->solution = sol; })
                  .steps;
  }
  for (const auto& s : records) out->steps.append(step_dict(s));
  return out;
}

py::array_t<double> evaluate_solution(const Solution& s, const Array& uv, std::size_t patch) {
  if (!s.solution.space) throw tspline::NumericalError("the Poisson solve made no step");
  if (patch >= s.solution.space->num_patches())
    throw tspline::InputError("patch " + std::to_string(patch) + " out of range (the map has " +
                              std::to_string(s.solution.space->num_patches()) + " patches)");
  const std::size_t n = rows_of(uv, "uv");
  py::array_t<double> out(static_cast<py::ssize_t>(n));
  double* o = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i)
    o[i] = tspline::evaluate_solution(s.solution, patch, checked_uv(uv, i)).u;
  return out;
}

}  // namespace

void bind_poisson(py::module_& m) {
  py::class_<Solution, std::shared_ptr<Solution>>(m, "Solution", "The last step of an adaptive Poisson solve")
      .def_readonly("steps", &Solution::steps,
                    "list of dicts, one per solve: step, dofs, cells, eta, l2, h1 (None without an exact "
                    "solution), solver, seconds, marked, refined, max_interface_jump")
      .def_readonly("problem", &Solution::problem,
                    "dict of the built-in problem (name, u, f, g, choice), or None")
      .def_readonly("map", &Solution::map, "tspline.Map: the geometry")
      .def_property_readonly(
          "dofs", [](const Solution& s) { return s.solution.space ? s.solution.space->num_dofs() : 0; },
          "int: degrees of freedom of the last step")
      .def_property_readonly(
          "patches", [](const Solution& s) { return s.geometry.size(); }, "int: patches")
      .def("evaluate", &evaluate_solution, py::arg("uv"), py::arg("patch") = 0,
           "evaluate(uv, patch=0) -> u. uv: #uv by 2 float64 array in the parameter square of patch `patch`; "
           "u: "
           "#uv float64 array, u_h(S_patch(uv)).");

  m.def(
      "poisson", &poisson, py::arg("map"), py::arg("f") = py::none(), py::arg("g") = py::none(),
      py::arg("exact") = py::none(), py::arg("problem") = py::none(), py::arg("steps") = 5,
      py::arg("refine") = "adaptive", py::arg("gamma") = 0.5, py::arg("max_dofs") = 200000,
      "poisson(map, f=None, g=None, exact=None, problem=None, steps=5, refine='adaptive', gamma=0.5, "
      "max_dofs=200000) -> Solution. Adaptive (or uniform) IGA solve of -Laplace u = f, u = g on the "
      "boundary, "
      "as `tspline poisson --solver direct`. map: a tspline.Map of any number of patches, or the path of a "
      "T-spline file. f, g, exact: expressions in x, y (as tspline poisson --f) or callables f(x, y) -> "
      "float; "
      "or problem='sinsin', 'polynomial' or 'gaussian' (tspline poisson --problem: g and the exact solution "
      "given, scaled to the domain).");
}

}  // namespace tspline_python

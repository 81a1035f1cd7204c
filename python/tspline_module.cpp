// Python module `tspline` (pybind11): a thin binding of the parameterization
// (tspline::run_parameterization), T-spline files, map evaluation and the
// adaptive Poisson solver. Arrays are read in place (NumPy float64, C order;
// other dtypes are converted once) and results are written straight into new
// NumPy arrays. Library errors become Python exceptions with the same
// messages: InputError (a ValueError), IoError (an OSError), NumericalError
// (an ArithmeticError).
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>

#include "expression.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/param_output.h"
#include "tspline/io/tspline_file.h"
#include "tspline/validity/map_certification.h"
#include "tspline/analysis/poisson.h"

namespace py = pybind11;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

namespace {

/// A parameterization result or a loaded file: the map, what the file records
/// besides it, and the report (param_report's JSON as a Python dict).
struct Map {
  tspline::TSplineMap map;
  tspline::io::TSplineFileMeta meta;
  py::dict report;
  bool certified_valid = false;
};

py::dict to_dict(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump()).cast<py::dict>();
}

/// The (n, 2) rows of a uv or xy array, checked.
std::size_t rows_of(const Array& a, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 2)
    throw tspline::InputError(std::string(what) + ": expected an array of shape (n, 2)");
  return static_cast<std::size_t>(a.shape(0));
}

Eigen::Vector2d checked_uv(const double* p) {
  if (!(p[0] >= 0.0 && p[0] <= 1.0 && p[1] >= 0.0 && p[1] <= 1.0))
    throw tspline::InputError("uv: parametric point (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) +
                              ") outside [0,1]^2");
  return {p[0], p[1]};
}

template <class T>
T take(py::dict& kw, const char* key, T fallback) {
  if (!kw.contains(key)) return fallback;
  T v = kw[key].cast<T>();
  kw.attr("pop")(key);
  return v;
}

Map parameterize(const py::object& domain, py::kwargs kwargs) {
  py::dict kw(kwargs);
  tspline::ParameterizationOptions opt;
  tspline::AdaptiveOptions adaptive;
  tspline::io::DomainReadOptions dopt;
  if (kw.contains("corners")) {
    const auto c = kw["corners"].cast<std::vector<long long>>();
    if (c.size() != 4) throw tspline::InputError("corners: expected 4 vertex indices");
    opt.corners = std::array<long long, 4>{c[0], c[1], c[2], c[3]};
    kw.attr("pop")("corners");
  }
  if (kw.contains("tol")) opt.tolerance_absolute = take<double>(kw, "tol", 0.0);
  opt.tolerance_relative = take(kw, "tol_rel", opt.tolerance_relative);
  opt.corner_trials = take(kw, "corner_trials", opt.corner_trials);
  opt.initial_level = take(kw, "init_level", opt.initial_level);
  opt.max_level = take(kw, "max_level", opt.max_level);
  opt.smoothing.max_sweeps = take(kw, "max_sweeps", opt.smoothing.max_sweeps);
  opt.smoothing.over_relaxation = take(kw, "omega", opt.smoothing.over_relaxation);
  opt.smoothing.relative_displacement_tolerance = take(kw, "sweep_tol", opt.smoothing.relative_displacement_tolerance);
  adaptive.min_jacobian = take(kw, "min_jacobian", adaptive.min_jacobian);
  adaptive.max_adapt = take(kw, "max_adapt", adaptive.max_adapt);
  adaptive.max_cells = take(kw, "max_cells", adaptive.max_cells);
  opt.max_cells = adaptive.max_cells;  // one budget, as in `tspline param`
  adaptive.optimize_control_points = !take(kw, "no_control_point_optimization", false);
  adaptive.certification.max_depth = take(kw, "cert_depth", adaptive.certification.max_depth);
  if (kw.contains("polygon")) dopt.polygon_index = take<std::size_t>(kw, "polygon", 0);
  if (kw.contains("layer")) dopt.layer = py::str(kw["layer"]).cast<std::string>(), kw.attr("pop")("layer");
  if (kw.contains("feature")) dopt.feature = take<std::size_t>(kw, "feature", 0);
  dopt.planar = take(kw, "planar", false);
  if (!kw.empty())
    throw py::type_error("parameterize: unknown keyword argument '" + py::str(kw.begin()->first).cast<std::string>() +
                         "'");

  tspline::Polygon polygon;
  nlohmann::json input;
  std::string source = "array";
  if (py::isinstance<py::str>(domain) || py::hasattr(domain, "__fspath__")) {
    source = py::str(py::module_::import("os").attr("fspath")(domain)).cast<std::string>();
    tspline::io::DomainInput d = tspline::io::read_domain(source, dopt);
    polygon = std::move(d.outer);
    input = std::move(d.description);
  } else {
    if (dopt.layer || dopt.feature || dopt.polygon_index || dopt.planar)
      throw tspline::InputError("layer, feature, polygon and planar apply to a file, not to an array of vertices");
    const Array a = domain.cast<Array>();
    const std::size_t n = rows_of(a, "polygon");
    const double* p = a.data();
    for (std::size_t i = 0; i < n; ++i) polygon.vertices.emplace_back(p[2 * i], p[2 * i + 1]);
    if (polygon.vertices.size() >= 2 && polygon.vertices.front() == polygon.vertices.back()) polygon.vertices.pop_back();
    for (std::size_t i = 0; i < polygon.vertices.size(); ++i) polygon.file_index.push_back(i);
    input = {{"format", "array"}, {"crs", nullptr}, {"projection", nullptr}, {"holes", 0}};
  }
  tspline::ParameterizationResult r = tspline::run_parameterization(polygon, opt, adaptive, {});
  if (!r.map) throw tspline::NumericalError("the parameterization produced no map");
  nlohmann::json report = tspline::io::param_report(r, source);
  report["input_geometry"] = input;
  tspline::io::TSplineFileMeta meta;
  meta.source = source;
  meta.boundary = r.front.boundary.polygon();
  meta.corners = r.front.boundary.corners().index;
  return Map{std::move(*r.map), std::move(meta), to_dict(report), r.certified_valid()};
}

Map load(const std::string& path) {
  tspline::io::LoadedTSpline t = tspline::io::read_tspline_file(path);
  const bool certified = tspline::certify_map(t.map).certified_valid();
  return Map{std::move(t.map), std::move(t.meta), py::dict(), certified};
}

py::array_t<double> evaluate(const Map& m, const Array& uv) {
  const std::size_t n = rows_of(uv, "uv");
  py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{2}});
  const double* in = uv.data();
  double* o = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d x = m.map.point(checked_uv(in + 2 * i));
    o[2 * i] = x.x(), o[2 * i + 1] = x.y();
  }
  return out;
}

py::array_t<double> jacobian(const Map& m, const Array& uv) {
  const std::size_t n = rows_of(uv, "uv");
  py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{2}, py::ssize_t{2}});
  const double* in = uv.data();
  double* o = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Matrix2d J = m.map.jacobian(checked_uv(in + 2 * i));  // J(r, c) = d x_r / d xi_c
    o[4 * i] = J(0, 0), o[4 * i + 1] = J(0, 1), o[4 * i + 2] = J(1, 0), o[4 * i + 3] = J(1, 1);
  }
  return out;
}

/// f, g, exact: an expression string (muParser, as on the command line) or a
/// Python callable f(x, y) -> float.
tspline::ScalarField field(const char* name, const py::object& f) {
  if (f.is_none()) return {};
  if (py::isinstance<py::str>(f)) return tspline_app::make_field(name, f.cast<std::string>());
  if (!PyCallable_Check(f.ptr())) throw py::type_error(std::string(name) + ": expected a string or a callable");
  auto fn = f.cast<py::function>();
  return [fn](double x, double y) { return fn(x, y).cast<double>(); };
}

/// The maps a solve runs on: a Map, or every patch of a T-spline file (version 1 or 2).
struct SolveGeometry {
  std::shared_ptr<Map> map;
  std::shared_ptr<tspline::io::LoadedMaps> file;
  tspline::AnalysisGeometry geometry;
};

SolveGeometry solve_geometry(const py::object& m) {
  SolveGeometry g;
  if (py::isinstance<Map>(m)) {
    g.map = m.cast<std::shared_ptr<Map>>();
    g.geometry = tspline::AnalysisGeometry(g.map->map);
    return g;
  }
  if (!py::isinstance<py::str>(m) && !py::hasattr(m, "__fspath__"))
    throw py::type_error("poisson: map must be a tspline.Map or the path of a T-spline file");
  const std::string path = py::str(py::module_::import("os").attr("fspath")(m)).cast<std::string>();
  g.file = std::make_shared<tspline::io::LoadedMaps>(tspline::io::read_maps_file(path));
  for (const auto& t : g.file->patches) g.geometry.patches.push_back(&t.map);
  g.geometry.interfaces = g.file->interfaces;
  return g;
}

struct Solution {
  SolveGeometry geometry;  // keeps the maps alive
  tspline::PoissonSolution solution;
  py::list steps;
};

py::dict step_dict(const tspline::PoissonStep& s) {
  py::dict d;
  d["step"] = s.step, d["dofs"] = s.dofs, d["cells"] = s.cells, d["eta"] = s.eta;
  d["l2"] = s.has_errors ? py::cast(s.errors.l2) : py::none();
  d["h1"] = s.has_errors ? py::cast(s.errors.h1) : py::none();
  d["solver"] = s.solver.kind, d["relative_residual"] = s.solver.relative_residual, d["seconds"] = s.seconds;
  d["marked"] = s.marked, d["refined"] = s.refined;
  return d;
}

Solution poisson(const py::object& m, const py::object& f, const py::object& g, const py::object& exact,
                 int steps, const std::string& refine, double gamma, std::size_t max_dofs) {
  tspline::PoissonProblem problem;
  problem.f = field("f", f);
  problem.g = field("g", g);
  problem.exact = field("exact", exact);
  if (!problem.f || !problem.g) throw tspline::InputError("poisson: f and g are required");
  tspline::AdaptiveSolveOptions opt;
  if (refine == "uniform")
    opt.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
  else if (refine != "adaptive")
    throw tspline::InputError("refine: expected 'adaptive' or 'uniform', got '" + refine + "'");
  opt.steps = steps, opt.gamma = gamma, opt.max_dofs = max_dofs;
  Solution out;
  out.geometry = solve_geometry(m);
  const std::vector<tspline::PoissonStep> records = tspline::solve_adaptive(
      out.geometry.geometry, problem, opt,
      [&](const tspline::PoissonStep&, const tspline::PoissonSolution& sol, const std::vector<double>&) {
        out.solution = sol;
      }).steps;
  for (const auto& s : records) out.steps.append(step_dict(s));
  return out;
}

py::array_t<double> evaluate_solution(const Solution& s, const Array& uv, std::size_t patch) {
  const std::size_t n = rows_of(uv, "uv");
  py::array_t<double> out(static_cast<py::ssize_t>(n));
  const double* in = uv.data();
  double* o = out.mutable_data();
  if (!s.solution.space) throw tspline::NumericalError("the Poisson solve made no step");
  if (patch >= s.solution.space->num_patches())
    throw tspline::InputError("patch " + std::to_string(patch) + " out of range (the map has " +
                              std::to_string(s.solution.space->num_patches()) + " patches)");
  for (std::size_t i = 0; i < n; ++i) o[i] = tspline::evaluate_solution(s.solution, patch, checked_uv(in + 2 * i)).u;
  return out;
}

}  // namespace

PYBIND11_MODULE(tspline, m) {
  m.doc() = "T-spline parameterization of 2D domains and isogeometric Poisson solver (thin binding of libtspline)";
  static py::exception<tspline::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<tspline::IoError> io_error(m, "IoError", PyExc_OSError);
  static py::exception<tspline::NumericalError> numerical_error(m, "NumericalError", PyExc_ArithmeticError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const tspline::InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const tspline::IoError& e) {
      PyErr_SetString(io_error.ptr(), e.what());
    } catch (const tspline::NumericalError& e) {
      PyErr_SetString(numerical_error.ptr(), e.what());
    }
  });

  py::class_<Map, std::shared_ptr<Map>>(m, "Map", "A T-spline map of [0,1]^2 onto the domain")
      .def_readonly("certified_valid", &Map::certified_valid, "det J > 0 certified on every Bezier element")
      .def_readonly("report", &Map::report, "report.json of the parameterization as a dict (empty for a loaded file)")
      .def_property_readonly("cells", [](const Map& x) { return x.map.mesh().num_cells(); })
      .def_property_readonly("functions", [](const Map& x) { return x.map.basis().size(); })
      .def("evaluate", &evaluate, py::arg("uv"), "S(uv) for uv of shape (n, 2): array (n, 2)")
      .def("jacobian", &jacobian, py::arg("uv"), "J(uv)[k] = dS/d(xi, eta), shape (n, 2, 2), J[k, r, c] = d x_r / d xi_c")
      .def(
          "save", [](const Map& x, const std::string& path) { tspline::io::write_tspline_file(path, x.map, x.meta); },
          py::arg("path"), "Writes the T-spline file (docs/tspline_format.md)");

  py::class_<Solution>(m, "Solution", "The last step of an adaptive Poisson solve")
      .def_readonly("steps", &Solution::steps, "one dict per solve (dofs, cells, eta, l2, h1, solver, ...)")
      .def_property_readonly("dofs", [](const Solution& s) { return s.solution.space->num_dofs(); })
      .def_property_readonly("patches", [](const Solution& s) { return s.solution.space->num_patches(); })
      .def("evaluate", &evaluate_solution, py::arg("uv"), py::arg("patch") = 0,
           "u_h(S_patch(uv)) for uv of shape (n, 2) in the parameter square of patch `patch`: array (n,)");

  m.def("parameterize", &parameterize, py::arg("domain"),
        "parameterize(domain, **options) -> Map. domain: an (n, 2) array of polygon vertices, or a file path (text "
        "polygon or any GIS polygon layer). Options as on the command line (tspline param), '-' as '_': corners, "
        "tol, tol_rel, corner_trials, init_level, max_level, max_sweeps, omega, sweep_tol, min_jacobian, max_adapt, "
        "max_cells, no_control_point_optimization, cert_depth, polygon, layer, feature, planar.");
  m.def("load", &load, py::arg("path"), "Reads a T-spline file; certified_valid is recomputed");
  m.def("poisson", &poisson, py::arg("map"), py::arg("f"), py::arg("g"), py::arg("exact") = py::none(),
        py::arg("steps") = 5, py::arg("refine") = "adaptive", py::arg("gamma") = 0.5, py::arg("max_dofs") = 200000,
        "Adaptive IGA solve of -Laplace u = f, u = g on the boundary. map: a Map, or the path of a T-spline file "
        "of one or more patches (tspline.json of `tspline param`; C0 across the interfaces). f, g, exact: "
        "expressions in x, y (as tspline poisson --f) or callables f(x, y).");
}

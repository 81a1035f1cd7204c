// tspline.meshopt: libmeshopt on CAD models through Gmsh, as the meshopt
// program (meshopt_runs.h: the same runs, files and reports), where the build
// has Gmsh; without it, tspline.meshopt.available is False and the functions
// raise tspline.InputError saying so.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>

#include "bindings.h"
#include "tspline/errors.h"
#ifdef TSPLINE_PYTHON_MESHOPT
#include "meshopt_runs.h"
#include "progress.h"
#endif

namespace tspline_python {
namespace {

using Path = std::filesystem::path;
using OptPath = std::optional<Path>;

std::string text(const OptPath& p) { return p ? p->string() : std::string(); }

#ifdef TSPLINE_PYTHON_MESHOPT
constexpr bool kAvailable = true;

py::object smooth(const Path& model, const Path& out, const OptPath& mesh, const std::string& measure,
                  const std::optional<std::string>& size, const OptPath& vtu, const OptPath& report,
                  int max_sweeps, double tol) {
  meshopt_app::SmoothArgs a;
  a.model = model.string(), a.out = out.string(), a.mesh = text(mesh), a.measure = measure;
  a.size = size.value_or(""), a.vtu = text(vtu), a.report = text(report);
  a.max_sweeps = max_sweeps, a.tol = tol, a.quiet = true;
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    j = meshopt_app::smooth_model(a);
  }
  return to_python(j);
}

py::object remesh(const Path& model, const Path& out, const std::optional<double>& length,
                  const std::optional<double>& max_deviation, const std::optional<double>& anisotropy,
                  const OptPath& mesh, double feature_angle, double min_angle, int rounds, const OptPath& vtu,
                  const OptPath& report) {
  meshopt_app::RemeshArgs a;
  a.model = model.string(), a.out = out.string(), a.mesh = text(mesh), a.vtu = text(vtu),
  a.report = text(report);
  a.length = length.value_or(0.0), a.max_deviation = max_deviation.value_or(0.0);
  a.anisotropy = anisotropy.value_or(-1.0);
  a.feature_angle = feature_angle, a.min_angle = min_angle, a.rounds = rounds, a.quiet = true;
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    tspline_app::Progress quiet(tspline_app::OutputMode::Quiet);
    j = meshopt_app::remesh_model(a, quiet);
  }
  return to_python(j);
}
#else
constexpr bool kAvailable = false;

[[noreturn]] void unavailable() {
  throw tspline::InputError("tspline.meshopt: this build has no Gmsh (libgmsh-dev; TSPLINE_WITH_GMSH)");
}
py::object smooth(const Path&, const Path&, const OptPath&, const std::string&,
                  const std::optional<std::string>&, const OptPath&, const OptPath&, int, double) {
  unavailable();
}
py::object remesh(const Path&, const Path&, const std::optional<double>&, const std::optional<double>&,
                  const std::optional<double>&, const OptPath&, double, double, int, const OptPath&,
                  const OptPath&) {
  unavailable();
}
#endif

}  // namespace

void bind_meshopt(py::module_& m) {
  py::module_ sub = m.def_submodule(
      "meshopt",
      "Mesh optimization on CAD models (libmeshopt through Gmsh), as the meshopt program: the same runs, "
      "output files and JSON reports");
  sub.attr("available") = kAvailable;
  sub.def(
      "smooth", &smooth, py::arg("model"), py::arg("out"), py::kw_only(), py::arg("mesh") = py::none(),
      py::arg("measure") = "shape", py::arg("size") = py::none(), py::arg("vtu") = py::none(),
      py::arg("report") = py::none(), py::arg("max_sweeps") = 1000, py::arg("tol") = 1e-3,
      "smooth(model, out, *, mesh=None, measure='shape', size=None, vtu=None, report=None, max_sweeps=1000, "
      "tol=1e-3) -> dict. `meshopt smooth`: untangles and smooths the surface mesh of a CAD model (STEP, "
      "IGES, "
      "BRep, .geo; mesh: its mesh with parametric coordinates, else Gmsh meshes it) in parametric space "
      "(Gargallo-Peiro et al.); writes out (.msh), vtu and the report (default: out with extension .json); "
      "returns the report (before/after quality, sweeps, ...). measure: 'shape', 'size' or 'size-shape'; "
      "size: the ideal size as an expression in x, y, z.");
  sub.def(
      "remesh", &remesh, py::arg("model"), py::arg("out"), py::kw_only(), py::arg("length") = py::none(),
      py::arg("max_deviation") = py::none(), py::arg("anisotropy") = py::none(), py::arg("mesh") = py::none(),
      py::arg("feature_angle") = 30.0, py::arg("min_angle") = 20.0, py::arg("rounds") = 3,
      py::arg("vtu") = py::none(), py::arg("report") = py::none(),
      "remesh(model, out, *, length=None, max_deviation=None, anisotropy=None, mesh=None, feature_angle=30, "
      "min_angle=20, rounds=3, vtu=None, report=None) -> dict. `meshopt remesh`: curvature-adapted "
      "anisotropic remeshing in the R^6 embedding (Dassi et al. 2014); give length (L) and/or max_deviation "
      "(D); writes out (.msh), vtu and the report; returns the report.");
}

}  // namespace tspline_python

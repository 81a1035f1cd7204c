#pragma once
// The runs of the meshopt program without their printing: `meshopt smooth`
// (meshopt_smooth.cpp) and `meshopt remesh` (meshopt_remesh.cpp) on a CAD
// model through Gmsh. The program (meshopt_main.cpp, cmd_remesh.cpp) prints
// their reports; the Python module (tspline.meshopt) returns them.
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace tspline_app {
class Progress;
}

namespace meshopt_app {

struct SmoothArgs {
  std::string model, out, mesh, measure = "shape", size, vtu, report;
  int max_sweeps = 1000;
  double tol = 1e-3;
  bool quiet = false;
};

/// (sweep, max relative move, relative objective change, tangled elements) after each sweep.
using SweepProgress = std::function<void(int, double, double, std::size_t)>;

/// Loads MODEL (and MESH, or meshes it with Gmsh), untangles and smooths the
/// surface mesh, writes OUT (and VTU) and the JSON report (REPORT, default OUT
/// with extension .json), and returns that report: model, mesh, measure,
/// surfaces, nodes, free_nodes, elements, before/after quality (tangled, min,
/// max, mean, std), sweeps, converged, seconds, outputs.
/// \throw toolkit::InputError for bad options or models; toolkit::IoError.
nlohmann::json smooth_model(const SmoothArgs& args, const SweepProgress& on_sweep = {});

struct RemeshArgs {
  std::string model, out, mesh, vtu, report;
  double length = 0.0;         ///< 0: derived from max_deviation (see meshopt_remesh.cpp)
  double anisotropy = -1.0;    ///< < 0: the default (see meshopt_remesh.cpp)
  double max_deviation = 0.0;  ///< 0: no cap on the chordal deviation
  double feature_angle = 30.0;
  double min_angle = 20.0;
  int rounds = 3;
  bool quiet = false, json = false;
};

/// Curvature-adapted anisotropic remeshing (Dassi et al. 2014): loads MODEL,
/// remeshes, writes OUT (and VTU) and the JSON report, which it returns.
/// Progress (phases, "meshing with Gmsh") goes to `out`.
/// \throw toolkit::InputError for bad options or models; toolkit::IoError.
nlohmann::json remesh_model(const RemeshArgs& args, tspline_app::Progress& out);

/// meshopt remesh: remesh_model and its summary; the exit code (cmd_remesh.cpp).
int run_remesh(const RemeshArgs& args);

}  // namespace meshopt_app

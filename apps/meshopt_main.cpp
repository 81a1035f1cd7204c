// meshopt: command-line front end of libmeshopt on CAD surfaces.
// Thin by design: it parses options, runs meshopt_runs.h (the model and mesh
// through the Gmsh adapter, smooth_surface or remesh, the outputs), prints the
// summary and maps errors to exit codes.
// Exit codes (apps/exit_codes.h, shared with tspline):
//   exit 0  success
//   exit 1  invalid input (model, mesh, options)
//   exit 2  a file could not be written
//   exit 3  the run finished but elements are still tangled
//   exit 4  unexpected internal error
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "exit_codes.h"
#include "meshopt_runs.h"

#if defined(__SANITIZE_ADDRESS__)
// LeakSanitizer: OpenCASCADE (libTK*, e.g. its STEP reader's static tables) and
// Gmsh keep allocations to the end of the process; suppress leaks whose stack
// passes through those third-party libraries only (our own code stays checked).
extern "C" const char* __lsan_default_suppressions() { return "leak:libTK\nleak:libgmsh\n"; }
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
#endif

namespace {

using meshopt_app::SmoothArgs;

std::string line(const char* name, const nlohmann::json& q) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%-8s tangled %6zu   quality min %.4f max %.4f mean %.4f std %.4f", name,
                q["tangled"].get<std::size_t>(), q["min"].get<double>(), q["max"].get<double>(),
                q["mean"].get<double>(), q["std"].get<double>());
  return buf;
}

int run_smooth(const SmoothArgs& a) {
  meshopt_app::SweepProgress on_sweep;
  if (!a.quiet)
    on_sweep = [](int sweep, double rx, double rf, std::size_t tangled) {
      if (sweep < 10 || sweep % 50 == 0)
        std::cout << "sweep " << sweep + 1 << ": max relative move " << rx << ", relative objective change " << rf
                  << ", tangled " << tangled << std::endl;
    };
  const nlohmann::json j = meshopt_app::smooth_model(a, on_sweep);
  const nlohmann::json& elements = j["elements"];
  const std::string vtu = j["outputs"]["vtu"];
  std::cout << "meshopt smooth: " << j["surfaces"] << " surfaces, " << j["nodes"] << " nodes ("
            << j["free_nodes"] << " free), " << elements["triangles"] << " triangles, "
            << elements["quadrangles"] << " quadrangles\n"
            << line("before", j["before"]) << "\n"
            << line("after", j["after"]) << "\n"
            << j["sweeps"] << " sweeps" << (j["converged"].get<bool>() ? " (converged)" : " (not converged)")
            << ", " << j["seconds"].get<double>() << " s\nwrote " << a.out << (vtu.empty() ? "" : ", " + vtu)
            << ", " << j["outputs"]["report"].get<std::string>() << std::endl;
  const std::size_t tangled = j["after"]["tangled"];
  if (tangled > 0) {
    std::cerr << "error: " << tangled << " elements are still tangled" << std::endl;
    return 3;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"meshopt: untangling and smoothing of surface meshes on CAD models (Gargallo-Peiro et al.)"};
  app.require_subcommand(1);
  SmoothArgs a;
  CLI::App* smooth = app.add_subcommand("smooth", "untangle and smooth the mesh of a CAD model in parametric space");
  smooth->add_option("MODEL", a.model, "CAD model: STEP, IGES, BRep or Gmsh .geo")->required();
  smooth->add_option("--out", a.out, "output mesh (.msh, MSH 4.1 with parametric coordinates)")->required();
  smooth->add_option("--mesh", a.mesh, "input mesh of MODEL with parametric coordinates (default: Gmsh meshes it)");
  smooth->add_option("--measure", a.measure, "shape, size or size-shape (default shape)");
  smooth->add_option("--size", a.size, "ideal element size as an expression in x, y, z (size measures)");
  smooth->add_option("--vtu", a.vtu, "ParaView file with quality and validity per element");
  smooth->add_option("--report", a.report, "JSON report (default: OUT with extension .json)");
  smooth->add_option("--max-sweeps", a.max_sweeps, "at most this many sweeps (default 1000)");
  smooth->add_option("--tol", a.tol, "tolerance of the relative move and objective change (default 1e-3)");
  smooth->add_flag("--quiet", a.quiet, "no per-sweep progress");
  meshopt_app::RemeshArgs r;
  CLI::App* remesh =
      app.add_subcommand("remesh", "curvature-adapted anisotropic remeshing in the R^6 embedding (Dassi et al. 2014)");
  remesh->add_option("MODEL", r.model, "CAD model: STEP, IGES, BRep or Gmsh .geo")->required();
  remesh->add_option("--out", r.out, "output mesh (.msh, MSH 4.1, nodes on their CAD entities)")->required();
  remesh->add_option("--length", r.length, "target edge length L in R^6 (default 160 D with --max-deviation D)");
  remesh->add_option("--max-deviation", r.max_deviation,
                     "D: split triangles whose estimated chordal deviation exceeds D (absolute, model units)");
  remesh->add_option("--anisotropy", r.anisotropy, "s in (x, s n) (default 5 L; 0: isotropic)");
  remesh->add_option("--mesh", r.mesh, "initial mesh of MODEL with parametric coordinates (default: Gmsh meshes it)");
  remesh->add_option("--feature-angle", r.feature_angle,
                     "CAD curves with a larger dihedral angle stay edge chains (degrees, default 30)");
  remesh->add_option("--min-angle", r.min_angle, "theta_min: collapse triangles with a smaller 6D angle (default 20)");
  remesh->add_option("--rounds", r.rounds, "K: rounds of sampling and optimizing (default 3)");
  remesh->add_option("--vtu", r.vtu, "ParaView file with aspect ratio, 6D length / L and curvature alignment");
  remesh->add_option("--report", r.report, "JSON report (default: OUT with extension .json)");
  remesh->add_flag("--json", r.json, "machine-readable progress and result on stdout (NDJSON)");
  remesh->add_flag("--quiet", r.quiet, "no progress or summary");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  }
  try {
    if (remesh->parsed()) return meshopt_app::run_remesh(r);
    return run_smooth(a);
  } catch (...) {
    return tspline_app::report_current_exception("meshopt");
  }
}

// meshopt: command-line front end of libmeshopt on CAD surfaces (issue 5).
// Thin by design: it parses options, loads the model and mesh through the Gmsh
// adapter, calls smooth_surface, writes the outputs and maps errors to exit codes.
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
#include "expression.h"
#include "meshopt_commands.h"
#include "meshopt/gmsh/gmsh_mesh.h"
#include "meshopt/surface_smoother.h"
#include "toolkit/errors.h"
#include "toolkit/io/atomic_file.h"
#include "toolkit/io/vtu_writer.h"

#if defined(__SANITIZE_ADDRESS__)
// LeakSanitizer: OpenCASCADE (libTK*, e.g. its STEP reader's static tables) and
// Gmsh keep allocations to the end of the process; suppress leaks whose stack
// passes through those third-party libraries only (our own code stays checked).
extern "C" const char* __lsan_default_suppressions() { return "leak:libTK\nleak:libgmsh\n"; }
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
#endif

namespace {

using meshopt::ElementQualities;
using meshopt::SurfaceMeasure;

struct SmoothArgs {
  std::string model, out, mesh, measure = "shape", size, vtu, report;
  int max_sweeps = 1000;
  double tol = 1e-3;
  bool quiet = false;
};

SurfaceMeasure parse_measure(const std::string& s) {
  if (s == "shape") return SurfaceMeasure::shape;
  if (s == "size") return SurfaceMeasure::size;
  if (s == "size-shape") return SurfaceMeasure::size_shape;
  throw toolkit::InputError("--measure must be shape, size or size-shape, got '" + s + "'");
}

nlohmann::json stats_json(const ElementQualities& q) {
  return {{"tangled", q.tangled}, {"min", q.min}, {"max", q.max}, {"mean", q.mean}, {"std", q.stddev}};
}

void write_vtu(const std::string& path, const meshopt::gmsh_io::GmshSurfaceMesh& g, const ElementQualities& q,
               const ElementQualities& shape) {
  toolkit::io::VtuMesh v;
  v.points3d = g.mesh.x;
  for (const meshopt::SurfaceElement& el : g.mesh.elements) v.cells.emplace_back(el.v.begin(), el.v.begin() + el.nv);
  v.quads_as_polygons = false;
  v.cell_scalars["quality"] = q.quality;
  v.cell_scalars["shape_quality"] = shape.quality;
  v.cell_ints["valid"] = std::vector<int>(q.valid.begin(), q.valid.end());
  v.cell_ints["surface"] = g.face_tags;
  std::vector<int> free(g.mesh.x.size());
  for (std::size_t i = 0; i < free.size(); ++i) free[i] = g.mesh.free_face[i] >= 0 ? 1 : 0;
  v.point_ints["free"] = free;
  toolkit::io::write_vtu(path, v);
}

std::string line(const char* name, const ElementQualities& q) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%-8s tangled %6zu   quality min %.4f max %.4f mean %.4f std %.4f", name, q.tangled,
                q.min, q.max, q.mean, q.stddev);
  return buf;
}

int run_smooth(const SmoothArgs& a) {
  namespace fs = std::filesystem;
  const SurfaceMeasure measure = parse_measure(a.measure);
  if (a.max_sweeps < 0) throw toolkit::InputError("--max-sweeps must be >= 0");
  if (!(a.tol > 0.0) || !std::isfinite(a.tol)) throw toolkit::InputError("--tol must be positive");
  const std::string report = a.report.empty() ? fs::path(a.out).replace_extension(".json").string() : a.report;
  for (const std::string& f : {a.out, a.vtu, report})
    if (!f.empty()) toolkit::io::ensure_writable_directory(fs::absolute(f).parent_path().string());
  std::optional<tspline_app::Expression> size_expr;
  if (!a.size.empty()) size_expr.emplace("--size", a.size, true);

  meshopt::gmsh_io::Session session;
  meshopt::gmsh_io::open_model(a.model);
  if (a.mesh.empty())
    meshopt::gmsh_io::generate_surface_mesh();
  else
    meshopt::gmsh_io::merge_mesh(a.mesh);
  meshopt::gmsh_io::GmshSurfaceMesh g = meshopt::gmsh_io::read_surface_mesh();

  meshopt::SurfaceSmoothingOptions opt;
  opt.measure = measure;
  opt.max_sweeps = a.max_sweeps;
  opt.tol_x = opt.tol_f = a.tol;
  if (size_expr) opt.size = [&](const Eigen::Vector3d& x) { return (*size_expr)(x.x(), x.y(), x.z()); };
  if (!a.quiet)
    opt.progress = [](int sweep, double rx, double rf, std::size_t tangled) {
      if (sweep < 10 || sweep % 50 == 0)
        std::cout << "sweep " << sweep + 1 << ": max relative move " << rx << ", relative objective change " << rf
                  << ", tangled " << tangled << std::endl;
    };
  std::size_t quads = 0, free_nodes = 0;
  for (const auto& el : g.mesh.elements) quads += el.nv == 4;
  for (int f : g.mesh.free_face) free_nodes += f >= 0;

  const ElementQualities before = meshopt::surface_mesh_quality(g.mesh, measure, opt.size);
  const auto t0 = std::chrono::steady_clock::now();
  const meshopt::SurfaceSmoothingReport rep = meshopt::smooth_surface(g.mesh, opt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const ElementQualities after = meshopt::surface_mesh_quality(g.mesh, measure, opt.size);

  meshopt::gmsh_io::write_mesh(a.out, g);
  if (!a.vtu.empty())
    write_vtu(a.vtu, g, after,
              measure == SurfaceMeasure::shape ? after : meshopt::surface_mesh_quality(g.mesh, SurfaceMeasure::shape));
  const nlohmann::json j = {
      {"model", a.model},
      {"mesh", a.mesh.empty() ? "generated by Gmsh" : a.mesh},
      {"measure", a.measure},
      {"size", a.size},
      {"surfaces", g.faces.size()},
      {"nodes", g.mesh.x.size()},
      {"free_nodes", free_nodes},
      {"elements", {{"triangles", g.mesh.elements.size() - quads}, {"quadrangles", quads}}},
      {"before", stats_json(before)},
      {"after", stats_json(after)},
      {"sweeps", rep.sweeps},
      {"converged", rep.converged},
      {"node_visits", rep.node_visits},
      {"newton_steps", rep.newton_steps},
      {"gradient_fallbacks", rep.gradient_fallbacks},
      {"seconds", seconds},
      {"outputs", {{"mesh", a.out}, {"vtu", a.vtu}}}};
  toolkit::io::write_text_atomic(report, j.dump(2) + "\n");

  std::cout << "meshopt smooth: " << g.faces.size() << " surfaces, " << g.mesh.x.size() << " nodes (" << free_nodes
            << " free), " << g.mesh.elements.size() - quads << " triangles, " << quads << " quadrangles\n"
            << line("before", before) << "\n"
            << line("after", after) << "\n"
            << rep.sweeps << " sweeps" << (rep.converged ? " (converged)" : " (not converged)") << ", " << seconds
            << " s\nwrote " << a.out << (a.vtu.empty() ? "" : ", " + a.vtu) << ", " << report << std::endl;
  if (after.tangled > 0) {
    std::cerr << "error: " << after.tangled << " elements are still tangled" << std::endl;
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

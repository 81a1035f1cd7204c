// meshopt remesh without its summary: curvature-adapted anisotropic
// remeshing of a CAD model's surface (Dassi, Mola & Si 2014) through
// libmeshopt and its Gmsh adapter (meshopt_runs.h).
#include <gmsh.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "meshopt/gmsh/gmsh_mesh.h"
#include "meshopt/gmsh/gmsh_remesh_model.h"
#include "meshopt/remesh.h"
#include "meshopt/remesh_statistics.h"
#include "meshopt_runs.h"
#include "progress.h"
#include "toolkit/errors.h"
#include "toolkit/io/atomic_file.h"
#include "toolkit/io/vtu_writer.h"
#include "toolkit/timing.h"

namespace meshopt_app {
namespace {

using toolkit::Clock;
constexpr auto since = toolkit::seconds_since;

constexpr double kDegree = std::numbers::pi / 180.0;

nlohmann::json histogram_json(const meshopt::Histogram& h) {
  return {{"lo", h.lo}, {"width", h.width}, {"counts", h.counts}};
}

nlohmann::json statistics_json(const meshopt::RemeshStatistics& s) {
  return {{"vertices", s.vertices},
          {"triangles", s.triangles},
          {"length6d_over_L",
           {{"min", s.length_ratio_min},
            {"mean", s.length_ratio_mean},
            {"max", s.length_ratio_max},
            {"histogram", histogram_json(s.length_ratio)}}},
          {"min_angle6d_degrees",
           {{"min", s.min_angle_min},
            {"mean", s.min_angle_mean},
            {"histogram", histogram_json(s.min_angle_degrees)}}},
          {"aspect_ratio3d", {{"min", s.quality_min}, {"mean", s.quality_mean}}}};
}

struct Deviation {
  double max = 0.0, mean = 0.0;
};
Deviation deviation(const std::vector<double>& d) {
  Deviation out;
  for (double x : d) {
    out.max = std::max(out.max, x);
    out.mean += x;
  }
  if (!d.empty()) out.mean /= static_cast<double>(d.size());
  return out;
}

void write_vtu(const std::string& path, const meshopt::RemeshMesh& m, double length, double s,
               const meshopt::gmsh_io::CurvatureAlignment& align,
               const meshopt::gmsh_io::CentroidProjection& centroids) {
  const std::vector<int>& faces = centroids.face;
  toolkit::io::VtuMesh v;
  for (const meshopt::RemeshVertex& x : m.vertices) v.points3d.push_back(x.x);
  std::vector<int> patch, face;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    v.cells.push_back({m.triangles[t].v[0], m.triangles[t].v[1], m.triangles[t].v[2]});
    patch.push_back(m.triangles[t].patch);
    face.push_back(faces[t]);
  }
  v.cell_scalars["aspect_ratio3d"] = meshopt::triangle_aspect_ratios(m);
  v.cell_scalars["length6d_over_L"] = meshopt::triangle_length_ratios(m, length, s);
  v.cell_scalars["angle_to_curvature_direction"] = align.angle_degrees;
  v.cell_scalars["chordal_deviation"] = centroids.distance;
  v.cell_ints["patch"] = patch;
  v.cell_ints["surface"] = face;
  std::vector<int> kind;
  for (const meshopt::RemeshVertex& x : m.vertices) kind.push_back(static_cast<int>(x.kind));
  v.point_ints["kind"] = kind;  // 0 corner, 1 feature curve, 2 surface
  toolkit::io::write_vtu(path, v);
}

// The options' ranges; the report's path (beside --out unless given), every
// output's folder writable.
std::string checked_report_path(const RemeshArgs& a) {
  namespace fs = std::filesystem;
  if (!(a.max_deviation >= 0.0) || !std::isfinite(a.max_deviation))
    throw toolkit::InputError("--max-deviation must be positive");
  if (a.length == 0.0 && a.max_deviation == 0.0) throw toolkit::InputError("give --length or --max-deviation");
  if (a.length != 0.0 && (!(a.length > 0.0) || !std::isfinite(a.length)))
    throw toolkit::InputError("--length must be positive");
  if (a.anisotropy != -1.0 && (!(a.anisotropy >= 0.0) || !std::isfinite(a.anisotropy)))
    throw toolkit::InputError("--anisotropy must be >= 0");
  if (!(a.feature_angle >= 0.0 && a.feature_angle <= 180.0))
    throw toolkit::InputError("--feature-angle must be in [0, 180] degrees");
  if (!(a.min_angle >= 0.0 && a.min_angle < 60.0)) throw toolkit::InputError("--min-angle must be in [0, 60) degrees");
  if (a.rounds < 0) throw toolkit::InputError("--rounds must be >= 0");
  if (fs::path(a.out).extension() != ".msh") throw toolkit::InputError("--out must end in .msh");
  const std::string report = a.report.empty() ? fs::path(a.out).replace_extension(".json").string() : a.report;
  for (const std::string& f : {a.out, a.vtu, report})
    if (!f.empty()) toolkit::io::ensure_writable_directory(fs::absolute(f).parent_path().string());
  return report;
}

// The model opened in the Gmsh session, and its start mesh: --mesh, or
// Gmsh's own.
void open_model_and_start_mesh(const RemeshArgs& a, tspline_app::Progress& out) {
  meshopt::gmsh_io::open_model(a.model);
  if (!a.mesh.empty()) return meshopt::gmsh_io::merge_mesh(a.mesh);
  out.log("meshing " + a.model + " with Gmsh");
  // A start that resolves the curvature (12 elements per 2 pi radius, unless
  // the model sets its own sizing from curvature): on a start coarser than a
  // pipe's radius the split of a bent feature edge would fold a triangle over
  // its opposite corner, is refused, and leaves an outlier of deviation.
  double from_curvature = 0.0;
  gmsh::option::getNumber("Mesh.MeshSizeFromCurvature", from_curvature);
  if (from_curvature == 0.0) gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 12);
  meshopt::gmsh_io::generate_surface_mesh();
}

meshopt::RemeshOptions remesh_options(const RemeshArgs& a, tspline_app::Progress& out) {
  meshopt::RemeshOptions opt;
  // A 3D edge of 6D length L along a direction of normal curvature kappa has
  // h = L / sqrt(1 + s^2 kappa^2) and deviates by kappa h^2 / 8, at most
  // L^2 / (16 s) (at kappa = 1 / s), i.e. L / 80 for s = 5 L. L = 160 D puts that
  // worst case at 2 D, so the deviation cap (which splits) acts only on the
  // curved directions near kappa = 1 / s and the 6D metric shapes the rest;
  // measured on the torus and pipe (bench/README.md), triangles for a given D
  // fall from L = 80 D to 160 D and change by under 5% beyond.
  opt.length = a.length > 0.0 ? a.length : 160.0 * a.max_deviation;
  opt.max_deviation = a.max_deviation;
  // Default s = 5 L: where the surface is curved (s kappa >> 1) an edge of 6D
  // length L turns the normal by about L / s = 0.2 rad (11 degrees), whatever L.
  opt.anisotropy = a.anisotropy >= 0.0 ? a.anisotropy : 5.0 * opt.length;
  opt.min_angle = a.min_angle * kDegree;
  opt.rounds = a.rounds;
  opt.progress = [&out, rounds = opt.rounds](int round, const std::string& phase) {
    out.progress(phase, round, rounds);
    out.event({{"event", "phase"}, {"round", round + 1}, {"phase", phase}});
  };
  return opt;
}

// What remesh_model measured, for its report.
struct RemeshRun {
  meshopt::RemeshStatistics before, after;
  meshopt::RemeshReport operations;
  std::map<int, long> euler_before, euler_after;  // Euler characteristic per patch
  std::size_t non_manifold_edges = 0;
  Deviation deviation;
  double seconds_input = 0.0, seconds_analysis = 0.0, seconds_output = 0.0;
};

nlohmann::json remesh_report(const RemeshArgs& a, const meshopt::RemeshOptions& opt,
                             const meshopt::gmsh_io::GmshRemeshGeometry& geometry, const RemeshRun& r,
                             const std::string& report) {
  nlohmann::json euler = nlohmann::json::array();
  for (const auto& [p, chi] : r.euler_after)
    euler.push_back({{"patch", p}, {"before", r.euler_before.count(p) ? r.euler_before.at(p) : 0}, {"after", chi}});
  const double diagonal = geometry.features().diagonal;
  return {{"model", a.model},
          {"mesh", a.mesh.empty() ? "generated by Gmsh" : a.mesh},
          {"length", opt.length},
          {"anisotropy", opt.anisotropy},
          {"max_deviation", opt.max_deviation},
          {"feature_angle_degrees", a.feature_angle},
          {"min_angle_degrees", a.min_angle},
          {"rounds", opt.rounds},
          {"patches", geometry.features().patch_faces.size()},
          {"feature_curves", geometry.features().feature_curves.size()},
          {"before", statistics_json(r.before)},
          {"after", statistics_json(r.after)},
          {"chordal_deviation",
           {{"max", r.deviation.max},
            {"mean", r.deviation.mean},
            {"max_relative", r.deviation.max / diagonal},
            {"mean_relative", r.deviation.mean / diagonal},
            {"diagonal", diagonal}}},
          {"topology",
           {{"euler_characteristics", euler},
            {"kept", r.euler_before == r.euler_after},
            {"non_manifold_edges", r.non_manifold_edges}}},
          {"operations",
           {{"splits", r.operations.splits},
            {"collapses", r.operations.collapses},
            {"rejected_collapses", r.operations.rejected_collapses},
            {"flips", r.operations.flips},
            {"smoothing_moves", r.operations.smoothing_moves}}},
          {"seconds",
           {{"input", r.seconds_input},
            {"sampling", r.operations.seconds_sampling},
            {"optimizing", r.operations.seconds_optimizing},
            {"analysis", r.seconds_analysis},
            {"output", r.seconds_output}}},
          {"outputs", {{"mesh", a.out}, {"vtu", a.vtu}, {"report", report}}}};
}

}  // namespace

nlohmann::json remesh_model(const RemeshArgs& a, tspline_app::Progress& out) {
  const std::string report = checked_report_path(a);
  RemeshRun r;
  auto t0 = Clock::now();
  meshopt::gmsh_io::Session session;
  open_model_and_start_mesh(a, out);
  meshopt::gmsh_io::GmshRemeshGeometry geometry(meshopt::gmsh_io::detect_features(a.feature_angle * kDegree));
  meshopt::RemeshMesh mesh = meshopt::gmsh_io::read_remesh_mesh(geometry);
  r.seconds_input = since(t0);

  const meshopt::RemeshOptions opt = remesh_options(a, out);
  r.before = meshopt::remesh_statistics(mesh, opt.length, opt.anisotropy);
  r.euler_before = mesh.euler_characteristics();
  r.operations = meshopt::remesh(mesh, geometry, opt);
  r.after = meshopt::remesh_statistics(mesh, opt.length, opt.anisotropy);
  r.euler_after = mesh.euler_characteristics();
  r.non_manifold_edges = mesh.non_manifold_edges();

  t0 = Clock::now();
  const meshopt::gmsh_io::CentroidProjection centroids = meshopt::gmsh_io::project_centroids(mesh, geometry);
  const meshopt::gmsh_io::CurvatureAlignment align = meshopt::gmsh_io::curvature_alignment(mesh, centroids);
  r.deviation = deviation(centroids.distance);
  r.seconds_analysis = since(t0);
  t0 = Clock::now();
  meshopt::gmsh_io::write_remesh_mesh(a.out, mesh, centroids.face);
  if (!a.vtu.empty()) write_vtu(a.vtu, mesh, opt.length, opt.anisotropy, align, centroids);
  r.seconds_output = since(t0);

  const nlohmann::json j = remesh_report(a, opt, geometry, r, report);
  toolkit::io::write_text_atomic(report, j.dump(2) + "\n");
  return j;
}

}  // namespace meshopt_app

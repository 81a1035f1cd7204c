// meshopt remesh without its summary: curvature-adapted anisotropic
// remeshing of a CAD model's surface (Dassi, Mola & Si 2014) through
// libmeshopt and its Gmsh adapter (meshopt_runs.h).
#include <gmsh.h>

#include <chrono>
#include <cmath>
#include <filesystem>
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

}  // namespace

nlohmann::json remesh_model(const RemeshArgs& a, tspline_app::Progress& out) {
  namespace fs = std::filesystem;
  if (!(a.max_deviation >= 0.0) || !std::isfinite(a.max_deviation))
    throw toolkit::InputError("--max-deviation must be positive");
  if (a.length == 0.0 && a.max_deviation == 0.0)
    throw toolkit::InputError("give --length or --max-deviation");
  if (a.length != 0.0 && (!(a.length > 0.0) || !std::isfinite(a.length)))
    throw toolkit::InputError("--length must be positive");
  if (a.anisotropy != -1.0 && (!(a.anisotropy >= 0.0) || !std::isfinite(a.anisotropy)))
    throw toolkit::InputError("--anisotropy must be >= 0");
  if (!(a.feature_angle >= 0.0 && a.feature_angle <= 180.0))
    throw toolkit::InputError("--feature-angle must be in [0, 180] degrees");
  if (!(a.min_angle >= 0.0 && a.min_angle < 60.0))
    throw toolkit::InputError("--min-angle must be in [0, 60) degrees");
  if (a.rounds < 0) throw toolkit::InputError("--rounds must be >= 0");
  if (fs::path(a.out).extension() != ".msh") throw toolkit::InputError("--out must end in .msh");
  const std::string report =
      a.report.empty() ? fs::path(a.out).replace_extension(".json").string() : a.report;
  for (const std::string& f : {a.out, a.vtu, report})
    if (!f.empty()) toolkit::io::ensure_writable_directory(fs::absolute(f).parent_path().string());

  const auto t_start = Clock::now();
  meshopt::gmsh_io::Session session;
  meshopt::gmsh_io::open_model(a.model);
  if (a.mesh.empty()) {
    out.log("meshing " + a.model + " with Gmsh");
    // A start that resolves the curvature (12 elements per 2 pi radius, unless
    // the model sets its own sizing from curvature): on a start coarser than a
    // pipe's radius the split of a bent feature edge would fold a triangle over
    // its opposite corner, is refused, and leaves an outlier of deviation.
    double from_curvature = 0.0;
    gmsh::option::getNumber("Mesh.MeshSizeFromCurvature", from_curvature);
    if (from_curvature == 0.0) gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 12);
    meshopt::gmsh_io::generate_surface_mesh();
  } else {
    meshopt::gmsh_io::merge_mesh(a.mesh);
  }
  meshopt::gmsh_io::GmshRemeshGeometry geometry(meshopt::gmsh_io::detect_features(a.feature_angle * kDegree));
  meshopt::RemeshMesh mesh = meshopt::gmsh_io::read_remesh_mesh(geometry);
  const double seconds_input = since(t_start);

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
  opt.progress = [&](int round, const std::string& phase) {
    out.progress(phase, round, opt.rounds);
    out.event({{"event", "phase"}, {"round", round + 1}, {"phase", phase}});
  };
  const meshopt::RemeshStatistics before = meshopt::remesh_statistics(mesh, opt.length, opt.anisotropy);
  const auto euler_before = mesh.euler_characteristics();
  const meshopt::RemeshReport rep = meshopt::remesh(mesh, geometry, opt);
  const meshopt::RemeshStatistics after = meshopt::remesh_statistics(mesh, opt.length, opt.anisotropy);

  auto t0 = Clock::now();
  const meshopt::gmsh_io::CentroidProjection centroids = meshopt::gmsh_io::project_centroids(mesh, geometry);
  const meshopt::gmsh_io::CurvatureAlignment align = meshopt::gmsh_io::curvature_alignment(mesh, centroids);
  const Deviation dev = deviation(centroids.distance);
  const double seconds_analysis = since(t0);
  t0 = Clock::now();
  meshopt::gmsh_io::write_remesh_mesh(a.out, mesh, centroids.face);
  if (!a.vtu.empty()) write_vtu(a.vtu, mesh, opt.length, opt.anisotropy, align, centroids);
  const double seconds_output = since(t0);

  const auto euler_after = mesh.euler_characteristics();
  nlohmann::json euler = nlohmann::json::array();
  bool topology_kept = euler_before == euler_after;
  for (const auto& [p, chi] : euler_after)
    euler.push_back(
        {{"patch", p}, {"before", euler_before.count(p) ? euler_before.at(p) : 0}, {"after", chi}});
  const std::size_t non_manifold = mesh.non_manifold_edges();
  const nlohmann::json j = {
      {"model", a.model},
      {"mesh", a.mesh.empty() ? "generated by Gmsh" : a.mesh},
      {"length", opt.length},
      {"anisotropy", opt.anisotropy},
      {"max_deviation", opt.max_deviation},
      {"feature_angle_degrees", a.feature_angle},
      {"min_angle_degrees", a.min_angle},
      {"rounds", opt.rounds},
      {"patches", geometry.features().patch_faces.size()},
      {"feature_curves", geometry.features().feature_curves.size()},
      {"before", statistics_json(before)},
      {"after", statistics_json(after)},
      {"chordal_deviation",
       {{"max", dev.max},
        {"mean", dev.mean},
        {"max_relative", dev.max / geometry.features().diagonal},
        {"mean_relative", dev.mean / geometry.features().diagonal},
        {"diagonal", geometry.features().diagonal}}},
      {"topology",
       {{"euler_characteristics", euler}, {"kept", topology_kept}, {"non_manifold_edges", non_manifold}}},
      {"operations",
       {{"splits", rep.splits},
        {"collapses", rep.collapses},
        {"rejected_collapses", rep.rejected_collapses},
        {"flips", rep.flips},
        {"smoothing_moves", rep.smoothing_moves}}},
      {"seconds",
       {{"input", seconds_input},
        {"sampling", rep.seconds_sampling},
        {"optimizing", rep.seconds_optimizing},
        {"analysis", seconds_analysis},
        {"output", seconds_output}}},
      {"outputs", {{"mesh", a.out}, {"vtu", a.vtu}, {"report", report}}}};
  toolkit::io::write_text_atomic(report, j.dump(2) + "\n");
  return j;
}

}  // namespace meshopt_app

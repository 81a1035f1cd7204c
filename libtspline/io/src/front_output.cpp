#include "tspline/io/front_output.h"

#include <filesystem>

#include "toolkit/io/atomic_file.h"
#include "tspline/detail/vtu_fields.h"
#include "tspline/io/output_files.h"

namespace tspline {

// The report's keys are the field names (from_json comes with the macro and is unused).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(MeshQualityStats, cells, inverted_cells, triangles, inverted_triangles,
                                   min_mean_ratio, mean_mean_ratio)

}  // namespace tspline

namespace tspline::io {

toolkit::io::VtuMesh tmesh_vtu(const TMesh& mesh, const std::vector<Eigen::Vector2d>& positions) {
  toolkit::io::VtuMesh out;
  out.points = positions;
  const auto nc = mesh.num_cells();
  out.cells.reserve(nc);
  std::vector<int> level(nc), valid(nc);
  std::vector<double> minq(nc);
  const std::vector<CellQuality> quality = cell_qualities(mesh, positions);
  for (int c = 0; c < static_cast<int>(nc); ++c) {
    out.cells.push_back(mesh.cell_polygon(c));
    level[c] = mesh.cell_level(c);
    valid[c] = quality[c].valid ? 1 : 0;
    minq[c] = quality[c].min_mean_ratio;
  }
  out.cell_ints["level"] = std::move(level);
  out.cell_ints["valid"] = std::move(valid);
  out.cell_scalars["min_quality"] = std::move(minq);
  detail::TMeshPointFields fields;
  fields.reserve(mesh.num_vertices());
  for (int v = 0; v < static_cast<int>(mesh.num_vertices()); ++v)
    fields.push(mesh.vertex_param(v), mesh.vertex_is_hanging(v), mesh.vertex_on_boundary(v));
  fields.attach_to(out);
  return out;
}

toolkit::io::VtuMesh boundary_vtu(const BoundaryMap& boundary) {
  toolkit::io::VtuMesh out;
  const Polygon& p = boundary.polygon();
  const int n = static_cast<int>(p.vertices.size());
  out.points = p.vertices;
  std::vector<int> corner(n, -1), file_index(n);
  for (int k = 0; k < 4; ++k) corner[boundary.corners().index[k]] = k;
  for (int i = 0; i < n; ++i) file_index[i] = static_cast<int>(p.file_index[i]);
  std::vector<int> side;
  int s = -1;
  // Walk the CCW polygon from corner 0: side k runs from corner k to corner k+1.
  const int start = static_cast<int>(boundary.corners().index[0]);
  for (int step = 0; step < n; ++step) {
    const int i = (start + step) % n;
    if (corner[i] >= 0) s = corner[i];
    out.cells.push_back({i, (i + 1) % n});
    side.push_back(s);
  }
  for (int k = 0; k < 4; ++k) {
    out.cells.push_back({static_cast<int>(boundary.corners().index[k])});
    side.push_back(-1);
  }
  out.cell_ints["side"] = std::move(side);
  out.point_ints["corner"] = std::move(corner);
  out.point_ints["file_index"] = std::move(file_index);
  return out;
}

nlohmann::json front_report(const FrontResult& r, const std::string& input_path) {
  using nlohmann::json;
  const Polygon& p = r.boundary.polygon();
  const Corners& c = r.boundary.corners();
  json corners = json::array();
  for (int k = 0; k < 4; ++k) {
    const auto i = c.index[k];
    corners.push_back({{"file_index", p.file_index[i]},
                       {"x", p.vertices[i].x()},
                       {"y", p.vertices[i].y()},
                       {"inner_angle_deg", c.inner_angle_deg[k]},
                       {"parametric", {k == 1 || k == 2 ? 1 : 0, k >= 2 ? 1 : 0}}});
  }
  json chains = json::array();
  for (int s = 0; s < 4; ++s) chains.push_back(r.boundary.chain_length(static_cast<Side>(s)));
  json trials = json::array();
  for (const CornerTrial& t : r.corner_trials) {
    json idx = json::array();
    for (std::size_t i : t.corners) idx.push_back(p.file_index[i]);
    trials.push_back({{"file_indices", idx},
                      {"inverted_cells", t.inverted_cells},
                      {"min_mean_ratio", t.min_mean_ratio},
                      {"mean_mean_ratio", t.mean_mean_ratio}});
  }
  json times = json::object();
  double total = 0.0;
  for (const auto& t : r.times) times[t.stage] = t.seconds, total += t.seconds;
  times["total"] = total;
  return {
      {"input", input_path},
      {"input_cleaning", {{"removed_vertices", r.removed_vertices}, {"notes", r.cleaning_notes}}},
      {"counts",
       {{"polygon_vertices", p.vertices.size()},
        {"cells", r.mesh.num_cells()},
        {"vertices", r.mesh.num_vertices()},
        {"hanging_vertices", r.mesh.num_hanging_vertices()},
        {"max_level", r.mesh.max_level()}}},
      {"tolerance",
       {{"area", r.tolerance_area},
        {"relative", r.tolerance_is_relative},
        {"boundary_splits", r.refinement.boundary_splits},
        {"balance_splits", r.refinement.balance_splits},
        {"edges_over_tolerance", r.refinement.edges_over_tolerance},
        {"max_edge_error", r.refinement.max_error}}},
      {"corners", {{"vertices", corners}, {"chain_lengths", chains}, {"explanation", c.explanation}, {"trials", trials}}},
      {"coons", r.quality_coons},
      {"optimized", r.quality_optimized},
      {"optimization",
       {{"sweeps", r.total_sweeps},
        {"sweeps_last_run", r.smoothing.sweeps},
        {"node_visits", r.node_visits},
        {"repair_rounds", r.repair_refined_cells.size()},
        {"repair_refined_cells", r.repair_refined_cells},
        {"converged", r.smoothing.converged},
        {"last_max_relative_move", r.smoothing.last_max_relative_move},
        {"tangled_nodes_before", r.smoothing.tangled_nodes_before},
        {"tangled_nodes_after", r.smoothing.tangled_nodes_after},
        {"newton_steps", r.smoothing.newton_steps},
        {"gradient_fallbacks", r.smoothing.gradient_fallbacks}}},
      {"seconds", times},
  };
}

void write_front_meshes(const FrontResult& r, const std::string& out_dir, bool physical,
                        toolkit::io::VtuCompression compression) {
  toolkit::io::ensure_writable_directory(out_dir);
  const std::filesystem::path dir(out_dir);
  std::vector<Eigen::Vector2d> param(r.mesh.num_vertices());
  for (int v = 0; v < static_cast<int>(param.size()); ++v) param[v] = r.mesh.vertex_param(v);
  toolkit::io::write_vtu((dir / output_files::kParametricTMesh).string(), tmesh_vtu(r.mesh, param),
                         compression);
  if (physical)
    toolkit::io::write_vtu((dir / output_files::kPhysicalTMesh).string(), tmesh_vtu(r.mesh, r.optimized),
                           compression);
  toolkit::io::write_vtu((dir / output_files::kBoundary).string(), boundary_vtu(r.boundary), compression);
}

}  // namespace tspline::io

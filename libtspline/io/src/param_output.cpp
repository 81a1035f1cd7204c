#include "tspline/io/param_output.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <utility>

#include "toolkit/errors.h"
#include "toolkit/io/atomic_file.h"
#include "tspline/detail/uv_point_index.h"
#include "tspline/detail/vtu_fields.h"
#include "tspline/io/bezier_vtu.h"
#include "tspline/io/cell_grid.h"
#include "tspline/io/front_output.h"
#include "tspline/io/output_files.h"
#include "tspline/io/tspline_file.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/element_map.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"
#include "tspline/validity/map_quality_bounds.h"
#include "tspline/validity/map_untangling.h"

namespace tspline {

// The report's keys are the field names (from_json comes with the macros and
// is unused).
// The options of the certified quality bounds (map_quality_bounds.h).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(QualityBoundOptions, relative_gap, absolute_gap, max_depth, max_patches,
                                   samples_per_edge)
// One adaptive round's untangling of the control points (map_untangling.h).
// The certification is left out: the round's own is in the report.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(SampleStats, points, nonpositive, min_det, min_mean_ratio, mean_mean_ratio)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(MapUntanglingReport, free_points, fixed_points, elements, samples, stages, iterations,
                                   evaluations, factorizations, shifted_factorizations, line_search_certifications,
                                   hessian_seconds, solve_seconds, cg_iterations, newton_from_stage, sample_refinements,
                                   local_repairs, local_repairs_certified, local_repair_iterations, local_repair_seconds,
                                   before, after, certified, stop_reason, seconds)

}  // namespace tspline

namespace tspline::io {

toolkit::io::VtuMesh surface_vtu(const TSplineMap& map, int k, const BezierExtraction* given) {
  if (k < 1 || k > 64) throw toolkit::InputError("samples per cell edge must be in [1, 64]");
  detail::SampleQualityFields quality;
  quality.reserve(cell_grid_point_estimate(map.mesh(), k));
  // The samples of a cell from its Bezier elements (element_map.h).
  const ExtractionOrOwn extraction_or_own(map.basis(), given);
  const BezierExtraction& extraction = extraction_or_own.get();
  CellMapEvaluator cell_map(extraction, map.control_points());
  toolkit::io::VtuMesh out = cell_grid_vtu(map.mesh(), k, [&](int c, const Eigen::Vector2d& uv) {
    cell_map.set_cell(c);
    const MapDerivatives d = cell_map.at(uv);
    quality.push(d.J, uv);
    return d.x;
  });
  quality.attach_to(out);
  return out;
}

toolkit::io::VtuMesh control_net_vtu(const TSplineMap& map) {
  toolkit::io::VtuMesh out;
  out.points = map.control_points();
  std::vector<int> kind, fn;
  for (int a = 0; a < static_cast<int>(map.basis().size()); ++a) {
    out.cells.push_back({a});
    kind.push_back(static_cast<int>(map.basis().function(a).kind));
    fn.push_back(a);
  }
  // Lines: the T-mesh edges between anchors (the T-spline's control net), and
  // each border/corner extra function joined to its vertex's anchor.
  const TMesh& mesh = map.mesh();
  std::vector<int> anchor(mesh.num_vertices(), -1);
  for (int a = 0; a < static_cast<int>(map.basis().size()); ++a)
    if (map.basis().function(a).kind == BlendingFunction::Kind::Anchor) anchor[map.basis().function(a).vertex] = a;
  std::vector<std::pair<int, int>> edges;  // each once, in ascending order
  edges.reserve(4 * mesh.num_cells());
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    const std::vector<int> poly = mesh.cell_polygon(c);
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const int u = poly[k], v = poly[(k + 1) % poly.size()];
      edges.push_back({std::min(u, v), std::max(u, v)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [u, v] : edges)
    if (anchor[u] >= 0 && anchor[v] >= 0) out.cells.push_back({anchor[u], anchor[v]});
  for (int a = 0; a < static_cast<int>(map.basis().size()); ++a) {
    const BlendingFunction& f = map.basis().function(a);
    if (f.kind != BlendingFunction::Kind::Anchor && anchor[f.vertex] >= 0) out.cells.push_back({anchor[f.vertex], a});
  }
  out.point_ints["kind"] = std::move(kind);
  out.point_ints["function"] = std::move(fn);
  return out;
}

toolkit::io::VtuMesh physical_tmesh_vtu(const TSplineMap& map, int k, const MapCertification* certificate,
                                        const CertificationOptions& options,
                                        const std::vector<CellMapQuality>* quality,
                                        const BezierExtraction* given) {
  if (k < 1 || k > 64) throw toolkit::InputError("samples per cell edge must be in [1, 64]");
  const TMesh& mesh = map.mesh();
  const int nc = static_cast<int>(mesh.num_cells());
  if (certificate && certificate->cell_certified.size() != mesh.num_cells()) certificate = nullptr;
  if (quality && quality->size() != mesh.num_cells()) quality = nullptr;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  toolkit::io::VtuMesh out;
  detail::TMeshPointFields fields;
  std::vector<int> vertex;
  // One point per parametric position: a segment is sampled from its
  // lexicographically smaller end, so both cells along it get the same doubles.
  detail::UvPointIndex index(static_cast<std::size_t>(nc) * static_cast<std::size_t>(2 * k + 2));
  const ExtractionOrOwn extraction_or_own(map.basis(), given);
  const BezierExtraction& extraction = extraction_or_own.get();
  CellMapEvaluator cell_map(extraction, map.control_points());
  auto point = [&](const Eigen::Vector2d& uv, int c, int v) {
    const auto [p, added] = index.find_or_add(uv);
    if (added) {
      cell_map.set_cell(c);
      out.points.push_back(cell_map.at(uv).x);
      fields.push(uv, v >= 0 && mesh.vertex_is_hanging(v),
                  uv.x() == 0.0 || uv.x() == 1.0 || uv.y() == 0.0 || uv.y() == 1.0);
      vertex.push_back(v);
    }
    return p;
  };
  std::vector<int> level(nc), valid(nc), certified(nc);
  std::vector<double> lower(nc, nan), relative(nc, nan), min_det(nc, nan), min_jr(nc, nan);
  out.cells.reserve(static_cast<std::size_t>(nc));
  for (int c = 0; c < nc; ++c) {
    const std::vector<int> poly = mesh.cell_polygon(c);
    std::vector<int> cell;
    cell.reserve(poly.size() * static_cast<std::size_t>(k));
    for (std::size_t e = 0; e < poly.size(); ++e) {
      const int va = poly[e], vb = poly[(e + 1) % poly.size()];
      const Eigen::Vector2d a = mesh.vertex_param(va), b = mesh.vertex_param(vb);
      cell.push_back(point(a, c, va));
      const bool forward = std::make_pair(a.x(), a.y()) < std::make_pair(b.x(), b.y());
      const Eigen::Vector2d &lo = forward ? a : b, &hi = forward ? b : a;
      for (int j = 1; j < k; ++j) {
        const int t = forward ? j : k - j;
        cell.push_back(point(lo + (hi - lo) * (static_cast<double>(t) / k), c, -1));
      }
    }
    out.cells.push_back(std::move(cell));
    level[c] = mesh.cell_level(c);
    if (quality) min_det[c] = (*quality)[c].min_det, min_jr[c] = (*quality)[c].min_mean_ratio;
    certified[c] = certificate ? (certificate->cell_certified[c] ? 1 : 0) : -1;
    valid[c] = certificate ? certified[c] : quality ? ((*quality)[c].min_det > 0.0 ? 1 : 0) : -1;
  }
  if (certificate && certificate->cell_det_lower_bound.size() == mesh.num_cells()) {
    lower = certificate->cell_det_lower_bound;  // the minimum over the cell's Bezier elements
    relative = certificate->cell_relative_lower_bound;
  } else if (certificate) {
    // A certificate without the bounds per cell (made elsewhere): the elements again.
    const std::vector<Eigen::Vector2d>& P = map.control_points();
    for (const BezierElement& e : extraction.elements()) {
      const ElementCertificate cert = certify_element(e, P, options);
      double& l = lower[e.cell];
      double& r = relative[e.cell];
      l = std::isnan(l) ? cert.det_lower_bound : std::min(l, cert.det_lower_bound);
      r = std::isnan(r) ? cert.relative_lower_bound : std::min(r, cert.relative_lower_bound);
    }
  }
  // The points were counted as they came: the arrays at their final size (all
  // patches' parts are held at once before they are merged).
  out.points.shrink_to_fit(), vertex.shrink_to_fit(), fields.shrink_to_fit();
  out.cell_ints["level"] = std::move(level);
  out.cell_ints["valid"] = std::move(valid);
  out.cell_ints["certified"] = std::move(certified);
  out.cell_scalars["det_lower_bound"] = std::move(lower);
  out.cell_scalars["relative_det_lower_bound"] = std::move(relative);
  out.cell_scalars["min_det_jacobian"] = std::move(min_det);
  out.cell_scalars["min_mean_ratio_jacobian"] = std::move(min_jr);
  out.point_ints["vertex"] = std::move(vertex);
  fields.attach_to(out);
  return out;
}

toolkit::io::VtuMesh bezier_vtu(const ParameterizationResult& r, const BezierExtraction* extraction) {
  if (!r.map) throw toolkit::InputError("bezier_vtu: the result has no map");
  return bezier_vtu(*r.map, r.adaptive.certify ? &r.certification : nullptr, r.adaptive.certification,
                    extraction);
}

toolkit::io::VtuMesh physical_tmesh_vtu(const ParameterizationResult& r, int k,
                                        const BezierExtraction* extraction) {
  if (!r.map) throw toolkit::InputError("physical_tmesh_vtu: the result has no map");
  return physical_tmesh_vtu(*r.map, k, r.adaptive.certify ? &r.certification : nullptr,
                            r.adaptive.certification, &r.cell_quality, extraction);
}

AdaptSeriesWriter::AdaptSeriesWriter(std::string out_dir, int samples,
                                     toolkit::io::VtuCompression compression)
    : out_dir_(std::move(out_dir)), samples_(samples), compression_(compression) {}

void AdaptSeriesWriter::add(int it, const TSplineMap& map, const std::vector<CellMapQuality>* quality) {
  // Created on first use, so that a run failing before the first fit leaves nothing.
  if (entries_.empty()) toolkit::io::ensure_writable_directory((std::filesystem::path(out_dir_) / output_files::kAdaptFolder).string());
  char name[64];
  std::snprintf(name, sizeof name, "adapt/mesh_%03d.vtu", it);
  const std::string mesh_file = name;
  std::snprintf(name, sizeof name, "adapt/surface_%03d.vtu", it);
  const std::string surface_file = name;
  const std::filesystem::path dir(out_dir_);
  toolkit::io::write_vtu((dir / mesh_file).string(), physical_tmesh_vtu(map, samples_, nullptr, {}, quality),
                         compression_);
  toolkit::io::write_vtu((dir / surface_file).string(), surface_vtu(map, samples_), compression_);
  entries_.push_back({static_cast<double>(it), mesh_file, 0});
  entries_.push_back({static_cast<double>(it), surface_file, 1});
}

void AdaptSeriesWriter::finish() const {
  toolkit::io::write_pvd((std::filesystem::path(out_dir_) / output_files::kAdaptSeries).string(), entries_);
}

namespace {

nlohmann::json map_quality_json(const MapQualityStats& q) {
  return {{"points", q.points},
          {"nonpositive_det_points", q.nonpositive_det},
          {"min_mean_ratio_jacobian", q.min_mean_ratio},
          {"mean_mean_ratio_jacobian", q.mean_mean_ratio},
          {"min_det_jacobian", q.min_det},
          {"max_det_jacobian", q.max_det},
          {"min_scaled_jacobian", q.min_scaled}};
}

// Certification counts and bounds (non-finite bounds are written as null).
nlohmann::json certification_json(const MapCertification& c) {
  auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"elements", c.elements},
          {"elements_certified", c.certified},
          {"elements_invalid", c.invalid},
          {"elements_undecided", c.undecided},
          {"min_relative_det_lower_bound", finite(c.min_relative_lower_bound)},
          {"min_det_lower_bound", finite(c.min_det_lower_bound)},
          {"max_subdivision_depth", c.max_depth_used},
          {"seconds", c.seconds}};
}


}  // namespace

QualityBoundOptions report_quality_bound_options() {
  QualityBoundOptions o;
  o.samples_per_edge = 25;  // 26 x 26 points per element
  return o;
}

nlohmann::json whole_map_quality_json(const MapQualityBounds& q, const QualityBoundOptions& o) {
  using nlohmann::json;
  const bool sampled = q.samples_per_element > 0 && q.elements > 0;
  auto figure = [&](const QualityBound& b) {
    json f = {{"certified_lower_bound", b.lower_bound},
              {"attained_min", b.attained},
              {"attained_min_at", {b.attained_at.x(), b.attained_at.y()}},
              {"sampled_min", sampled ? json(b.sampled) : json(nullptr)},
              {"samples_per_element", q.samples_per_element}};
    if (sampled) f["sampled_min_at"] = {b.sampled_at.x(), b.sampled_at.y()};
    return f;
  };
  return {{"mean_ratio", figure(q.mean_ratio)},
          {"scaled_jacobian", figure(q.scaled)},
          {"certified_bounds",
           {{"method", "Bernstein bounds of det J, |S_xi|, |S_eta| with subdivision (map_quality_bounds.h)"},
            {"elements", q.elements},
            {"elements_bounded_to_the_gap", q.bounded_elements},  // the others cannot hold the minimum
            {"max_subdivision_depth", q.max_depth_used},
            {"sub_patches", q.patches},
            {"elements_stopped_at_a_limit", q.elements_not_converged},
            {"seconds", q.seconds},
            // The gap targets and both limits (max_depth, max_patches) an element may stop at.
            {"options", o}}}};
}

nlohmann::json boundary_corner_json(const BoundaryCornerQuality& c) {
  return {{"scaled_jacobian", c.scaled_jacobian},
          {"mean_ratio", c.mean_ratio},
          {"angle_degrees", c.angle_degrees},
          {"at", {c.at.x(), c.at.y()}},
          {"patch", c.patch},
          {"corner", c.corner},
          {"note", "J at a corner whose two sides are the domain's boundary is the pair of boundary tangents, which "
                   "no interior control point changes: the whole-map minima cannot exceed these values"}};
}

std::string whole_map_quality_summary(const nlohmann::json& w) {
  auto num = [](const nlohmann::json& v) {
    if (v.is_null()) return std::string("none");
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v.get<double>());
    return std::string(buf);
  };
  if (!w.is_object() || !w.contains("mean_ratio") || !w["mean_ratio"].is_object() || !w.contains("scaled_jacobian"))
    return "whole map: no quality figures (no map)";
  const nlohmann::json &jr = w.at("mean_ratio"), &sj = w.at("scaled_jacobian");
  const std::size_t k = jr.at("samples_per_element").get<std::size_t>();
  const std::string sample =
      k > 0 ? "min " + num(jr.at("sampled_min")) + " in a dense sample of " + std::to_string(k) + " points per element"
            : "no dense sample";
  std::string line = "whole map: J_r >= " + num(jr.at("certified_lower_bound")) + " certified (" + sample +
                     "), scaled Jacobian >= " + num(sj.at("certified_lower_bound")) + " certified (" +
                     (k > 0 ? "sampled min " + num(sj.at("sampled_min")) : std::string("no dense sample")) + ")";
  if (w.contains("boundary_corner")) {
    const nlohmann::json& c = w.at("boundary_corner");
    char angle[32];
    std::snprintf(angle, sizeof angle, "%.1f", c.at("angle_degrees").get<double>());
    line += "; the boundary fixes the scaled Jacobian at " + num(c.at("scaled_jacobian")) + " at a corner of " +
            angle + " degrees";
  }
  return line;
}

nlohmann::json combine_whole_map_quality_json(const std::vector<nlohmann::json>& whole_maps) {
  using nlohmann::json;
  json out;
  for (const char* name : {"mean_ratio", "scaled_jacobian"}) {
    json best;
    for (std::size_t p = 0; p < whole_maps.size(); ++p) {
      if (!whole_maps[p].is_object() || !whole_maps[p].contains(name)) continue;  // a patch without figures
      const json& f = whole_maps[p].at(name);
      if (best.is_null()) {
        best = f;
        best["certified_lower_bound_patch"] = best["attained_min_patch"] = best["sampled_min_patch"] = p;
        continue;
      }
      if (f["certified_lower_bound"].get<double>() < best["certified_lower_bound"].get<double>()) {
        best["certified_lower_bound"] = f["certified_lower_bound"];
        best["certified_lower_bound_patch"] = p;
      }
      if (f["attained_min"].get<double>() < best["attained_min"].get<double>())
        best["attained_min"] = f["attained_min"], best["attained_min_at"] = f["attained_min_at"],
        best["attained_min_patch"] = p;
      if (!f["sampled_min"].is_null() &&
          (best["sampled_min"].is_null() || f["sampled_min"].get<double>() < best["sampled_min"].get<double>()))
        best["sampled_min"] = f["sampled_min"], best["sampled_min_at"] = f["sampled_min_at"],
        best["sampled_min_patch"] = p;
    }
    out[name] = best;
  }
  return out;
}

namespace {

// The T-spline: its functions by kind, the boundary interpolation's residuals.
nlohmann::json tspline_json(const ParameterizationResult& r) {
  std::size_t kinds[3] = {0, 0, 0};
  for (const auto& f : r.map->basis().functions()) ++kinds[static_cast<int>(f.kind)];
  return {{"degree", 3},
          {"blending_functions", r.map->basis().size()},
          {"control_points", r.map->control_points().size()},
          {"anchor_functions", kinds[0]},
          {"edge_extra_functions", kinds[1]},
          {"corner_extra_functions", kinds[2]},
          {"interpolation_max_residual", r.fit.max_residual},
          {"interpolation_relative_residual", r.fit.relative_residual},
          {"matrix_nonzeros", r.fit.nonzeros},
          {"control_points_optimized", r.control_points_optimized}};
}

// The adaptive loop's dense sample and, with a map, the certified bounds and
// dense sample of whole_map_quality_json and the worst boundary corner.
nlohmann::json whole_map_json(const ParameterizationResult& r) {
  const DenseMapQuality& q = r.dense_quality;
  nlohmann::json w = {{"min_mean_ratio", q.min_mean_ratio},
                      {"min_scaled", q.min_scaled},
                      {"nonpositive_det_points", q.nonpositive_det},
                      {"points", q.points},
                      {"points_per_element", (q.samples_per_edge + 1) * (q.samples_per_edge + 1)},
                      {"worst_at", {q.worst_at.x(), q.worst_at.y()}}};
  if (r.map) {
    const QualityBoundOptions qo = report_quality_bound_options();
    w.update(whole_map_quality_json(certified_map_quality(*r.map, qo), qo));
    if (const auto corner = worst_boundary_corner(*r.map)) w["boundary_corner"] = boundary_corner_json(*corner);
  }
  return w;
}

// The Jacobian's quality at the Gauss points, and over the whole map.
nlohmann::json jacobian_json(const ParameterizationResult& r) {
  nlohmann::json j = map_quality_json(r.quality);
  j["gauss_points_per_direction"] = r.adaptive.gauss;
  j["threshold"] = r.adaptive.min_jacobian;
  j["note"] =
      "min/mean at the Gauss points; whole_map.mean_ratio and whole_map.scaled_jacobian: certified_lower_bound holds "
      "everywhere on the map (Bernstein bounds), sampled_min is the minimum of a dense sample (samples_per_element "
      "points per Bezier element), a value of the map, so the true minimum lies between them; whole_map.min_mean_ratio, "
      "min_scaled, points, points_per_element and worst_at: the adaptive loop's sample (points_per_element points per "
      "element and the Gauss points), kept for older readers";
  j["whole_map"] = whole_map_json(r);
  return j;
}

// The certification of the map kept.
nlohmann::json final_certification_json(const ParameterizationResult& r) {
  nlohmann::json c = certification_json(r.certification);
  c["depth_limit"] = r.adaptive.certification.max_depth;
  c["extra_refinement_rounds"] = r.certification_rounds;
  return c;
}

// The adaptive rounds, one record each.
nlohmann::json iterations_json(const ParameterizationResult& r) {
  nlohmann::json its = nlohmann::json::array();
  for (const AdaptIteration& it : r.iterations)
    its.push_back({{"cells", it.cells},
                   {"vertices", it.vertices},
                   {"functions", it.functions},
                   {"inverted_tmesh_cells", it.inverted_cells},
                   {"cells_refined_after", it.refined_cells},
                   {"interpolation_relative_residual", it.fit.relative_residual},
                   {"control_points_optimized", it.control_points_optimized},
                   {"untangling", it.untangling},
                   {"jacobian", map_quality_json(it.quality)},
                   {"seconds", it.seconds}});
  if (r.adaptive.certify)
    for (std::size_t k = 0; k < r.iterations.size(); ++k) {
      its[k]["certification"] = certification_json(r.iterations[k].certification);
      its[k]["certification"]["cells_marked_only_for_certification"] = r.iterations[k].certification_marked_cells;
    }
  return its;
}

nlohmann::json adaptive_json(const ParameterizationResult& r) {
  const AdaptiveOptions& ad = r.adaptive;
  return {{"max_rounds", ad.max_adapt},
          {"stall_rounds", ad.stall_rounds},
          {"max_cells", r.options.max_cells},
          {"map_untangling", ad.optimize_control_points},
          {"iterations", iterations_json(r)},
          {"kept_iteration", r.kept_iteration},
          {"stop_reason", r.stop_reason}};
}

}  // namespace

nlohmann::json param_report(const ParameterizationResult& r, const std::string& input_path) {
  nlohmann::json rep = front_report(r.front, input_path);
  rep["tspline"] = tspline_json(r);
  rep["jacobian"] = jacobian_json(r);
  rep["boundary_curve_proven_simple"] = r.boundary_simple;
  if (!r.boundary_problem.empty()) rep["boundary_problem"] = r.boundary_problem;
  rep["valid"] = r.valid();
  rep["good"] = r.good();
  if (r.adaptive.certify) {
    rep["certified_valid"] = r.certified_valid();
    rep["certification"] = final_certification_json(r);
  }
  rep["adaptive"] = adaptive_json(r);
  double total = 0.0;
  for (const auto& t : r.front.times) rep["seconds"][t.stage] = t.seconds, total += t.seconds;
  rep["seconds"]["total"] = total;
  return rep;
}

void write_param_outputs(const ParameterizationResult& r, const std::string& out_dir,
                         const nlohmann::json& report, int samples, toolkit::io::VtuCompression compression) {
  const std::filesystem::path dir(out_dir);
  write_front_meshes(r.front, out_dir, /*physical=*/false, compression);
  toolkit::io::write_vtu((dir / output_files::kPhysicalTMesh).string(), physical_tmesh_vtu(r, samples),
                         compression);
  TSplineFileMeta meta;
  meta.source = report.value("input", "");
  meta.boundary = r.front.boundary.polygon();
  meta.corners = r.front.boundary.corners().index;
  write_tspline_file((dir / output_files::kTSpline).string(), *r.map, meta);
  toolkit::io::write_vtu((dir / output_files::kSurface).string(), surface_vtu(*r.map, samples), compression);
  toolkit::io::write_vtu((dir / output_files::kBezierSurface).string(), bezier_vtu(r), compression);
  toolkit::io::write_vtu((dir / output_files::kControlNet).string(), control_net_vtu(*r.map), compression);
  toolkit::io::write_text_atomic((dir / output_files::kReport).string(), report.dump(2) + "\n");  // last: the run's summary
}

}  // namespace tspline::io

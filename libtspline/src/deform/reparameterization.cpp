#include "tspline/deform/reparameterization.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "tspline/boundary/plane.h"
#include "tspline/boundary/boundary_map.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/deform/boundary_deformation.h"
#include "tspline/errors.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/tmesh/mesh_quality.h"
#include "tspline/validity/map_quality.h"
#include "toolkit/timing.h"

namespace tspline {

Polygon corresponding_polygon(const Polygon& old, const Polygon& read, const std::string& ring) {
  std::size_t max_index = 0;
  for (std::size_t f : old.file_index) max_index = std::max(max_index, f);
  const bool cleaned = max_index + 1 != old.vertices.size();  // the old run removed vertices of the file
  const std::size_t n = read.vertices.size();
  // Where each file index sits in `read` (its own file_index, or its order).
  std::vector<std::size_t> at(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t f = read.file_index.size() == n ? read.file_index[k] : k;
    if (f >= n) throw InputError(ring + " of the moved boundary: file index " + std::to_string(f) + " out of range");
    at[f] = k;
  }
  if ((!cleaned && n != old.vertices.size()) || (cleaned && n <= max_index))
    throw InputError(ring + " of the moved boundary has " + std::to_string(n) + " vertices, the previous map's " +
                     (cleaned ? "file had at least " + std::to_string(max_index + 1)
                              : std::to_string(old.vertices.size())) +
                     " (vertex i moves to vertex i: the counts must match)");
  Polygon out;
  out.file_index = old.file_index;
  out.vertices.reserve(old.vertices.size());
  for (std::size_t f : old.file_index) out.vertices.push_back(read.vertices[at[f]]);
  return out;
}

ParameterizationResult reparameterize(const TSplineMap& old_map, const Polygon& old_polygon,
                                      const std::array<std::size_t, 4>& corners, const Polygon& moved,
                                      const ParameterizationOptions& options, const AdaptiveOptions& adaptive,
                                      std::optional<double> reference_mean_ratio,
                                      const IterationCallback& on_iteration) {
  if (moved.vertices.size() != old_polygon.vertices.size())
    throw InputError("the moved boundary has " + std::to_string(moved.vertices.size()) +
                     " vertices, the previous map's " + std::to_string(old_polygon.vertices.size()));
  return reparameterize(old_map, old_polygon, corners, moved,
                        fit_boundary_deformation(old_polygon.vertices, moved.vertices), options, adaptive,
                        reference_mean_ratio, on_iteration);
}

ParameterizationResult reparameterize(const TSplineMap& old_map, const Polygon& old_polygon,
                                      const std::array<std::size_t, 4>& corners, const Polygon& moved,
                                      const BoundaryDeformation& d, const ParameterizationOptions& options,
                                      const AdaptiveOptions& adaptive, std::optional<double> reference_mean_ratio,
                                      const IterationCallback& on_iteration) {
  const auto t0 = std::chrono::steady_clock::now();
  if (moved.vertices.size() != old_polygon.vertices.size() || d.residual.size() != old_polygon.vertices.size())
    throw InputError("the moved boundary has " + std::to_string(moved.vertices.size()) +
                     " vertices, the previous map's " + std::to_string(old_polygon.vertices.size()));
  // Simple, finite, in range; the same orientation (a reflection is no motion
  // of the domain: the map would have det J < 0 everywhere).
  const Polygon checked = validate_polygon(moved);
  if (checked.file_index != moved.file_index || checked.vertices != moved.vertices)
    throw InputError("the moved boundary runs the other way round (a reflection of the domain): "
                     "the vertices must keep their order around the domain");
  Corners c;
  c.index = corners;
  c.explanation = "kept from the previous map";
  for (int k = 0; k < 4; ++k) {
    const std::size_t n = moved.vertices.size(), i = corners[k];
    const Eigen::Vector2d a = moved.vertices[(i + 1) % n] - moved.vertices[i];
    const Eigen::Vector2d b = moved.vertices[(i + n - 1) % n] - moved.vertices[i];
    c.inner_angle_deg[k] = ccw_degrees(a, b);
  }
  const BoundaryMap old_boundary(old_polygon, c);
  BoundaryMap new_boundary(moved, c);
  WarmStart warm{warm_start_map(old_map, old_boundary, d), 0.0};
  if (reference_mean_ratio) {
    warm.reference_mean_ratio = *reference_mean_ratio;
  } else {
    // One Bezier extraction for both checks (as the adaptive loop's).
    const BezierExtraction extraction(old_map.basis());
    const MapQualityStats q = map_quality(old_map, extraction, adaptive.gauss);
    warm.reference_mean_ratio = std::min(
        q.min_mean_ratio,
        dense_map_quality(extraction, old_map.control_points(), adaptive.dense_samples).min_mean_ratio);
  }

  FrontResult front(std::move(new_boundary));
  front.mesh = old_map.mesh();
  front.optimized.resize(front.mesh.num_vertices());
  for (int v = 0; v < static_cast<int>(front.optimized.size()); ++v)
    front.optimized[v] = front.mesh.vertex_on_boundary(v) ? front.boundary.point_at(front.mesh.vertex_param(v))
                                                          : warm.map.point(front.mesh.vertex_param(v));
  front.coons = front.optimized;
  front.quality_coons = front.quality_optimized = mesh_quality(front.mesh, front.optimized);
  const double diag = bounding_box_diagonal(moved);
  front.tolerance_is_relative = !options.tolerance_absolute.has_value();
  front.tolerance_area =
      options.tolerance_absolute ? *options.tolerance_absolute : options.tolerance_relative * diag * diag;
  const double warm_seconds = toolkit::seconds_since(t0);
  front.times.push_back({"warm_start", warm_seconds});
  {
    std::string text = "warm start: " + std::to_string(moved.vertices.size()) +
                       " vertices moved, affine part and a remainder of at most " +
                       std::to_string(d.max_residual()) + "; " + std::to_string(front.mesh.num_cells()) +
                       " cells of the previous map, its whole-map J_r " + std::to_string(warm.reference_mean_ratio);
    report_step(options.progress, "warm_start", text);
  }
  return run_parameterization_from(std::move(front), std::move(warm), options, adaptive, on_iteration);
}

}  // namespace tspline

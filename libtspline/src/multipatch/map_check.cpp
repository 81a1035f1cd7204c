// The check of a map of any number of patches; see tspline/multipatch/map_check.h.
#include "tspline/multipatch/map_check.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "tspline/detail/thread_pool.h"
#include "tspline/errors.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/spline/bezier_extraction.h"

namespace tspline {

namespace {

PatchCheck check_patch(const TSplineMap& map, const MapCheckOptions& o, const QualityBoundOptions& qo) {
  PatchCheck c;
  const BezierExtraction extraction(map.basis());
  c.cells = map.mesh().num_cells();
  c.certification = certify_map(extraction, c.cells, map.control_points(), o.certification);
  c.quality = certified_map_quality(extraction, map.control_points(), qo);
  c.dense = dense_map_quality(extraction, map.control_points(), o.dense_samples);
  c.gauss = map_quality(map, extraction, o.gauss);
  c.corner = worst_boundary_corner(map);
  return c;
}

}  // namespace

MapCheck check_map(const std::vector<const TSplineMap*>& patches, const std::vector<Interface>& interfaces,
                   const MapCheckOptions& o) {
  if (o.dense_samples < 1 || o.dense_samples > 64)
    throw InputError("check: dense_samples must be in [1, 64], got " + std::to_string(o.dense_samples));
  if (o.gauss < 1 || o.gauss > 10) throw InputError("check: gauss must be in [1, 10], got " + std::to_string(o.gauss));
  for (const Interface& f : interfaces)
    if (f.patch_a >= patches.size() || f.patch_b >= patches.size() || f.side_a < 0 || f.side_a > 3 || f.side_b < 0 ||
        f.side_b > 3)
      throw InputError("check: interface along cut " + std::to_string(f.cut) + " names a patch or side out of range");
  MapCheck m;
  m.patches.resize(patches.size());
  // Many patches: one per range of the pool, each on one thread (its own
  // figures are those of any thread count); one patch: its elements in parallel.
  QualityBoundOptions qo = o.quality;
  if (patches.size() > 1) qo.threads = 1;
  // (Patches handed out one at a time: their sizes vary along the layout.)
  detail::parallel_items(patches.size(), detail::pool_threads(),
                         [&](std::size_t p) { m.patches[p] = check_patch(*patches[p], o, qo); });
  std::vector<MapQualityBounds> parts;
  parts.reserve(patches.size());
  m.min_relative_det_lower_bound = m.min_det_lower_bound = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    PatchCheck& c = m.patches[p];
    const MapCertification& z = c.certification;
    m.cells += c.cells;
    m.elements += z.elements;
    m.certified += z.certified;
    m.invalid += z.invalid;
    m.undecided += z.undecided;
    if (z.certified_valid()) ++m.certified_patches;
    m.max_depth_used = std::max(m.max_depth_used, z.max_depth_used);
    // (A NaN bound never replaces a number: the comparison is false.)
    if (z.min_relative_lower_bound < m.min_relative_det_lower_bound)
      m.min_relative_det_lower_bound = z.min_relative_lower_bound;
    if (z.min_det_lower_bound < m.min_det_lower_bound) m.min_det_lower_bound = z.min_det_lower_bound;
    m.min_dense_mean_ratio = std::min(m.min_dense_mean_ratio, c.dense.min_mean_ratio);
    m.min_gauss_mean_ratio = std::min(m.min_gauss_mean_ratio, c.gauss.min_mean_ratio);
    if (c.corner && (!m.corner || c.corner->scaled_jacobian < m.corner->scaled_jacobian))
      m.corner = c.corner, m.corner_patch = p;
    MapQualityBounds part = c.quality;
    part.per_element.clear();
    parts.push_back(std::move(part));
  }
  m.quality = merge_map_quality(std::move(parts));
  m.quality.samples_per_edge = o.quality.samples_per_edge;
  // The gaps per range, then the largest (the same for any number of ranges).
  std::vector<double> gaps(static_cast<std::size_t>(detail::pool_threads()), 0.0);
  detail::parallel_ranges(interfaces.size(), detail::pool_threads(), [&](std::size_t begin, std::size_t end, int slot) {
    for (std::size_t i = begin; i < end; ++i) {
      const Interface& f = interfaces[i];
      gaps[slot] = std::max(gaps[slot], interface_gap(*patches[f.patch_a], f.side_a, *patches[f.patch_b], f.side_b));
    }
  }, 64);
  m.max_interface_gap = *std::max_element(gaps.begin(), gaps.end());
  return m;
}

}  // namespace tspline

#pragma once
// A new map for a moved boundary, from the previous map (moving domains, shape
// optimization): the same T-mesh, knots and corners; the boundary curve
// follows the moved polygon (vertex i of the old polygon moved to vertex i of
// the new one); the interior starts from the old map moved with it
// (boundary_deformation.h) and is untangled and improved from there only where
// it needs it; cells are refined only where the moved map needs them.
#include <array>
#include <cstddef>
#include <string>

#include "tspline/boundary/polygon.h"
#include "tspline/deform/boundary_deformation.h"
#include "tspline/pipeline/adaptive_parameterization.h"

namespace tspline {

/// The polygon of a moved ring in the numbering of the old one: vertex k is
/// the vertex of `read` (as read from a file, vertices in file order) at the old
/// vertex's file index. \p ring names the ring in messages ("the outer ring").
/// \throw InputError if the vertex counts differ (or, when the old ring was
/// cleaned of vertices, `read` is too short to hold its file indices).
Polygon corresponding_polygon(const Polygon& old, const Polygon& read, const std::string& ring);

/// The map of the moved polygon `moved` (vertex k = the moved old_polygon
/// vertex k, file_index as old_polygon's) from `old_map` of `old_polygon` (CCW,
/// validated, as the map's file stores it) with the given corners (indices
/// into the polygon). The moved polygon must be simple and keep the
/// orientation. `reference_mean_ratio`: the old map's whole-map J_r if known
/// (else it is measured). \throw InputError naming the problem (vertex count,
/// crossing edges by file index, a reflection); NumericalError as the fit.
ParameterizationResult reparameterize(const TSplineMap& old_map, const Polygon& old_polygon,
                                      const std::array<std::size_t, 4>& corners, const Polygon& moved,
                                      const ParameterizationOptions& options, const AdaptiveOptions& adaptive,
                                      std::optional<double> reference_mean_ratio = std::nullopt,
                                      const IterationCallback& on_iteration = {});

/// The same with the deformation given (its residual: one entry per vertex of
/// old_polygon): a patch of a layout moves with the layout's global affine
/// part, so that two patches agree on their common side.
ParameterizationResult reparameterize(const TSplineMap& old_map, const Polygon& old_polygon,
                                      const std::array<std::size_t, 4>& corners, const Polygon& moved,
                                      const BoundaryDeformation& deformation, const ParameterizationOptions& options,
                                      const AdaptiveOptions& adaptive,
                                      std::optional<double> reference_mean_ratio = std::nullopt,
                                      const IterationCallback& on_iteration = {});

}  // namespace tspline

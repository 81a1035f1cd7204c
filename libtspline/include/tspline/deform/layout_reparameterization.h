#pragma once
// A new multi-patch map for a moved domain, from the previous one: the same
// layout (patches, corners, interfaces), T-meshes and knots. The rings' motion
// (vertex i of ring k to vertex i of ring k) moves every point of the layout:
// points on the rings with the ring edge they lie on, inner layout nodes and
// cut points by the motion's global affine part plus the mean value
// interpolant of the rings' residual motion (linear along each ring edge). Each patch then moves like a single
// patch (reparameterization.h) with the layout's one affine part, so that two
// patches agree on their common side; knots are equalized across interfaces
// where a patch had to refine.
#include <array>
#include <cstddef>
#include <vector>

#include <optional>

#include "tspline/boundary/domain.h"
#include "tspline/deform/boundary_deformation.h"
#include "tspline/layout/ring_geometry.h"
#include "tspline/multipatch/multipatch_parameterization.h"

namespace tspline {

/// What the previous multi-patch map is made of (a version-2 T-spline file).
struct PreviousLayout {
  Domain domain;  ///< the rings it was built on (validated: CCW, file_index)
  std::vector<const TSplineMap*> maps;
  std::vector<Polygon> polygons;  ///< per patch, as stored (CCW)
  std::vector<std::array<std::size_t, 4>> corners;
  std::vector<Interface> interfaces;
  std::vector<Cut> cuts;
  /// Per patch, its map's whole-map J_r if known (a run in memory); empty: measured.
  std::vector<double> reference_mean_ratio;
};

/// Moves any point of the previous domain (on a ring or inside) with the rings.
class LayoutMotion {
 public:
  /// \pre old and moved have the same rings and vertex counts (ring k vertex i moved to ring k vertex i).
  LayoutMotion(const Domain& old, const Domain& moved);
  Eigen::Vector2d operator()(const Eigen::Vector2d& x) const;
  const BoundaryDeformation& deformation() const { return global_; }

 private:
  std::vector<Eigen::Vector2d> old_, new_;  // all rings' vertices, ring after ring
  std::vector<std::size_t> ring_start_;      // first vertex of each ring in old_ (and its end)
  BoundaryDeformation global_;
  double tolerance_ = 0.0;                   // "on a ring": closer than this to a ring edge
  std::optional<RingGeometry> rings_;        // the old rings' edges, bucketed
};

/// The moved domain's map. `layout_sweeps`: sweeps of the layout optimizer
/// (layout_optimizer.h) over the inner nodes of a quad layout on the moved
/// rings, the ring nodes and the topology kept (0: the nodes stay where the
/// motion put them). `moved`: rings in the previous domain's numbering
/// (corresponding_polygon per ring). \throw InputError: other ring or vertex
/// counts, a moved ring that is not simple or crosses another (validate_domain's
/// message), a reflection, or a motion so large that a patch of the layout
/// folds (then map the domain from scratch); NumericalError as the patch runs.
MultiPatchResult reparameterize_layout(const PreviousLayout& old, const Domain& moved,
                                       const ParameterizationOptions& options, const AdaptiveOptions& adaptive,
                                       const MultiPatchOptions& multi = {}, const PatchCallback& on_patch = {},
                                       int layout_sweeps = 8);

}  // namespace tspline

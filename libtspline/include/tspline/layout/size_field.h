#pragma once
// The patch size a quad layout should have at each point of the domain: the
// local width of the domain (how far it is across a neck, an inlet, a strait
// between two islands), extended inside with a bounded growth rate.
//
// Width at a boundary sample p: the shortest edge p-q of the constrained
// Delaunay triangulation of the densified rings, inside the domain, whose ends
// are "across" from each other: on different rings, or on one ring with an arc
// length between them of more than `across_ratio` times their distance (so that
// neighbours along the coast, and the two sides of a convex corner, do not
// count). The Delaunay graph contains the nearest-neighbour graph, so the
// narrowest place of a neck is such an edge once the rings are sampled finer
// than the neck. Then
//     h(x) = min(max_size, min over samples p of (factor w(p) + grading |x - p|)),
// at least min_size, computed on a background grid by a two-pass chamfer
// propagation (the Lipschitz extension of the boundary values) and
// interpolated bilinearly.
#include <Eigen/Core>
#include <vector>

#include "tspline/boundary/domain.h"

namespace tspline {

struct SizeFieldOptions {
  /// Patch size per unit of local width: 1/2, two patches across every neck
  /// (the quad mesher meshes at twice the size and splits, so that its coarse
  /// elements are as wide as the neck).
  double factor = 0.5;
  double grading = 0.35;      ///< growth of the size per unit distance from the boundary
  double min_size = 0.0;      ///< absolute; widths below are not resolved
  double max_size = 0.0;      ///< absolute; 0: an eighth of the bounding-box diagonal
  double across_ratio = 2.5;  ///< arc length / distance above which two samples of a ring face each other
  int grid_cells = 768;       ///< grid cells along the longer side of the bounding box
  bool operator==(const SizeFieldOptions&) const = default;
};

class SizeField {
 public:
  /// \pre `domain` is validated (rings counter-clockwise).
  SizeField(const Domain& domain, const SizeFieldOptions& options = {});
  double operator()(const Eigen::Vector2d& x) const;
  /// Local width at the ring samples (for reports and tests): the smallest
  /// width found over the whole domain.
  double min_width() const { return min_width_; }

 private:
  Eigen::Vector2d lo_;
  double cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
  std::vector<double> h_;  // (nx_ + 1) x (ny_ + 1) node values
  double min_size_ = 0.0, max_size_ = 0.0, min_width_ = 0.0;
};

}  // namespace tspline

#pragma once
// Chord-length correspondence between the polygon and the boundary of [0,1]^2.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "tspline/boundary/corners.h"
#include "tspline/boundary/polygon.h"

namespace tspline {

/// Sides of the unit square, and the direction of their chord parameter t in [0,1]:
/// Bottom: xi 0->1 (t = xi), Right: eta 0->1 (t = eta),
/// Top: xi 1->0 (t = 1 - xi), Left: eta 1->0 (t = 1 - eta).
/// The sides follow the CCW polygon from corner k to corner k+1.
enum class Side { Bottom = 0, Right = 1, Top = 2, Left = 3 };

/// The four corners split the CCW polygon into four chains, each mapped by
/// chord length onto its side of the unit square.
class BoundaryMap {
 public:
  /// \throw InputError unless the corners are distinct, in range and in
  /// CCW order; NumericalError if an edge is too short for a strictly increasing
  /// chord parameter (length below double resolution relative to its chain).
  BoundaryMap(Polygon ccw_polygon, Corners corners);

  const Polygon& polygon() const { return polygon_; }
  const Corners& corners() const { return corners_; }

  /// Point of the polygon at chord parameter t in [0,1] on `side` (t=0 at the
  /// chain's first corner). Exact at the chain's vertices. O(log n).
  /// \throw InputError if t is not in [0,1].
  Eigen::Vector2d point(Side side, double t) const;

  /// Physical point for a parametric point on the boundary of [0,1]^2
  /// (one coordinate must be 0 or 1). \throw InputError otherwise.
  Eigen::Vector2d point_at(const Eigen::Vector2d& uv) const;

  /// Chain of `side`: polygon vertices from its first corner to its last corner
  /// (inclusive) and their chord parameters (0 ... 1, strictly increasing).
  const std::vector<Eigen::Vector2d>& chain_points(Side side) const;
  const std::vector<double>& chain_params(Side side) const;
  /// Length of the chain.
  double chain_length(Side side) const;

  /// Index range [first, last) into chain_points(side) of the vertices whose
  /// chord parameter lies strictly inside (t0, t1), t0 < t1 (empty range otherwise). O(log n).
  std::pair<std::size_t, std::size_t> vertices_between(Side side, double t0, double t1) const;

 private:
  Polygon polygon_;
  Corners corners_;
  std::array<std::vector<Eigen::Vector2d>, 4> chain_points_;
  std::array<std::vector<double>, 4> chain_params_;
  std::array<double, 4> chain_length_{};
};

}  // namespace tspline

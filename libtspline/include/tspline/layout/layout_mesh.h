#pragma once
// The coarse quadrilateral mesh of a quad layout while it is being built: its
// nodes (inside the domain, or on a ring at an arc length), its quads (the
// future patches) and the rings they run along. A quad edge used by one quad
// only lies on a ring: the patch side there is the ring's own polyline between
// the two nodes, not the chord.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "tspline/layout/ring_nodes.h"

namespace tspline {

struct LayoutMesh {
  std::vector<Eigen::Vector2d> x;          ///< node positions
  std::vector<int> ring;                   ///< per node: its ring, -1 inside
  std::vector<double> arc;                 ///< per ring node: arc length on its ring
  std::vector<std::array<int, 4>> quads;   ///< counter-clockwise
  std::size_t size() const { return x.size(); }
};

/// The rings of the domain with the side of the domain: the outer ring (0) has
/// the domain on its left, the holes on their right (all rings counter-clockwise).
struct LayoutRings {
  std::vector<RingCurve> curves;
  /// +1 for the outer ring, -1 for holes: the arc direction in which a
  /// counter-clockwise quad runs along the ring.
  double direction(int r) const { return r == 0 ? 1.0 : -1.0; }
};

/// Adjacency of a LayoutMesh, rebuilt after every change of its quads.
class LayoutTopology {
 public:
  explicit LayoutTopology(const LayoutMesh& m);
  /// Quads around node n, and the corner index of n in each.
  const std::vector<std::pair<int, int>>& corners_of(int n) const { return corners_[n]; }
  std::size_t valence(int n) const { return corners_[n].size(); }
  /// Whether edge j of quad q (from quads[q][j] to quads[q][(j + 1) % 4]) lies on a ring.
  bool on_ring(int q, int j) const { return on_ring_[4 * static_cast<std::size_t>(q) + j]; }
  /// The other quad sharing edge j of quad q and that edge's index in it, or (-1, -1).
  std::pair<int, int> across(int q, int j) const { return across_[4 * static_cast<std::size_t>(q) + j]; }

 private:
  std::vector<std::vector<std::pair<int, int>>> corners_;
  std::vector<char> on_ring_;
  std::vector<std::pair<int, int>> across_;
};

}  // namespace tspline

#pragma once
// The true rings of a domain as a point set to test a layout against: which
// points lie inside the domain, which segments cross a ring, which ring edge
// is nearest. Ring edges are bucketed on a uniform grid; intersections use
// CGAL's exact predicates.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "tspline/layout/ring_nodes.h"

namespace tspline {

/// Distance of p from the segment [a, b].
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b);
/// Whether the closed segments [a, b] and [c, d] share a point (exact predicates).
bool segments_intersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                        const Eigen::Vector2d& d);

class RingGeometry {
 public:
  struct Edge {
    Eigen::Vector2d a, b;
    int ring;
    std::size_t index;  ///< from vertex index to index + 1 of its ring
  };
  /// Any set of edges (the rings' own, or chords between nodes).
  RingGeometry(std::vector<Edge> edges, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi);
  /// The edges of the rings.
  static RingGeometry of_rings(const std::vector<RingCurve>& rings);

  const Edge& edge(int e) const { return edges_[e]; }
  std::size_t size() const { return edges_.size(); }
  /// The edges whose grid cells meet the box [lo, hi], each once.
  std::vector<int> near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;
  /// Whether p is inside the region the edges bound (parity of a ray's crossings).
  bool inside(const Eigen::Vector2d& p) const;
  /// Whether the segment from a to b meets an edge anywhere but at its own ends
  /// where they lie on a ring (a_on_ring, b_on_ring: within tol of an edge),
  /// or ends on an edge with its other end on that edge's line (a flat
  /// corner: the rule of the patch layout's validate_cuts).
  bool crosses(const Eigen::Vector2d& a, const Eigen::Vector2d& b, bool a_on_ring, bool b_on_ring, double tol) const {
    return crossing(a, b, a_on_ring, b_on_ring, tol) >= 0;
  }
  /// Whether a cut from a to b may lie where it lies: it crosses no edge
  /// (crosses()) and, if both ends are on rings, its midpoint is inside (with
  /// no crossing the whole cut is then inside; between two ring points it may
  /// also lie wholly outside, touching the rings at its ends only). The rule
  /// of the patch layout's validate_cuts.
  bool admits_cut(const Eigen::Vector2d& a, const Eigen::Vector2d& b, bool a_on_ring, bool b_on_ring,
                  double tol) const {
    return !crosses(a, b, a_on_ring, b_on_ring, tol) && !(a_on_ring && b_on_ring && !inside(0.5 * (a + b)));
  }
  /// The first edge crossed as by crosses(), or -1.
  int crossing(const Eigen::Vector2d& a, const Eigen::Vector2d& b, bool a_on_ring, bool b_on_ring, double tol) const;
  /// The edge nearest to p (brute force over the grid cells around it, widening).
  int nearest(const Eigen::Vector2d& p) const;

 private:
  template <class F>
  void for_cells(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, F&& f) const;
  int column(double x) const;  ///< the grid column of x, clamped
  int row(double y) const;     ///< the grid row of y, clamped
  /// Whether the segment crosses edge f, by the rule of crosses().
  bool crosses_edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Edge& f, bool a_on_ring,
                    bool b_on_ring, double tol) const;
  std::vector<Edge> edges_;
  std::vector<std::vector<int>> cells_;
  Eigen::Vector2d lo_;
  double cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
};

}  // namespace tspline

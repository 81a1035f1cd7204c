#pragma once
// The nodes of a quad layout on the domain's rings: the points where patch
// sides along the boundary begin and end.
//
// A patch side along a ring is the ring's own polyline between two nodes, so
// the nodes decide how much of the coast one side must follow. They are chosen
// by a relative Douglas-Peucker split: a piece of ring between two nodes is
// split at its vertex farthest from its chord while that distance exceeds
// `max_deviation` times the chord (a deep inlet, a sharp tip or a peninsula
// inside one side would cost the patch its quality; wiggles small against the
// side do not), at the ring's corners (a turn of more than 40 degrees on the
// scale of a quarter piece, or of more than 150 degrees at the vertex itself:
// the tip of a spike or a crack of any size), and then at equal arc length
// while the chord is longer than the local patch size (size_field.h). Other
// features smaller than `min_size` are not resolved: they stay inside one
// side and the patch's T-mesh follows them.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "tspline/boundary/domain.h"

namespace tspline {

/// std::fmod(s, length), without its division where s lies in [0, length)
/// already (then fmod returns s itself): ring arc lengths mostly do.
inline double arc_mod(double s, double length) { return s >= 0.0 && s < length ? s : std::fmod(s, length); }

/// Arc-length parameterization of one closed ring (a validated, CCW ring).
class RingCurve {
 public:
  explicit RingCurve(const std::vector<Eigen::Vector2d>& vertices);
  double length() const { return arc_.back(); }
  std::size_t size() const { return v_.size(); }
  const Eigen::Vector2d& vertex(std::size_t i) const { return v_[i % v_.size()]; }
  /// Arc length of vertex i from vertex 0 (i may be size(): the whole ring).
  double arc(std::size_t i) const { return arc_[i]; }
  /// The point at arc length s (taken modulo the length).
  Eigen::Vector2d point(double s) const;
  /// Largest distance of the ring's vertices strictly between arc lengths a < b
  /// (b may exceed length(): the piece wraps past vertex 0) from the chord, and
  /// the arc length of that vertex (-1 if there is none).
  std::pair<double, double> farthest_from_chord(double a, double b) const;
  /// The arc length of the vertex nearest to arc length s if it is within eps
  /// (so that a node never lies a hair's breadth from a vertex: the patch
  /// polygon would have a needle edge there), else s; in [0, length).
  double snap_to_vertex(double s, double eps) const;
  /// Unit direction in which the ring leaves the point at arc length s going
  /// forward (dir > 0: the edge after s) or backward (dir < 0: the edge before
  /// s, reversed); at a vertex the two differ.
  Eigen::Vector2d direction(double s, double dir) const;
  /// Signed turn at vertex i in (-pi, pi], counter-clockwise positive.
  double turn(std::size_t i) const;
  /// Index of the first vertex with arc length strictly greater than s (mod
  /// length), in [0, size()]; size() wraps to vertex 0 of the next lap.
  std::size_t first_vertex_after(double s) const;

 private:
  /// The edge i with arc(i) <= s < arc(i + 1), and s reduced to [0, length).
  std::pair<std::size_t, double> edge_at(double s) const;
  std::vector<Eigen::Vector2d> v_;
  std::vector<double> arc_;  // size() + 1 entries
};

struct RingNodeOptions {
  double max_deviation = 0.2;  ///< split a piece while a vertex is farther than this x chord from it
  double min_size = 0.0;       ///< never split a piece shorter (by arc length) than this
  int min_nodes_per_ring = 4;  ///< a ring gets at least this many nodes
  /// Vertices where the ring turns by more than this (radians) on the scale of
  /// a quarter of the local piece size are nodes (corners of the domain).
  double corner_turn = 40.0 * 3.14159265358979323846 / 180.0;
  /// Vertices where the ring turns by more than this at the vertex itself (an
  /// inner angle below 30 or above 330 degrees: a spike, a crack) are nodes,
  /// whatever the scale of the feature.
  double sharp_turn = 150.0 * 3.14159265358979323846 / 180.0;
};

/// Nodes of one ring as arc lengths in [0, length), increasing, at ring vertices
/// where the Douglas-Peucker split chose them. `size` is the local patch size at
/// a point (pieces longer than it are split at equal arc length); may be empty.
std::vector<double> ring_nodes(const RingCurve& ring, const RingNodeOptions& options,
                               const std::function<double(const Eigen::Vector2d&)>& size = {});

/// Splits the pieces of `nodes` (arc lengths on `ring`) whose chord is longer
/// than size() at the piece's midpoint, at equal arc length. Returns the new nodes.
std::vector<double> split_long_pieces(const RingCurve& ring, std::vector<double> nodes,
                                      const std::function<double(const Eigen::Vector2d&)>& size, double min_size);

}  // namespace tspline

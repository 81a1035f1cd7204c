#pragma once
// Plane geometry on Eigen vectors, in floating point: the cross product,
// angles between directions and the signed area of a ring. (Predicates whose sign must be exact, such as whether
// a ring is simple, use CGAL's exact predicates instead: polygon_validation.)
#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <vector>

namespace tspline {

/// a x b: the z component of the 3D cross product, twice the signed area of
/// the triangle (0, a, b); > 0 when b lies counter-clockwise of a.
inline double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// The angle that turns direction a into direction b, counter-clockwise
/// positive, in [-pi, pi].
inline double signed_angle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::atan2(cross(a, b), a.dot(b));
}

/// The angle from direction a counter-clockwise to direction b, in [0, 2 pi):
/// with a towards the next vertex of a counter-clockwise ring and b towards
/// the previous one, the ring's inside angle there.
inline double ccw_angle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double t = signed_angle(a, b);
  return t < 0 ? t + 2.0 * std::numbers::pi : t;
}

/// ccw_angle in degrees, in [0, 360).
inline double ccw_degrees(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double d = signed_angle(a, b) * 180.0 / std::numbers::pi;
  return d < 0.0 ? d + 360.0 : d;
}

/// The signed area of the closed ring (> 0 counter-clockwise), by the shoelace
/// formula relative to the first vertex (less cancellation for rings far from
/// the origin, e.g. projected coastline coordinates); 0 below three vertices.
inline double signed_area(const std::vector<Eigen::Vector2d>& ring) {
  const std::size_t n = ring.size();
  if (n < 3) return 0.0;
  const Eigen::Vector2d o = ring[0];
  double twice = 0.0;
  for (std::size_t i = 1; i + 1 < n; ++i) twice += cross(ring[i] - o, ring[i + 1] - o);
  return 0.5 * twice;
}

}  // namespace tspline

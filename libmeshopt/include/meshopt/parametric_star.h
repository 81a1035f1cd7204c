#pragma once
// Point location in a face's parameter plane, to skip the costly exact test of
// a trimmed CAD face (gmsh::model::isInside) where the mesh already proves that
// a point is inside: it lies in a mesh element whose corners are in the face,
// away from the element edges along which a trimming curve may pass.
#include <Eigen/Core>

namespace meshopt {

/// True if p lies in triangle (a, b, c) of either orientation (boundary included).
bool in_triangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                 const Eigen::Vector2d& c);

/// Distance from p to the segment [a, b].
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

/// The margin, relative to an edge's length, within which a point near an edge
/// that a trimming curve may follow is left to the exact test (the curve
/// deviates from the straight edge by its sagitta, well below a quarter of it).
inline constexpr double kTrimmingMargin = 0.25;

}  // namespace meshopt

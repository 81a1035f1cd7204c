#pragma once
// Choice of the four polygon vertices that map to the corners of [0,1]^2.
#include <array>
#include <cstddef>
#include <string>

#include "tspline/polygon.h"

namespace tspline {

/// Four vertex indices into a validated, counter-clockwise Polygon, in CCW order,
/// mapped to the parametric corners (0,0), (1,0), (1,1), (0,1) respectively.
struct Corners {
  std::array<std::size_t, 4> index{};
  /// Human-readable explanation of how they were chosen (goes to the report).
  std::string explanation;
  /// Inner angle at each corner in degrees (measured at the polygon vertex).
  std::array<double, 4> inner_angle_deg{};
};

/// Corners from user input given in the FILE's own numbering (Polygon::file_index).
/// The four must be distinct, in range, and appear in cyclic order along the file's
/// vertex order (either direction of traversal is NOT accepted: they must follow
/// the file order i<j<k<l up to a cyclic shift). They are re-ordered for the CCW
/// polygon so that the user's first corner goes to (0,0) when the file is CCW.
/// \throw InputError naming the offending index.
Corners corners_from_file_indices(const Polygon& ccw_polygon, const std::array<long long, 4>& file_indices);

/// Automatic choice: prefers convex vertices with inner angle (measured at the
/// scale of the polygon, not only of its finest edges) near 90 degrees, and
/// balanced chain lengths. Deterministic. The explanation says why.
Corners choose_corners(const Polygon& ccw_polygon);

}  // namespace tspline

#pragma once
// Choice of the four polygon vertices that map to the corners of [0,1]^2.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"

namespace tspline {

/// Four vertex indices into a validated, counter-clockwise Polygon, in CCW order,
/// mapped to the parametric corners (0,0), (1,0), (1,1), (0,1) respectively.
struct Corners {
  std::array<std::size_t, 4> index{};
  /// Human-readable explanation of how they were chosen (goes to the report).
  std::string explanation;
  /// Inner angle at each corner in degrees, measured at the polygon vertex itself
  /// (between its two adjacent edges; the explanation also gives the angle at the
  /// scale of the polygon, between chords to the points at arc length +-1..4% of
  /// the perimeter, which is what the automatic choice uses).
  std::array<double, 4> inner_angle_deg{};
};

/// Corners from user input given in the FILE's own numbering (Polygon::file_index).
/// The four must be distinct, in range [0, n), and in cyclic order of the file
/// numbering: some cyclic rotation of (i, j, k, l) is strictly increasing (e.g.
/// 3 10 20 40 or 20 40 3 10, but not 3 20 10 40 nor the reverse 40 20 10 3).
/// The user's first corner always maps to (0,0). If the file was counter-clockwise
/// the next corners map to (1,0), (1,1), (0,1) in the given order; if the file was
/// clockwise (validate_polygon reversed it) they are traversed in reverse, so that
/// the CCW polygon meets them as i, l, k, j, mapped to (0,0), (1,0), (1,1), (0,1).
/// \throw InputError naming the offending corner and index ("corner 3: vertex
/// index 4 is out of cyclic order ..."; "... is out of range ..."; "... is repeated ...").
Corners corners_from_file_indices(const Polygon& ccw_polygon, const std::array<long long, 4>& file_indices);

/// Automatic choice: prefers convex vertices with inner angle (measured at the
/// scale of the polygon, not only of its finest edges) near 90 degrees, and
/// balanced chain lengths. Deterministic; O(n log n + K^4) with K <= 72 candidate
/// vertices (the best-angled convex vertices plus equally spaced fallbacks). The
/// corner whose chord to the next corner points most nearly along +x maps to (0,0).
/// The explanation says why.
Corners choose_corners(const Polygon& ccw_polygon);

/// The `count` cheapest automatic choices (by the same cost; the first is
/// choose_corners()), mutually distinct: any two differ in some corner by more
/// than 2% of the perimeter. Fewer if there are not that many.
std::vector<Corners> corner_candidates(const Polygon& ccw_polygon, std::size_t count);

}  // namespace tspline

#pragma once
// Validation of an input polygon with CGAL's exact predicates, and orientation.
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"

namespace tspline {

/// Coordinates beyond +-kMaxPolygonCoordinate, and polygons whose bounding box
/// is smaller than kMinPolygonExtent on both sides, are rejected (not
/// rescaled): the pipeline squares lengths (tolerance areas, Jacobian
/// determinants, energies), which must stay far inside the range of doubles.
/// A user rescales once (km, m, mm, ...) and keeps the units of the output.
inline constexpr double kMaxPolygonCoordinate = 1e50;
inline constexpr double kMinPolygonExtent = 1e-50;

/// \throw InputError naming the vertex or the extent if the polygon's scale is
/// outside the supported range above (called by validate_polygon).
void check_polygon_scale(const Polygon& p);

/// Checks that `p` is a simple polygon usable as a domain boundary and returns it
/// oriented counter-clockwise (vertex order reversed if it was clockwise; the
/// file_index entries travel with their vertices).
/// \throw InputError with a one-line message naming the problem:
///   fewer than 4 vertices; a NaN/inf coordinate (names the vertex); a scale
///   out of range (check_polygon_scale); two equal
///   consecutive vertices (names them); zero area; collinear-overlapping or
///   crossing edges (names the two edges by their file vertex indices, e.g.
///   "polygon is not simple: edges 3-4 and 10-11 intersect near (x, y)"; "overlap
///   near" for collinear overlaps). Runs in O(n log n + k), k = pairs of edges with
///   overlapping bounding boxes. An empty `file_index` is filled with 0..n-1.
Polygon validate_polygon(Polygon p);

/// What clean_polygon did.
struct PolygonCleaning {
  Polygon polygon;                               ///< the cleaned polygon, file numbering kept
  std::vector<std::size_t> removed_file_indices;  ///< sorted
  std::vector<std::string> notes;                ///< one per removed vertex, in the file's numbering
};

/// Real data is cleaned, not rejected: removes vertices that repeat their
/// predecessor (also across the closing seam) and tips of zero-area spikes (an
/// edge that doubles back along the previous one, exactly collinear), with a
/// note per vertex in the file's numbering. True crossings are left for
/// validate_polygon to reject. Non-finite coordinates are left as well.
PolygonCleaning clean_polygon(Polygon p);

/// Signed area (positive for counter-clockwise).
double signed_area(const Polygon& p);

}  // namespace tspline

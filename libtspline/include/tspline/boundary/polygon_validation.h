#pragma once
// Validation of an input polygon with CGAL's exact predicates, and orientation.
#include <optional>
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
/// `min_vertices`: 4 for a ring that carries a patch's four corners (the
/// outer ring of a single-patch domain), 3 for a hole (an islet can be a triangle).
Polygon validate_polygon(Polygon p, std::size_t min_vertices = 4);

/// Needles narrower than this fraction of the bounding-box diagonal d are
/// removed when no width is given (validate_domain): the width that the default
/// boundary tolerance epsilon = 1e-5 d^2 (ParameterizationOptions::
/// tolerance_relative) gives by needle_width_for_tolerance.
inline constexpr double kDefaultNeedleWidthRelative = 1e-5;

/// The diagonal of the polygon's bounding box (0 for an empty polygon).
double bounding_box_diagonal(const Polygon& p);

/// The needle width that goes with the boundary tolerance epsilon (an AREA,
/// ParameterizationOptions::tolerance_absolute / tolerance_relative) on a domain
/// of bounding-box diagonal d: epsilon / d, the width of a strip as long as the
/// diagonal whose area is epsilon. A needle narrower than this encloses less area
/// than the tolerance the boundary is approximated to, wherever it lies.
double needle_width_for_tolerance(double tolerance_area, double diagonal);

/// The needle width for a ring and a boundary tolerance (absolute epsilon, or
/// relative r: epsilon = r d^2): needle_width_for_tolerance(epsilon(d), d) with d
/// the bounding-box diagonal of the ring as cleaned at that width. The ring's
/// own diagonal is used unless cleaning at its width removes what spans the
/// bounding box (the diagonal halves, or the ring collapses: a 4e9 km typo spike
/// on an island must not make the whole island "narrower than the tolerance"):
/// then the cleaned ring's diagonal gives the width, and if that collapses too,
/// 0 (exact spikes only). Non-finite coordinates give 0.
double needle_width_for_ring(const Polygon& p, std::optional<double> tolerance_absolute, double tolerance_relative);

/// What clean_polygon did.
struct PolygonCleaning {
  Polygon polygon;                               ///< the cleaned polygon, file numbering kept
  std::vector<std::size_t> removed_file_indices;  ///< sorted
  std::vector<std::string> notes;                ///< one per removed vertex, in the file's numbering
  std::size_t needles = 0;         ///< tips removed (zero-area spikes and needles narrower than needle_width)
  double max_needle_width = 0.0;   ///< the widest of them (0 for exactly collinear spikes)
};

/// Real data is cleaned, not rejected: removes vertices that repeat their
/// predecessor (also across the closing seam), or lie within `needle_width` of it
/// where a needle's tip has just gone (its two base vertices; of two such
/// vertices the later in the file goes), and the tips of needles: a vertex
/// b between a and c where the ring goes out and comes back (the edges at b make
/// an angle below 90 degrees) and the nearer of a, c lies within `needle_width`
/// of the line of the other edge (the needle's width). `needle_width` = 0 removes
/// exactly collinear spikes only (an edge that doubles back along the previous
/// one; exact predicates). Removal repeats until no needle is left, across the
/// closing seam (vertex 0) too; each removed tip changes the area by at most
/// needle_width x (the longer edge) / 2. A note per vertex in the file's
/// numbering. True crossings are left for validate_polygon to reject.
/// Non-finite coordinates are left as well. \throw InputError if
/// needle_width is negative or not finite.
PolygonCleaning clean_polygon(Polygon p, double needle_width = 0.0);

/// validate_polygon(c.polygon, min_vertices) for a ring cleaned by
/// clean_polygon(ring, needle_width); a ring whose needles leave fewer than
/// min_vertices vertices is named as what it is: \throw InputError "the ring
/// encloses no area: it is nothing but needles narrower than 0.000141 (2 of its
/// 3 vertices are left once they are removed)" ("nothing but zero-area spikes"
/// for needle_width 0).
Polygon validate_cleaned_polygon(PolygonCleaning c, double needle_width, std::size_t min_vertices = 4);

/// One line for the progress notes: "<ring>: " and the first few per-vertex
/// notes ("removed vertex 0 (...); removed vertex 5 (...)"), "and N more" after
/// them; empty if nothing was removed.
std::string cleaning_summary(const std::string& ring, const PolygonCleaning& c);

/// Signed area (positive for counter-clockwise).
double signed_area(const Polygon& p);

}  // namespace tspline

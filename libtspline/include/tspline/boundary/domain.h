#pragma once
// A planar domain with holes: an outer ring and hole rings, validated as a
// whole (every ring simple, holes strictly inside the outer ring, no two rings
// crossing or touching, no hole inside another).
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"

namespace tspline {

/// The outer boundary and the holes, each a Polygon in its file's numbering.
/// After validate_domain() every ring is oriented counter-clockwise (the
/// domain lies to the left of the outer ring and to the right of each hole).
struct Domain {
  Polygon outer;
  std::vector<Polygon> holes;
};

/// Name of ring r in messages: ring 0 is "the outer ring", ring k >= 1 is "hole k".
std::string ring_name(std::size_t r);

/// How validate_domain cleans the rings.
struct DomainCleaningOptions {
  /// Needles narrower than this are removed from every ring (clean_polygon);
  /// unset: needle_width_for_ring(outer, none, kDefaultNeedleWidthRelative), i.e.
  /// 1e-5 x the outer ring's bounding-box diagonal, the width of the default
  /// boundary tolerance. A caller with another boundary tolerance passes
  /// needle_width_for_ring(outer, tolerance_absolute, tolerance_relative).
  std::optional<double> needle_width;
  /// If set, receives one note per ring that was cleaned ("hole 9: removed
  /// vertex 0 (tip of a zero-area spike: edges 6-0 and 0-1 overlap)"), in ring order.
  std::vector<std::string>* notes = nullptr;
  /// A hole whose ring crosses itself (a bow-tie islet of quantized data) is
  /// replaced by its convex hull, with a note giving both areas, if the hull's
  /// area is at most this: the islet lies wholly below the boundary tolerance
  /// (the hull contains every reading of the crossing ring, so the domain
  /// changes by less than the area epsilon the boundary fit may leave between
  /// the map and one polygon segment, Sect. 3). Unset: epsilon of the needle
  /// width, needle_width x the outer ring's bounding-box diagonal.
  std::optional<double> crossing_repair_area;
  /// Every hole that crosses itself is replaced by its convex hull, whatever
  /// its size. Off: a crossing hole larger than crossing_repair_area is an
  /// input error naming the ring and edges. The outer ring is never repaired.
  bool repair_crossing_holes = false;
  /// Tips of the domain sharper than this (degrees; a patch corner of angle
  /// theta has scaled Jacobian sin(theta) in every map) are cut off by a chord
  /// that removes at most blunt_tip_area each, with a note per tip
  /// (blunt_sharp_tips, sharp_tips.h); 0 keeps every tip. If a cut would make
  /// two rings meet, no tip is cut (one note says so).
  double blunt_tips_below_degrees = 0.0;
  /// The area each tip's cut may remove. Unset: as crossing_repair_area (the
  /// boundary tolerance's epsilon).
  std::optional<double> blunt_tip_area;
  /// If set, receives the number of tips cut off.
  std::size_t* blunted_tips = nullptr;
};

/// Cleans (clean_polygon: repeated vertices, needles and spikes narrower than
/// the needle width, anywhere in the ring, vertex 0 too), validates and orients
/// the domain; the file numbering of every ring is kept in messages. The outer
/// ring needs 4 vertices, a hole 3; a hole that is nothing but needles (no
/// area at the needle width: an islet below the boundary tolerance) is dropped
/// with a note.
/// \throw InputError with one line naming the rings and edges (file vertex
/// indices of the ring): a ring that is not a simple polygon (prefixed with the
/// ring's name), "hole 2 crosses the outer ring: edge 4-5 of hole 2 and edge
/// 0-1 of the outer ring intersect near (x, y)" (also for touching rings), "hole
/// 1 lies outside the outer ring", "hole 3 lies inside hole 1".
Domain validate_domain(Domain d, const DomainCleaningOptions& cleaning = {});

/// Area of the outer ring minus the areas of the holes (a validated domain).
double domain_area(const Domain& d);

/// Whether p lies strictly inside the domain (inside the outer ring and
/// outside every hole; points on a ring count as outside).
bool domain_contains(const Domain& d, const Eigen::Vector2d& p);

}  // namespace tspline

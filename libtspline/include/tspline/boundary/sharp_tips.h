#pragma once
// Sharp tips of the domain blunted within the boundary tolerance.
//
// Each patch of a map is the image of the unit square with its sides along the
// boundary, so at a patch corner the Jacobian is the pair of boundary tangents
// there: a tip of the domain with angle theta that is a patch corner has scaled
// Jacobian sin(theta) in every map, and one that is not a patch corner has
// det J = 0 (a smooth side cannot turn there). A 10.5-degree cape caps the
// whole map's scaled Jacobian at 0.18, whatever the layout and the optimizer.
//
// The map only approximates the polygon: the boundary fit leaves between the
// map and each polygon segment triangles of area up to the boundary tolerance
// epsilon (an AREA; Brovka 2013, Sect. 3). Cutting a tip off by a chord that
// removes at most epsilon changes the domain by no more than the fit already
// may, and turns one corner of theta into two of about 90 + theta / 2 degrees.
#include <cstddef>
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"

namespace tspline {

struct TipBlunting {
  Polygon polygon;                 ///< the ring with its tips cut (file numbering kept; see blunt_sharp_tips)
  std::vector<std::string> notes;  ///< one per tip cut, in the file's numbering
  std::size_t tips = 0;            ///< tips cut
  double removed_area = 0.0;       ///< the area of all cut-off pieces together
};

/// Cuts off every tip of the domain sharper than `max_degrees` (the domain's
/// angle at a ring vertex: on the left of a counter-clockwise outer ring, on
/// the right of a counter-clockwise hole) by a chord between the two points at
/// equal arc length d from the tip along the ring, d the largest whose cut-off
/// piece has area at most `max_area` (several vertices may go where the tip is
/// made of short edges). A tip is left as it is if the chord would make a
/// corner of 170 degrees or more at either end (the tip is the end of a long
/// thin feature whose sides run on: shorter cuts are tried first), or if the
/// ring would not stay simple, or if the chord would be shorter than
/// `min_width` (a facet narrower than the needle width is a feature below the
/// tolerance again: a typo vertex thousands of km out gives a spike so thin
/// that the area allows only such a facet). Both cut points carry the tip's file index (a
/// corner given at the tip lands on its second cut point). Tips whose pieces
/// would overlap are cut one after the other.
/// \param ring validated and counter-clockwise (validate_polygon).
/// \param hole whether the domain lies outside the ring.
/// \param ring_label the ring's name in notes ("the outer ring", "hole 3").
/// \throw InputError if max_degrees is not in [0, 90], or max_area or min_width is negative or not finite.
TipBlunting blunt_sharp_tips(Polygon ring, bool hole, double max_degrees, double max_area, double min_width,
                             const std::string& ring_label);

/// The domain angle (degrees, in (0, 360)) at vertex i of a counter-clockwise
/// ring: inside for the outer ring, outside for a hole.
double domain_angle_degrees(const Polygon& ring, std::size_t i, bool hole);

}  // namespace tspline

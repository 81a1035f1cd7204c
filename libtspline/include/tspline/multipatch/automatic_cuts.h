#pragma once
// Automatic cuts of a domain with holes into four-sided patches (patch_layout.h).
//
// Candidates are straight segments from each hole to the nearest point of
// another ring and to the sharp convex vertices of other rings. A layout takes
// k cuts per hole (k = 2, 3, 4, each tried; cheapest first, or those into sharp
// vertices first), joins every hole to the outer ring, then splits every patch
// with more than four cut ends by chords that cut a four-sided patch off it:
// between two of its cut ends (the rest keeps two cut ends fewer), or from a
// cut end along the bisector of its angle (within 30 degrees) into the ring
// side that makes the piece four-sided (the rest keeps one fewer); in half of
// the variants the sharp convex ring vertices (<= 120 degrees) count as cut
// ends there, so that patches get them as corners. The layout kept is the
// cheapest by
//   sum of cut lengths / sqrt(area)
//   + sum over corners of ((angle - 90 deg) / 90 deg)^2
//   + sum over kinks inside patch sides (turn > 25 deg at 1/40 of the patch's
//     perimeter) of 4 (turn / 90 deg)^2 (a kink inside a side costs more than
//     a corner of 45 degrees: the spline side cannot follow it, and the map
//     loses area and quality there)
//   + for each cut end, ((a - b) / (a + b))^2, a and b the angles on its two sides,
// that is: short cuts, meeting the boundary at right angles or bisecting its
// corners, and patches whose sides are smooth and corners near 90 degrees.
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/multipatch/patch_layout.h"

namespace tspline {

struct AutomaticCuts {
  std::vector<Cut> cuts;
  double cost = 0.0;
  std::string explanation;  ///< which variant was kept, for the report
};

/// \pre `domain` is validated and has at least one hole.
/// \throw InputError if no variant gives a layout of four-sided patches
/// (the message suggests --cuts).
AutomaticCuts automatic_cuts(const Domain& domain);

/// The cost above of a layout (for reports and tests).
double layout_cost(const Domain& domain, const PatchLayout& layout);

}  // namespace tspline

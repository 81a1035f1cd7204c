#pragma once
// Internal to libtspline (the parameterization's T-mesh optimization), not part of the public interface.
// Local submesh templates of the T-mesh optimization (Brovka 2013 Sect. 4.2-4.3,
// Fig. 4, Eqs. 4-5, Appendix).
//
// For a free vertex x and each cell around it, the triangles are (x, p, q) for
// every pair p, q of the cell's other corners that is not collinear with x in
// the parametric domain, oriented counter-clockwise there:
//  - x a corner of the cell: 3 triangles (the three corner triangles of the
//    quadrilateral that contain x);
//  - x a T-junction in the cell's edge: the cell's 4 corners give 6 pairs, one of
//    them (the two ends of x's edge) is collinear with x, leaving 5 triangles.
// The ideal triangle is the parametric one. Weights: regular vertex, each cell's
// group by its scale tau = size / (smallest size around x) in {1, 2, 4} (Eq. 4);
// hanging vertex, the T-junction cell's 5 triangles 8/5, the two others 1 (Eq. 5).
#include <vector>

#include "meshopt/local_objective.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline::detail {

/// The triangles of the local submesh of vertex v (any vertex, boundary ones
/// included: only the cells inside [0,1]^2 contribute). `weighted` = false gives
/// the unweighted K* (all weights 1), for comparison.
std::vector<meshopt::LocalTriangle> local_submesh(const TMesh& mesh, int v, bool weighted = true);


}  // namespace tspline::detail

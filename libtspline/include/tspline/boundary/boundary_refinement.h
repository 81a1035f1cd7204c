#pragma once
// Refinement of the T-mesh until its boundary edges approximate the polygon
// within a tolerance (Brovka 2013 Sect. 3, Fig. 2a).
#include <cstddef>
#include <limits>

#include "tspline/boundary/boundary_map.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// Approximation error of the boundary cell edge whose chord parameters on
/// `side` are [t0, t1]: the largest area of the triangles formed by the physical
/// edge (the segment between the polygon points at t0 and t1) and each polygon
/// vertex strictly between t0 and t1. 0 if there is no such vertex.
double boundary_edge_error(const BoundaryMap& boundary, Side side, double t0, double t1);

struct BoundaryRefinementOptions {
  double tolerance_area = 0.0;  ///< epsilon: refine while some triangle area exceeds it (absolute units^2)
  int max_level = 22;           ///< cells are not refined beyond this level
  /// The T-mesh never has more leaves than this: InputError if meeting the
  /// tolerance needs more (a long thin feature, or a tolerance too fine).
  std::size_t max_cells = std::numeric_limits<std::size_t>::max();
};

struct BoundaryRefinementReport {
  std::size_t boundary_splits = 0;    ///< splits made by the area criterion
  std::size_t balance_splits = 0;     ///< splits made by 2:1 balancing
  std::size_t edges_over_tolerance = 0;  ///< boundary edges still above tolerance (at max_level)
  double max_error = 0.0;             ///< largest remaining boundary edge error
  int passes = 0;
};

/// Refines the boundary cells of `mesh` by the area criterion and re-balances
/// until every boundary edge meets the tolerance or reaches max_level. Builds the
/// topology at the end. \throw InputError if tolerance_area <= 0 or max_level is
/// invalid, or if the mesh would need more than max_cells cells.
BoundaryRefinementReport refine_to_boundary(TMesh& mesh, const BoundaryMap& boundary,
                                            const BoundaryRefinementOptions& options);

/// Side of the unit square and chord parameters [t0, t1] of a cell's edge that
/// lies on the boundary of [0,1]^2. Returns false if that edge is interior.
bool boundary_edge_params(const QuadNode& q, CellEdge edge, Side& side, double& t0, double& t1);

}  // namespace tspline

#pragma once
// Curved-element export for finite element codes (`tspline export --msh`):
// the Bezier elements of the T-spline map (bezier_extraction.h) as bicubic
// Lagrange quadrilaterals, Gmsh element type 36 (MSH_QUA_16), in Gmsh's MSH 4.1
// ASCII format.
//
// Every element's 16 nodes are points ON the map at the equispaced parametric
// positions lo + (hi - lo) (i/3, j/3), i, j = 0..3 (interpolatory nodes, not
// Bezier control points), in Gmsh's order for type 36: the 4 corners
// counter-clockwise from (0,0), then two nodes per edge along the edges 0-1,
// 1-2, 2-3, 3-0, then the 4 interior nodes counter-clockwise from (1/3,1/3).
// Nodes at the same parametric position (compared exactly, in integer T-mesh
// units) are one node, so elements that share a whole edge share its 4 nodes;
// at a T-junction the edge of the coarse element and those of the fine elements
// along it share only the nodes at common positions (the ends, and where the
// coarse edge's 1/3 and 2/3 points meet a fine node): a non-conforming,
// "hanging" interface.
//
// What is lost: the T-spline is C2 (rational) inside the smooth parts of the
// map; the Lagrange elements only interpolate it at the nodes, are C0 across
// shared edges and leave a small gap at T-junction interfaces; between nodes
// they differ from the map by the interpolation error (O(h^4)).
#include <cstddef>
#include <string>

#include "tspline/spline/tspline_map.h"

namespace tspline::io {

/// The 16 local positions (s, t) in [0,1]^2 of the nodes of a Gmsh type-36
/// quadrilateral, in Gmsh's node order.
extern const double kQua16Local[16][2];

struct MshExportStats {
  std::size_t elements = 0;
  std::size_t nodes = 0;
};

/// The MSH 4.1 ASCII text: one surface entity (tag 1, physical group 1
/// "domain"), the shared nodes, one type-36 element per Bezier element in the
/// order of BezierExtraction (element tag = index + 1).
std::string msh_document(const TSplineMap& map, MshExportStats* stats = nullptr);

/// Writes msh_document() atomically. \throw IoError.
MshExportStats write_msh_file(const std::string& path, const TSplineMap& map);

}  // namespace tspline::io

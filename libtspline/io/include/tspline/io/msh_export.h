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

#include <vector>

#include "tspline/multipatch/patch_layout.h"
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

/// A multi-patch map (format version 2): surface entity p + 1 per patch p (its
/// elements in one block, in BezierExtraction order; element tags numbered on
/// across the patches), each in the physical group 1 "domain" and its own group
/// p + 2 "patch p"; the nodes of a patch as above, and along every interface the
/// two patches share their nodes where the parametric positions correspond (t on
/// side_a of patch a is 1 - t on side_b of patch b, compared exactly; with the
/// shared interface knots of `tspline param` that is every node of the cut), so
/// that the mesh is conforming across cuts. A node belongs to the entity of the
/// first patch that has it. One patch and no interfaces: msh_document(map).
/// \throw InputError for an empty map list or an interface naming a
/// patch or side out of range.
std::string msh_document(const std::vector<const TSplineMap*>& maps, const std::vector<Interface>& interfaces,
                         MshExportStats* stats = nullptr);

/// Writes the multi-patch msh_document() atomically. \throw IoError.
MshExportStats write_msh_file(const std::string& path, const std::vector<const TSplineMap*>& maps,
                              const std::vector<Interface>& interfaces);

}  // namespace tspline::io

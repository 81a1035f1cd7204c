#pragma once
// Decomposition of a domain with holes into four-sided patches by cuts.
//
// A cut is a polyline inside the domain from a ring (outer ring or hole) to a
// ring, or to an end of another cut. The rings and the cuts form a plane graph;
// its faces inside the domain are the patches. The ends of the cuts are the
// nodes of the graph, and every node on a face is one of its four corners, so
// every cut is a whole side of each of its two patches: an interface along
// which both patches can share one parametrization and one set of knots (the
// map is then watertight, and the analysis can glue the functions, C0). A face
// with fewer than four nodes takes its sharpest convex ring vertices as the
// missing corners; one with more than four is an input error (the automatic
// cuts of automatic_cuts.h split such faces further).
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/boundary/polygon.h"

namespace tspline {

/// A polyline, at least two points; its ends on rings or at ends of other cuts.
using Cut = std::vector<Eigen::Vector2d>;

/// A face of the graph of rings and cuts (counter-clockwise, domain on the left).
struct LayoutFace {
  std::vector<Eigen::Vector2d> points;
  std::vector<char> is_node;  ///< per point: an end of a cut
  /// Per point, the edge from it to the next point: cut index, or -1 for a ring edge.
  std::vector<int> edge_cut;
  std::size_t nodes() const;
};

/// The faces of the graph inside the domain.
/// \pre `domain` is validated (validate_domain), `cuts` are valid (validate_cuts).
/// `ring_corners`: points on rings that are nodes although no cut ends there.
std::vector<LayoutFace> layout_faces(const Domain& domain, const std::vector<Cut>& cuts,
                                     const std::vector<Eigen::Vector2d>& ring_corners = {});

/// Checks the cuts against the domain and each other.
/// \throw InputError naming the cut(s) and ring edges: fewer than two points or
/// a non-finite coordinate; an end that lies neither on a ring nor at an end of
/// another cut; two cuts that cross or touch away from a shared end ("cuts 1
/// and 3 cross near (x, y)"); a cut that crosses or touches a ring away from its
/// ends; a cut outside the domain. Cuts are numbered from 1 in messages.
void validate_cuts(const Domain& domain, const std::vector<Cut>& cuts);

struct Patch {
  Polygon polygon;                     ///< counter-clockwise; file_index = position
  std::array<std::size_t, 4> corners;  ///< indices into polygon.vertices, CCW, mapped to (0,0), (1,0), (1,1), (0,1)
  std::array<int, 4> side_cut{-1, -1, -1, -1};  ///< cut forming side k (corner k to k+1), or -1 (a ring)
};

/// One cut as the common side of two patches. Both patches run counter-clockwise,
/// so they traverse the cut in opposite directions: the point at chord parameter
/// t on side a.side of patch a is the point at 1 - t on side b.side of patch b.
struct Interface {
  std::size_t cut = 0;
  std::size_t patch_a = 0, patch_b = 0;
  int side_a = 0, side_b = 0;
};

struct PatchLayout {
  std::vector<Cut> cuts;
  std::vector<Patch> patches;
  std::vector<Interface> interfaces;
};

/// The patches and interfaces of the domain cut by `cuts` (validated here).
/// \throw InputError as validate_cuts, or naming the face: not simply
/// connected or pinched (a hole with a single cut), more than four nodes, or
/// fewer than four corners with no convex ring vertex to complete them.
/// `ring_corners`: points on rings that are patch corners although no cut ends
/// there (a quad layout's corner at a sharp tip); InputError if one is off the rings.
PatchLayout build_patch_layout(const Domain& domain, std::vector<Cut> cuts,
                               const std::vector<Eigen::Vector2d>& ring_corners = {});

}  // namespace tspline

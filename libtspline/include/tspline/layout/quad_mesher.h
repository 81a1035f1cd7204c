#pragma once
// A coarse all-quadrilateral mesh of a straight-sided polygonal domain, by
// Gmsh (Frontal-Delaunay for quads, Blossom recombination, then the split of
// every element into quadrilaterals; Remacle et al., "Blossom-Quad", IJNME
// 89, 2012). Each ring segment becomes exactly two mesh edges (its midpoint is
// a node), so the caller decides the boundary nodes; inside, the element size
// follows `size`.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

namespace tspline {

struct PlanarQuadMesh {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<int, 4>> quads;  ///< counter-clockwise
  /// Per node: the ring (-1 inside), the ring segment (from ring point k to
  /// k + 1) and the position t in [0, 1] on it (0 and 1: the ring points).
  std::vector<int> ring, segment;
  std::vector<double> t;
};

/// Whether this build can make quad meshes (Gmsh was found at build time).
bool quad_mesher_available();

/// \param rings the outer ring, then the holes; each a closed polygon (no
/// repeated first point) without self-intersections, rings disjoint.
/// \param size the target edge length of the final quadrilaterals at a point.
/// \throw NumericalError if Gmsh fails or leaves a non-quadrilateral element;
/// InputError if this build has no Gmsh.
PlanarQuadMesh quad_mesh(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                         const std::function<double(const Eigen::Vector2d&)>& size);

}  // namespace tspline

#pragma once
// Helpers shared by the topological moves of a quad layout (edge rotations in
// layout_topology.cpp, openings in layout_opening.cpp): private to libtspline.
#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "tspline/layout/layout_mesh.h"
#include "tspline/layout/layout_quality.h"

namespace tspline::layout_local {

/// Whether nodes a and b are joined by a quad edge.
bool has_edge(const LayoutMesh& m, const LayoutTopology& t, int a, int b);

/// The nodes of the quads around `nodes` (their one-ring), each once.
std::vector<int> one_ring(const LayoutMesh& m, const LayoutTopology& t, const std::vector<int>& nodes);

/// The worst figure (layout_quad_figure) of the quads around `nodes`.
double region_figure(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, const std::vector<int>& nodes);

/// The patch corners of the quads at the given nodes that the layout's final
/// check rejects (patch_corner_in_range, at the node itself).
int rejected_corners(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, const std::vector<int>& nodes);

/// sin of the corner at p between the directions to next and to prev (-1 if degenerate).
double corner_sj(const Eigen::Vector2d& p, const Eigen::Vector2d& next, const Eigen::Vector2d& prev);

// The quads at the nodes a local move reads (`reach`) as a layout of their
// own, nodes and quads in the order of the whole layout: every quad at a node
// the move may change is there with all its neighbours, so the move's
// topology, figures and node moves are exactly those on the whole layout, for
// a cost that does not grow with the layout (a copy of the whole layout and of
// its topology per try made rotations quadratic in the number of quads).
struct LocalLayout {
  LayoutMesh mesh;
  std::vector<int> node;  ///< local -> global, increasing
  std::vector<int> quad;  ///< local -> global, increasing
  static int local(const std::vector<int>& ids, int global) {
    return static_cast<int>(std::lower_bound(ids.begin(), ids.end(), global) - ids.begin());
  }
};

LocalLayout local_layout(const LayoutMesh& m, const LayoutTopology& t, const std::vector<int>& reach);

}  // namespace tspline::layout_local

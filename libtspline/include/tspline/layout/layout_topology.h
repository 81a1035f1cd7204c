#pragma once
// Topological improvement of a quad layout: edge rotations where node moves
// alone cannot raise the worst corners.
//
// Two quads sharing an inner edge form a hexagon h0..h5 (the edge is h0-h3);
// it can be split into two quads by either of the other two diagonals, h1-h4
// or h2-h5 (Kinney, "CleanUp: improving quadrilateral finite element meshes",
// 1997; the same move walks a flat single-quad corner along a ring or gives a
// reflex coastal tip the cut it needs: a ring node whose domain angle phi is
// split into k corners gets phi / k each, SJ <= sin(phi / k)). A rotation is
// kept where, after the nodes around it are optimized again
// (layout_optimizer.h), the worst quad around it is better than before and
// no more of its patch corners lie outside 1-170 degrees at the node itself
// (the layout's final check; in a tangled neighbourhood the worst quad can
// rise while a ring node is left the corner of one quad on a straight coast,
// which no node move mends); inner nodes keep valence >= 3, and no edge is
// doubled.
#include <atomic>
#include <cstddef>
#include <functional>
#include <vector>

#include "tspline/layout/layout_mesh.h"
#include "tspline/layout/layout_quality.h"

namespace tspline {

struct LayoutRotationOptions {
  /// Quads whose figure (min of J_r and the side shape, layout_quality.h) is
  /// below this are where rotations are tried.
  double target = 0.45;
  int rounds = 3;
  /// Per round, rotations are tried around this many of the worst quads at most.
  std::size_t max_quads = 300;
  int local_sweeps = 6;  ///< optimizer sweeps over the nodes of a tried rotation and their neighbours
  /// Rotations around quads whose tries read disjoint nodes are tried together
  /// on the pool's threads, at most this many at once (1: one by one). The
  /// result does not depend on it: a quad joins a batch only if its try reads
  /// no node that the try of an earlier quad, in the batch or still waiting,
  /// may read.
  std::size_t max_batch = 64;
  /// A quad whose try found no better rotation is not tried again while no
  /// node its try reads has moved or changed quads (the try would find the
  /// same); false tries it again in every round (same result, more time).
  bool skip_known_failures = true;
  const std::atomic<bool>* cancel = nullptr;  ///< as LayoutOptimizationOptions::cancel, checked per batch
};

struct LayoutRotationReport {
  std::size_t tried = 0, kept = 0;
  std::vector<int> moved;  ///< the nodes re-optimized around kept rotations
};

/// The rings with a ring node that is the corner of one quad only where the
/// ring is nearly straight (inner angle above 150 degrees at any of the
/// corner's scales, layout_quality.h) or reflex: a patch corner of about 180
/// degrees or more, where no map is valid (det J at a corner of the square is
/// the cross product of the two boundary tangents).
std::vector<char> rings_with_flat_corners(const LayoutMesh& m, const LayoutQuality& quality);
/// Those ring nodes (the flat single-quad corners), in node order.
std::vector<int> flat_ring_corners(const LayoutMesh& m, const LayoutQuality& quality);

/// Gives each of the flat single-quad ring corners `corners` a second quad by
/// a sheet of quads (a chord of the dual mesh inserted; the local alternative
/// to pillowing its whole ring): the corner's quad is cut into three around
/// it, and from there the sheet runs through the quads on both sides, each cut
/// in two, until it meets a ring, where a new ring node halves the ring piece,
/// or until it comes back into the corner's quad from the other side (a closed
/// sheet). A quad the sheet crosses in both directions is cut in four. New
/// nodes start at midpoints (the layout optimizer moves them). All or nothing:
/// returns the quads added, or 0 with `m` unchanged where a sheet would run
/// through a quad twice in one direction or back into its corner's quad other
/// than as a closed sheet, or where the sheets would add more than max_quads
/// quads. A corner that an earlier sheet has already given a second quad
/// needs no sheet of its own and is skipped.
std::size_t insert_corner_sheets(LayoutMesh& m, const LayoutRings& rings, const std::vector<int>& corners,
                                 std::size_t max_quads);

/// Pillows the rings marked: every node of such a ring moves a third of the
/// way inside, a copy takes its place on the ring, and each quad edge along
/// the ring gets a new quad between the two (a conforming layer; every ring
/// node then has two quads). A ring node that was the corner of one quad with
/// a convex corner below 150 degrees (a tip of the coast, not a flat corner)
/// keeps one quad: its two layer quads and its old quad become two quads (the
/// moved node goes, left with no quad), so that a sharp tip is not split in
/// two halves. Returns the rings pillowed.
std::size_t pillow_rings(LayoutMesh& m, const std::vector<char>& rings);

/// The figure of quad q used to rank layouts: min(J_r, side shape) over its corners and sides.
double layout_quad_figure(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int q);

struct LayoutOpeningOptions {
  /// Ring nodes with a patch corner wider than this (degrees, at the node
  /// itself) are where openings are tried.
  double wide_corner_degrees = 150.0;
  int local_sweeps = 12;  ///< optimizer sweeps over the nodes around a tried opening
  /// The corners are tried in batches on the pool's threads, each batch the
  /// longest run of corners in order whose tries read disjoint local layouts,
  /// at most this many (1: one by one, the same result).
  std::size_t max_batch = 64;
  const std::atomic<bool>* cancel =
      nullptr;  ///< as LayoutOptimizationOptions::cancel, checked per batch of corners
};

struct LayoutOpeningReport {
  std::size_t tried = 0, kept = 0;
  std::vector<int> moved;  ///< the nodes re-optimized around kept openings (new nodes included)
};

/// Gives a ring node one quad more where one of its patch corners is wide: a
/// reflex tip of the coast with interior angle phi split into k corners gets
/// phi / k each (SJ <= sin(phi / k): 328 degrees in two quads is 164 each, SJ
/// 0.28; in three, 109). An edge rotation cannot do it where the inner nodes
/// next to the tip have valence 3. The opening ("quad open", Kinney 1997):
/// an inner neighbour c of the ring node n, of valence >= 4, is split in two
/// along a path n - c - y through the fan of quads around c; the quads on
/// one side keep c, the others take a copy c', and the new quad (n, c, y, c')
/// fills the gap (n and y gain one quad each, c and c' have valence >= 3).
/// The best opening by the figure of the quads around it after their nodes
/// are optimized again is kept if it raises that figure and adds no corner
/// outside 1-170 degrees (as the rotations).
LayoutOpeningReport open_wide_ring_corners(LayoutMesh& m, const LayoutQuality& Q,
                                           const std::function<bool(const LayoutMesh&, const LayoutTopology&, int)>& admissible,
                                           const LayoutOpeningOptions& options = {});

/// \param admissible as for optimize_layout_nodes.
LayoutRotationReport rotate_layout_edges(LayoutMesh& m, const LayoutQuality& Q,
                                         const std::function<bool(const LayoutMesh&, const LayoutTopology&, int)>& admissible,
                                         const LayoutRotationOptions& options = {});

}  // namespace tspline

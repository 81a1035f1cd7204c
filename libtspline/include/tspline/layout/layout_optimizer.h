#pragma once
// Node positions of a quad layout that its patch maps can live with: every
// node moved (inner nodes in the plane, ring nodes along their ring between
// their ring neighbours) to raise the worst corners of the layout as the
// patch maps see them (layout_quality.h), the topology kept.
//
// Per corner with side vectors e1 = t1 L1, e2 = t2 L2 the energy is
//     E = 1 / J_r + 1 / SJ = (|e1| + |e2|)^2 / (2 chi(det, eps)),
// chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2 the regularization of Garanzha et
// al. (2021) (so that a folded start can be unfolded; eps = 1e-4 |e|^2), and
// a ring vertex inside a side with figure k = sin(phi / 2) adds 2 / k. Nodes
// move one at a time (nonlinear Gauss-Seidel; nodes that share no quad in
// batches on the pool's threads, with the same result) to lower the sum of
// E^p over the corners they touch (p = 4: close to the worst corner, yet
// smooth): inner nodes by a pattern search in eight directions with a step
// kept per node, ring nodes by sampling their arc (every ring vertex in
// reach, where the corner angles jump, and a uniform grid, then a local
// refinement). A move is kept only if `admissible` accepts it (the caller's
// check of the true geometry: inner nodes inside the domain, no cut crossing
// a ring), unless the node was not admissible where it stood (then any move
// that lowers the energy).
#include <atomic>
#include <exception>
#include <functional>
#include <vector>

#include "tspline/layout/layout_mesh.h"
#include "tspline/layout/layout_quality.h"
#include "tspline/layout/ring_geometry.h"

namespace tspline {

struct LayoutOptimizationOptions {
  int max_sweeps = 60;
  double power = 4.0;
  /// Stop when a sweep lowers no node's local energy by more than this, relatively.
  double tolerance = 1e-4;
  /// ... or when the worst corner's J_r has not risen by 0.1 % for this many sweeps.
  int stall_sweeps = 8;
  int ring_samples = 24;  ///< uniform samples of a ring node's reach (plus its vertices, at most max_ring_vertices)
  int max_ring_vertices = 160;
  /// A move may not put more patch corners of the node's quads out of range
  /// at the nodes themselves (patch_corner_in_range, the final layout's check)
  /// than were before it: the energy sees the corners at larger scales, where
  /// a cut leaving a ring node nearly along the ring's first edge looks fine.
  bool keep_patch_corners_in_range = false;
  /// While the layout is tangled, ring nodes stay where they are (sliding one
  /// across a fold only drags the fold along the coast), except those with an
  /// inverted corner of their own (a corner of theirs with scaled Jacobian <= 0
  /// at one of LayoutQuality::corner_scales): where the coast turns at the
  /// node, only the node's slide can unfold that corner. false: every ring
  /// node stays.
  bool untangle_ring_corners = true;
  /// Checked before every sweep: once set (by another thread), LayoutCancelled is thrown.
  const std::atomic<bool>* cancel = nullptr;
  /// A sweep's moves in batches on the pool's threads (nodes that share no
  /// quad, taken in sweep order): the same result as moving the nodes one by
  /// one (false), in less time.
  bool in_batches = true;
};

/// Thrown where a layout's cancel flag was set (QuadLayoutOptions::cancel).
struct LayoutCancelled : std::exception {
  const char* what() const noexcept override { return "the quad layout was cancelled"; }
};

/// Throws LayoutCancelled if `cancel` is given and set.
inline void throw_if_cancelled(const std::atomic<bool>* cancel) {
  if (cancel && cancel->load(std::memory_order_relaxed)) throw LayoutCancelled();
}

struct LayoutOptimizationReport {
  LayoutCornerQuality before, after;  ///< worst over the quads (layout_quality.h)
  int sweeps = 0;
  std::size_t moves = 0;
};

/// The worst corner and kink over all quads.
LayoutCornerQuality worst_layout_quality(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& q);

using LayoutAdmissible = std::function<bool(const LayoutMesh&, const LayoutTopology&, int)>;

/// The check of the true geometry: an inner node inside the domain the rings
/// of `geometry` bound, and no cut from node n (a quad edge not on a ring)
/// crossing a ring (ends within tol of a ring count as on it). `geometry` must
/// outlive the returned function.
LayoutAdmissible admissible_in(const RingGeometry& geometry, double tol);

/// \param admissible whether node n may stay where it now is (called after a
/// tentative move that lowers the energy; from the pool's threads at once,
/// for nodes that share no quad: it must be safe to call so, as a function
/// of the mesh that reads only node n's quads is).
/// \param active the nodes that may move (empty: all); the report's figures
/// are then over the quads around them.
LayoutOptimizationReport optimize_layout_nodes(LayoutMesh& m, const LayoutQuality& quality,
                                               const LayoutAdmissible& admissible, const std::vector<int>& active = {},
                                               const LayoutOptimizationOptions& options = {});

}  // namespace tspline

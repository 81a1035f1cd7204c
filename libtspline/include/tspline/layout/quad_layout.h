#pragma once
// Automatic quad layouts: a coarse partition of the domain, holes included,
// into four-sided patches that meet full side to full side, with patch sizes
// following the local width of the domain (size_field.h).
//
//  1. nodes on every ring (ring_nodes.h): where the coast turns or wanders far
//     from the chord, and at most one local patch size apart;
//  2. the straight polygon through those nodes is meshed into quadrilaterals
//     (quad_mesher.h; each ring piece becomes two quad edges);
//  3. the boundary nodes go back onto the true rings (a quad edge along the
//     boundary becomes the ring's own polyline between its two nodes, at the
//     same fraction of arc length as of the chord);
//  4. the layout optimized for its patch maps: K* untangling of the inner
//     nodes (layout_kstar.h), then every node moved to raise the worst patch
//     corners as the maps see them (layout_optimizer.h, layout_quality.h), and
//     openings of wide ring corners and edge rotations where quads stay poor
//     (layout_topology.h);
//  5. checks on the true geometry: every inner node inside the domain, no inner
//     quad edge crossing a ring, the straight rings simple; where one fails,
//     the ring pieces involved get a node more and the mesh is made again;
//  6. the quads are the patches (patch_layout.h): the inner edges are the cuts,
//     the quad corners the patch corners.
#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/layout/layout_optimizer.h"
#include "tspline/layout/ring_nodes.h"
#include "tspline/layout/size_field.h"
#include "tspline/multipatch/patch_layout.h"

namespace tspline {

class QuadLayoutMemo;  // quad_layout_memo.h (internal)

/// A memo for the layouts of one domain (QuadLayoutOptions::memo).
std::shared_ptr<QuadLayoutMemo> make_quad_layout_memo();

struct QuadLayoutOptions {
  RingNodeOptions nodes;
  SizeFieldOptions size;
  /// Features narrower than this times the bounding-box diagonal are not
  /// resolved by patches (unless size.min_size is set).
  double min_size_fraction = 2e-3;
  /// A flat single-quad ring corner (a patch corner of about 180 degrees)
  /// gets a sheet of quads through it (insert_corner_sheets, layout_topology.h)
  /// where the sheets add fewer quads than pillowing its ring; false: the ring
  /// is pillowed (a layer of quads along all of it).
  bool corner_sheets = true;
  /// Per ring, the arc lengths of the ring nodes to start from instead of
  /// computing them (QuadLayout::ring_nodes of an earlier layout of the same
  /// domain: its repairs done already); empty: computed (ring_nodes.h).
  std::vector<std::vector<double>> start_ring_nodes;
  /// The widest patch corner a layout may have (patch_corner_in_range; the
  /// least is 1 degree): a map's scaled Jacobian at a patch corner is the
  /// sine of its angle, so 170 degrees caps it at 0.17 there, 150 at 0.5.
  double max_patch_corner_degrees = 170.0;
  /// No node move may put a patch corner out of range, from the first mesh
  /// on (LayoutOptimizationOptions::keep_patch_corners_in_range). Off: the
  /// guard is turned on where a mesh optimized in full is rejected for such a
  /// corner, and that mesh is optimized again (the guard costs quality where
  /// nothing needs it: fjords' certified scaled Jacobian 0.267 against 0.503).
  bool guard_patch_corners = false;
  /// Rounds of "add nodes where the true geometry breaks the layout, mesh again".
  int max_repair_rounds = 40;
  /// Set by another thread when the layout is no longer wanted (parameterize_domain
  /// builds it while a single patch is tried): build_quad_layout then throws
  /// LayoutCancelled (layout_optimizer.h) at its next check (every optimization
  /// sweep, rotation batch and repair round).
  const std::atomic<bool>* cancel = nullptr;
  /// Told what each mesh round does (a large coast takes several rounds of
  /// tens of seconds each); never called from two threads at once.
  std::function<void(const std::string&)> progress;
  /// Shared by the layouts of one domain (make_quad_layout_memo): a layout
  /// takes from an earlier one the quad mesher's quads for the same ring nodes
  /// and the first pass of their optimization (K* untangling, a short node
  /// optimization, edge rotations), which are what the work itself would give
  /// (the pillowed second layout of parameterize_domain starts from the first
  /// layout's ring nodes, and so from its first mesh). A memo serves only the
  /// domain and size options it was first used with. Null: nothing shared.
  std::shared_ptr<QuadLayoutMemo> memo;
};


struct QuadLayoutStats {
  std::size_t patches = 0;
  std::size_t ring_nodes = 0;                ///< layout nodes on the rings
  std::size_t inner_nodes = 0;               ///< layout nodes inside the domain
  std::array<std::size_t, 8> inner_valence{};  ///< inner nodes by valence (7: 7 or more)
  /// Scaled Jacobian of the quads with straight sides (chords on the rings).
  double straight_min_scaled_jacobian = 1.0;
  double straight_mean_scaled_jacobian = 1.0;
  int repair_rounds = 0;
  std::size_t pillowed_rings = 0;            ///< rings given a layer of quads (a flat single-quad corner)
  std::size_t corner_sheets = 0;             ///< flat single-quad ring corners given a sheet of quads instead
  /// How far the layout was optimized: 2 all (node optimization and edge
  /// rotations, layout_optimizer.h and layout_topology.h), 1 nodes only, 0 the
  /// mesher's own nodes. Where level 2 leaves a patch corner outside 1-170
  /// degrees or cuts crossing, the same mesh is tried at level 1; where that
  /// fails too, the ring gets nodes near the place and a new mesh is optimized
  /// at level 2 again; level 0 is the last try once the repair rounds are used up.
  int optimization_level = 2;
  std::size_t rotations = 0;       ///< edge rotations kept
  std::size_t openings = 0;        ///< wide ring corners given a quad more (open_wide_ring_corners)
  int optimization_sweeps = 0;     ///< node optimization sweeps, all passes
  /// The worst patch corner as the patch maps see it (layout_quality.h): J_r
  /// and the scaled Jacobian there. A prediction, not a bound: the certified
  /// whole-map figures of the report are the ones to trust (measured within a
  /// few percent of these at the worst patch when the patch's sides are smooth).
  double corner_mean_ratio = 1.0, corner_scaled_jacobian = 1.0;
  double min_size = 0.0, max_size = 0.0;     ///< of the size field, absolute
  double seconds = 0.0;
};

struct QuadLayout {
  PatchLayout layout;
  /// Patch corners on rings that no cut ends at (a quad corner at a sharp tip).
  std::vector<Eigen::Vector2d> ring_corners;
  /// Per ring, the arc lengths of the nodes the layout was meshed with (the
  /// repair rounds' included), ascending.
  std::vector<std::vector<double>> ring_nodes;
  QuadLayoutStats stats;
  std::string explanation() const;
};

/// \pre `domain` is validated (validate_domain).
/// \throw InputError if this build has no quad mesher (quad_mesher.h);
/// NumericalError if no valid layout was found within the repair rounds.
QuadLayout build_quad_layout(const Domain& domain, const QuadLayoutOptions& options = {});

/// Scaled Jacobian of a straight quadrilateral: min over its corners of
/// cross(e1, e2) / (|e1| |e2|), negative at a reflex or inverted corner.
double quad_corner_scaled_jacobian(const std::array<Eigen::Vector2d, 4>& q);

}  // namespace tspline

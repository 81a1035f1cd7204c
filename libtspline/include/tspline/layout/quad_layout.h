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
//  4. checks on the true geometry: every inner node inside the domain, no inner
//     quad edge crossing a ring, the straight rings simple; where one fails,
//     the ring pieces involved get a node more and the mesh is made again;
//  5. the quads are the patches (patch_layout.h): the inner edges are the cuts,
//     the quad corners the patch corners.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/layout/ring_nodes.h"
#include "tspline/layout/size_field.h"
#include "tspline/multipatch/patch_layout.h"

namespace tspline {

struct QuadLayoutOptions {
  RingNodeOptions nodes;
  SizeFieldOptions size;
  /// Features narrower than this times the bounding-box diagonal are not
  /// resolved by patches (unless size.min_size is set).
  double min_size_fraction = 2e-3;
  /// Rounds of "add nodes where the true geometry breaks the layout, mesh again".
  int max_repair_rounds = 40;
};

struct QuadLayoutStats {
  std::size_t patches = 0;
  std::size_t ring_nodes = 0;                ///< layout nodes on the rings
  std::size_t inner_nodes = 0;               ///< layout nodes inside the domain
  std::array<std::size_t, 8> valence{};      ///< inner nodes by valence (7: 7 or more)
  double min_corner_scaled_jacobian = 1.0;   ///< of the quads with straight sides (chords on the rings)
  double mean_corner_scaled_jacobian = 1.0;
  int repair_rounds = 0;
  std::size_t pillowed_rings = 0;            ///< rings given a layer of quads (a flat single-quad corner)
  /// How far the layout was optimized: 3 all (edge rotations of flat corners
  /// and sharp tips, smoothing, sliding, worst corners), 2 without the
  /// rotations, 1 smoothing and sliding,
  /// 0 the mesher's own nodes (a level is dropped where it tangles the layout
  /// or turns a patch corner reflex).
  int optimization_level = 3;
  double min_size = 0.0, max_size = 0.0;     ///< of the size field, absolute
  double seconds = 0.0;
};

struct QuadLayout {
  PatchLayout layout;
  /// Patch corners on rings that no cut ends at (a quad corner at a sharp tip).
  std::vector<Eigen::Vector2d> ring_corners;
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

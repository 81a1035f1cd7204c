#pragma once
// What a quad layout promises its patch maps, read off the layout alone.
//
// Each patch is mapped from the unit square with its four sides parameterized
// by chord length (arc length along a ring), so at a patch corner the map's
// Jacobian is J = [t1 L1, t2 L2]: t1, t2 the unit tangents of the two sides
// leaving the corner (along the ring where a side runs along it, at the node
// itself) and L1, L2 the sides' lengths. There the map's scaled Jacobian is
// sin(theta) and its mean ratio J_r = 2 det J / |J|_F^2 = 2 sin(theta) L1 L2 /
// (L1^2 + L2^2), whatever the patch map does inside: the whole-map figures can
// never exceed the worst corner of the layout (measured: on the seas and
// coastlines the worst patch's certified J_r is its worst corner's to three
// digits). A ring vertex inside a side with inner angle phi (the domain's)
// splits into cells of about phi / 2 each, SJ <= sin(phi / 2); measured, two
// such kinks close together (a step in the coast) do worse, so its figure is
// taken as sin^2(phi / 2).
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "tspline/layout/layout_mesh.h"

namespace tspline {

struct LayoutCornerQuality {
  double mean_ratio = 1.0;       ///< J_r at the corner, <= scaled_jacobian
  double scaled_jacobian = 1.0;  ///< sin of the corner angle (negative: reflex or inverted)
};

/// Whether a patch corner with sides leaving along a and b (counter-clockwise
/// from a to b) is one a patch map can take: between 1 and max_degrees (sin 1
/// deg = 0.0175; above 90 degrees the sine must exceed obtuse_corner_sine
/// (max_degrees), 0.174 for 170); near 180 degrees det J ~ 0 there, since det
/// J at a corner of the square is the cross product of the two side tangents.
/// The layout's final check (quad_layout.cpp) and the edge rotations
/// (layout_topology.cpp) hold the layout to it.
bool patch_corner_in_range(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double max_degrees = 170.0);

/// The least sine of a patch corner of more than 90 degrees that is in range:
/// sin(max_degrees) rounded up to three decimals (0.174 for 170 degrees).
/// \throw InputError unless max_degrees is in (90, 180).
double obtuse_corner_sine(double max_degrees);

class LayoutQuality {
 public:
  /// max_corner_degrees: the widest patch corner in range (patch_corner_in_range).
  explicit LayoutQuality(const LayoutRings& rings, double max_corner_degrees = 170.0);
  const LayoutRings& rings() const { return rings_; }
  double max_corner_degrees() const { return max_corner_degrees_; }
  /// patch_corner_in_range with this quality's widest corner.
  bool corner_in_range(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const;

  /// Length of side j of quad q (from quads[q][j] to the next corner): the ring's
  /// arc length where it lies on a ring, the chord otherwise.
  double side_length(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const;
  /// The corner's two side vectors t1 L1 (to the next corner) and t2 L2 (to the
  /// previous). Along a ring, t is the ring's own direction at the node (scale
  /// 0) or the direction to the ring's point at arc length scale x L from it: a
  /// coast that turns right after the corner (a spike, a tiny edge at the node)
  /// gives the map that corner too, on the scale of its first cells.
  std::pair<Eigen::Vector2d, Eigen::Vector2d> corner_vectors(const LayoutMesh& m, const LayoutTopology& t, int q,
                                                             int j, double scale = 0.0) const;
  /// The scales at which corners are measured (corner, and the optimizer's energy).
  static constexpr std::array<double, 3> corner_scales{0.0, 0.05, 0.2};
  /// corner_vectors at each of `scales` (ring sides measured once), into out;
  /// returns how many were written: 1 at an inner node (a cut corner is the
  /// same at every scale), scales.size() at a ring node.
  int corner_vectors_at(const LayoutMesh& m, const LayoutTopology& t, int q, int j, std::span<const double> scales,
                        std::pair<Eigen::Vector2d, Eigen::Vector2d>* out) const;
  /// The worst over corner_scales.
  LayoutCornerQuality corner(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const;
  /// sin^2(phi / 2), phi the domain's inner angle, worst over the ring vertices
  /// strictly inside side j of quad q; 1 where the side is a cut or has none.
  double side_kinks(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const;
  /// How far ring side j of quad q strays from its chord. A vertex p inside the
  /// patch (left of the chord) leaves the patch the width w(p) to the line of
  /// the opposite side where the straight patch had w(f), f the foot of p on
  /// the chord: the figure is w(p) / w(f) (a coast bulging into a thin patch
  /// pinches it; for a rectangle 1 - d_in / width), and the sine of the angle
  /// at either end's corner between the adjacent side and the direction to p
  /// (a coast reaching towards a cut pinches the patch there). Vertices outside give
  /// 1 - d_out / (2 c), c the chord. The smallest, 1 for a cut. Not a bound of
  /// the map's figures but what the corners cannot see.
  double side_shape(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const;
  /// The worst of the quad's corners and side kinks.
  LayoutCornerQuality quad(const LayoutMesh& m, const LayoutTopology& t, int q) const;

  /// The ring vertices strictly inside ring side j of quad q: ring r, indices
  /// i0 .. i1 - 1 (wrapping past size()); r = -1 for a cut. They depend only
  /// on the side's two end nodes.
  struct SideVertices {
    int ring = -1;
    std::size_t i0 = 0, i1 = 0;
  };
  SideVertices side_vertices(const LayoutMesh& m, const LayoutTopology& t, int q, int j) const;
  /// side_shape with the side's vertices given (side_vertices of the same
  /// side, its end nodes where they were then): the same value.
  double side_shape(const LayoutMesh& m, int q, int j, const SideVertices& v) const;
  /// side_kinks with the side's vertices given: the same value.
  double side_kinks(const SideVertices& v) const { return v.ring < 0 ? 1.0 : kink_min(v.ring, v.i0, v.i1); }

 private:
  // Minimum of the kink figures of ring r's vertices i0 .. i1 - 1 (i1 may pass
  // size(): the range wraps), by a sparse table over the doubled vertex list.
  double kink_min(int r, std::size_t i0, std::size_t i1) const;
  const LayoutRings& rings_;
  double max_corner_degrees_, obtuse_sine_;
  std::vector<std::vector<std::vector<double>>> table_;  // per ring, per level
};

}  // namespace tspline

#pragma once
// The energy the layout's node optimizer minimizes (layout_optimizer.h), per
// quad and per node.
//
// A quad's energy is the sum over its corners of (|e1| + |e2|)^2 / (2 chi(det))
// (the corner's inverse mean ratio, regularized by chi(d, eps) =
// (d + sqrt(eps^2 + d^2)) / 2 as in Garanzha et al. 2021, eps = eps_rel |e1| |e2|),
// the worst over LayoutQuality::corner_scales at ring nodes, plus 2 / k for
// each ring side with kinks k < 1 and 2 / g for each side with shape g < 1
// (layout_quality.h), every term to the power p. With `barrier` an inverted
// corner makes it infinite.
#include <array>
#include <limits>
#include <vector>

#include "tspline/layout/layout_quality.h"
#include "tspline/layout/layout_topology.h"

namespace tspline {

/// The energy of quad q.
double layout_quad_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int q, double p,
                          double eps_rel, bool barrier);

/// The energy of the quads around node n.
double layout_node_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n, double p,
                          double eps_rel, bool barrier);

/// The part of layout_node_energy that moves with node n (the rest is the
/// same wherever n goes on its ring, or inside): in each quad, with n its
/// corner j, the corners j and j +- 1 (their sides end at n; along a ring,
/// their lengths and directions too), the shapes of the sides j + 1 and j + 2
/// (n is a corner of the side opposite them), and for a ring node the kinks
/// and shapes of the sides j - 1 and j (their arcs end at n). The opposite
/// corner's sides do not end at n, and an inner node's sides are cuts.
/// Where it is finite but the node's energy is not, no move of n makes that
/// finite (an inverted or degenerate opposite corner).
/// With stop_at: the sum stops once it reaches stop_at (a search that only
/// asks whether a place beats its best so far), and that partial sum is
/// returned (>= stop_at; every term is positive).
double layout_moving_energy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n, double p,
                            double eps_rel, bool barrier,
                            double stop_at = std::numeric_limits<double>::infinity());

/// layout_moving_energy of one node, prepared for a search that moves only
/// that node (the mesh is read where the node stands at each call): at its
/// neighbouring corners joined to it by a cut, the side away from it is
/// measured once, and so are the ring vertices of the sides that do not end
/// at it.
class LayoutMovingEnergy {
 public:
  LayoutMovingEnergy(const LayoutMesh& m, const LayoutTopology& t, const LayoutQuality& Q, int n, double p,
                     double eps_rel, bool barrier);
  /// layout_moving_energy(m, t, Q, n, p, eps_rel, barrier, stop_at), bit for bit.
  double operator()(double stop_at = std::numeric_limits<double>::infinity()) const;

 private:
  struct Neighbour {
    int node = -1;           ///< the corner's node (corner j + 1 or j - 1 of a quad at n's corner j)
    int scales = 1;          ///< as corner_vectors_at
    bool n_is_next = false;  ///< n is the corner's next corner (its first side), else its previous
    bool fresh = false;      ///< the side to n runs along a ring: the corner is computed afresh
    int edge = -1;           ///< at an inner n: the node's index in edge_nodes_
    std::array<Eigen::Vector2d, LayoutQuality::corner_scales.size()> fixed;  ///< the other side, per scale
    std::array<double, LayoutQuality::corner_scales.size()> fixed_norm;      ///< its length, per scale
  };
  const LayoutMesh& m_;
  const LayoutTopology& t_;
  const LayoutQuality& Q_;
  int n_;
  double p_, eps_rel_;
  bool barrier_;
  std::vector<Neighbour> neighbours_;  ///< per quad at n, corners j + 1 and j - 1
  /// At an inner n, the nodes joined to it by a cut, each once: every cut
  /// from n is a side of two quads and of corners at both its ends, so its
  /// vector and length are taken once per call instead of four times.
  std::vector<int> edge_nodes_;
  /// per quad at n, the ring vertices of sides j + 1 and j + 2 (which do not
  /// end at n: they stay where n goes)
  std::vector<LayoutQuality::SideVertices> far_sides_;
};

}  // namespace tspline

#pragma once
// Cubic T-spline blending functions on a balanced quadtree T-mesh
// (Brovka, López, Escobar, Cascón, Montenegro, "A new method for T-spline parameterization
// of complex 2D geometries", Engineering with Computers 2014, Sect. 5.2, Eq. 6;
// docs/method.md, "The T-spline, its untangling and its quality"; file format: docs/tspline_format.md).
//
// Every T-mesh vertex is an anchor. Its local knot vectors (5 knots per
// direction, the anchor's coordinate in the middle) come from casting rays from
// the anchor along -xi, +xi (resp. -eta, +eta) and collecting the first two mesh
// lines crossed; a ray that leaves [0,1]^2 repeats the border knot (open knot
// structure). An anchor on the border therefore has 4 repeated knots on that
// side ({0,0,0,0,t1}); each border anchor also carries an extra function with
// exactly three repeated knots on that side ({0,0,0,t1,t2}), and each corner
// anchor three extras (one per side and one with three repeated knots in both
// directions). On a mesh without T-junctions this gives exactly the tensor
// product cubic B-splines with open knot vectors: (n+3)^2 functions.
//
// Mesh lines for ray casting: a ray along eta = e crosses a vertical line at xi
// = x if some cell edge on xi = x contains the point (x, e) (edges ending on the
// ray count, from either side).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// One blending function N_alpha(xi, eta) = N[knots_xi](xi) * N[knots_eta](eta).
struct BlendingFunction {
  enum class Kind : std::uint8_t {
    Anchor,      ///< the function of a T-mesh vertex
    EdgeExtra,   ///< three repeated knots in one direction (border vertex)
    CornerExtra  ///< three repeated knots in both directions (corner vertex)
  };
  std::array<double, 5> knots_xi{};
  std::array<double, 5> knots_eta{};
  int vertex = -1;  ///< the anchor's T-mesh vertex
  Kind kind = Kind::Anchor;
  /// Parametric interpolation point (Sect. 5.3, Fig. 8): the anchor for Anchor;
  /// for EdgeExtra the midpoint of the mesh edge from the border vertex into the
  /// domain (length = the first inner knot span); for CornerExtra the centre of
  /// the corner cell.
  Eigen::Vector2d interpolation_point = Eigen::Vector2d::Zero();
};

/// Value and first/second derivatives of the cubic B-spline with the 5 given
/// knots (non-decreasing; repeated knots allowed) at t. Support [k0, k4];
/// right-continuous except at t == k4 == 1 (the border), where the left limit is
/// used so that the basis is defined on the closed square. d1, d2 may be null.
double cubic_bspline(const std::array<double, 5>& knots, double t, double* d1 = nullptr, double* d2 = nullptr);

/// Whether cubic_bspline(knots, t) is +0 without evaluating it: t outside the
/// support, at its right end below 1 (right-continuous), or at its left end
/// where that knot has multiplicity below 4 (the function is continuous there
/// and starts at 0). Not every zero: a sufficient test, exact where it says yes.
bool cubic_bspline_vanishes(const std::array<double, 5>& knots, double t);

/// True iff blending function f is non-zero somewhere on the border of [0,1]^2
/// (four repeated knots at 0 or 1 in some direction): the functions whose
/// control points define the boundary curve.
bool touches_border(const BlendingFunction& f);

/// Values and derivatives of the normalized functions R_alpha = N_alpha / sum N_beta
/// (Eq. 6) that are non-zero somewhere on a cell.
struct BasisValues {
  std::vector<int> ids;  ///< function indices
  std::vector<double> R, R_xi, R_eta, R_xixi, R_xieta, R_etaeta;
};

class TSplineBasis {
 public:
  /// \pre mesh.has_topology().
  explicit TSplineBasis(const TMesh& mesh);
  /// The basis of `mesh`, a copy of other's mesh: other's functions, copied
  /// instead of made again (what TSplineBasis(mesh) would make).
  TSplineBasis(const TSplineBasis& other, const TMesh& mesh)
      : mesh_(&mesh), functions_(other.functions_), cell_functions_(other.cell_functions_) {}

  std::size_t size() const { return functions_.size(); }
  const BlendingFunction& function(int a) const { return functions_[a]; }
  const std::vector<BlendingFunction>& functions() const { return functions_; }

  /// Functions whose support intersects the interior of cell c (sorted).
  const std::vector<int>& functions_on_cell(int c) const { return cell_functions_[c]; }

  /// Cell containing the parametric point (closed square; points on cell
  /// boundaries go to the cell above/right, except on xi = 1 or eta = 1).
  int locate(const Eigen::Vector2d& uv) const;

  /// R and its derivatives up to order `order` (0, 1 or 2) at uv in cell c.
  void evaluate(int c, const Eigen::Vector2d& uv, BasisValues& out, int order = 2) const;
  /// Same, locating the cell.
  void evaluate(const Eigen::Vector2d& uv, BasisValues& out, int order = 2) const;

  const TMesh& mesh() const { return *mesh_; }

 private:
  const TMesh* mesh_;
  std::vector<BlendingFunction> functions_;
  std::vector<std::vector<int>> cell_functions_;
};

}  // namespace tspline

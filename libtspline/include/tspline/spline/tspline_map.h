#pragma once
// The cubic T-spline map S(xi, eta) = sum_alpha P_alpha R_alpha(xi, eta) from
// [0,1]^2 onto the physical domain (Brovka 2013 Eq. 7).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "tspline/tmesh/tmesh.h"
#include "tspline/spline/tspline_basis.h"

namespace tspline {

/// S and its derivatives at a parametric point.
struct MapDerivatives {
  Eigen::Vector2d x = Eigen::Vector2d::Zero();   ///< S
  Eigen::Matrix2d J = Eigen::Matrix2d::Zero();   ///< columns dS/dxi, dS/deta
  Eigen::Vector2d xixi = Eigen::Vector2d::Zero();   ///< d2S/dxi2
  Eigen::Vector2d xieta = Eigen::Vector2d::Zero();  ///< d2S/dxi deta
  Eigen::Vector2d etaeta = Eigen::Vector2d::Zero(); ///< d2S/deta2
};

class TSplineMap {
 public:
  /// Takes the T-mesh (topology must be built) and one control point per
  /// blending function of TSplineBasis(mesh), in its order.
  /// \throw InputError if the number of control points is wrong.
  TSplineMap(TMesh mesh, std::vector<Eigen::Vector2d> control_points);
  /// All control points at the origin (to be set with set_control_points()).
  explicit TSplineMap(TMesh mesh);
  TSplineMap(const TSplineMap& other);
  TSplineMap& operator=(const TSplineMap& other);
  TSplineMap(TSplineMap&&) noexcept = default;
  TSplineMap& operator=(TSplineMap&&) noexcept = default;

  const TMesh& mesh() const { return *mesh_; }
  const TSplineBasis& basis() const { return *basis_; }
  const std::vector<Eigen::Vector2d>& control_points() const { return control_points_; }
  /// \throw InputError if the count differs from basis().size().
  void set_control_points(std::vector<Eigen::Vector2d> control_points);

  Eigen::Vector2d point(const Eigen::Vector2d& uv) const;
  Eigen::Matrix2d jacobian(const Eigen::Vector2d& uv) const;
  /// Derivatives up to `order` (0, 1, 2) in cell c (or located if c < 0).
  MapDerivatives derivatives(const Eigen::Vector2d& uv, int order = 1, int c = -1) const;

 private:
  std::unique_ptr<TMesh> mesh_;  // heap: the basis keeps a pointer to it
  std::unique_ptr<TSplineBasis> basis_;
  std::vector<Eigen::Vector2d> control_points_;
};

/// The map whose control points are the Greville abscissae of the blending
/// functions (mean of the three middle local knots in each direction). On a
/// T-mesh without T-junctions this is exactly the identity of [0,1]^2 (the
/// reference geometry for analysis tests and benchmarks); with T-junctions it
/// is only close to it (the normalized basis does not reproduce linear functions).
TSplineMap greville_identity_map(TMesh mesh);

}  // namespace tspline

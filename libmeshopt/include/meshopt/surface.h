#pragma once
// A parameterized surface phi: U subset R^2 -> Sigma subset R^3 (Gargallo-Peiro
// Eq. 2) as libmeshopt sees it: the point, its first and second derivatives at
// parametric coordinates u = (u, v), and the parametric domain U.
//
// The smoother moves nodes in U (Sect. 4); the measures are evaluated on the
// physical triangle (phi(u0), phi(u1), phi(u2)) and so do not depend on the
// parameterization (Proposition 1). No CAD kernel here: adapters (e.g. the Gmsh
// one in libmeshopt/gmsh) implement this interface.
#include <Eigen/Core>
#include <limits>

namespace meshopt {

/// phi and its derivatives at one parametric point.
struct SurfacePoint {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 2> d = Eigen::Matrix<double, 3, 2>::Zero();  ///< columns phi_u, phi_v
  Eigen::Vector3d duu = Eigen::Vector3d::Zero();                        ///< order 2 only
  Eigen::Vector3d duv = Eigen::Vector3d::Zero();
  Eigen::Vector3d dvv = Eigen::Vector3d::Zero();
};

class ParametricSurface {
 public:
  virtual ~ParametricSurface() = default;
  /// phi(u).
  virtual Eigen::Vector3d value(const Eigen::Vector2d& u) const = 0;
  /// phi(u) with derivatives up to `order` (1: x and d; 2: also duu, duv, dvv).
  virtual SurfacePoint evaluate(const Eigen::Vector2d& u, int order) const = 0;
  /// True iff u lies in the parametric domain U (nodes must stay inside it).
  /// Called at every line-search point: keep it cheap (e.g. a bounding box).
  virtual bool contains(const Eigen::Vector2d& u) const = 0;
  /// The exact domain test where it is costly (a trimmed CAD face), called once
  /// per accepted move and on input; defaults to contains().
  virtual bool contains_exactly(const Eigen::Vector2d& u) const { return contains(u); }
};

/// Unit normal phi_u x phi_v / |phi_u x phi_v|; zero vector where the surface is
/// degenerate: |phi_u x phi_v| <= 1e-12 max(|phi_u|, |phi_v|)^2 (a pole, where one
/// derivative vanishes, or parallel derivatives), or not finite.
Eigen::Vector3d unit_normal(const SurfacePoint& p);

/// The plane z = 0 with phi(u, v) = (u, v, 0) (the planar case of the same
/// library call), restricted to the box [lo, hi] (unbounded by default).
class PlaneSurface final : public ParametricSurface {
 public:
  PlaneSurface() = default;
  PlaneSurface(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) : lo_(lo), hi_(hi) {}
  Eigen::Vector3d value(const Eigen::Vector2d& u) const override { return {u.x(), u.y(), 0.0}; }
  SurfacePoint evaluate(const Eigen::Vector2d& u, int order) const override;
  bool contains(const Eigen::Vector2d& u) const override {
    return (u.array() >= lo_.array()).all() && (u.array() <= hi_.array()).all();
  }

 private:
  Eigen::Vector2d lo_ = Eigen::Vector2d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi_ = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
};

}  // namespace meshopt

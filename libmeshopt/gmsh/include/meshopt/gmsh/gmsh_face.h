#pragma once
// A CAD face of the current Gmsh model as a meshopt::ParametricSurface: phi and
// its first and second derivatives from gmsh::model::getValue / getDerivative /
// getSecondDerivative, the domain from the parametrization bounds (and, as the
// exact test, gmsh::model::isInside for trimmed faces).
#include <Eigen/Core>

#include "meshopt/surface.h"

namespace meshopt::gmsh_io {

class GmshFace final : public ParametricSurface {
 public:
  /// \pre gmsh is initialized and the model has a surface with this tag.
  explicit GmshFace(int tag);
  int tag() const { return tag_; }
  Eigen::Vector3d value(const Eigen::Vector2d& u) const override;
  SurfacePoint evaluate(const Eigen::Vector2d& u, int order) const override;
  /// The parametrization bounds.
  bool contains(const Eigen::Vector2d& u) const override;
  /// The bounds and gmsh::model::isInside (about 10 us per call for an OCC face).
  bool contains_exactly(const Eigen::Vector2d& u) const override;
  Eigen::Vector2d lower() const { return lo_; }
  Eigen::Vector2d upper() const { return hi_; }

 private:
  int tag_;
  Eigen::Vector2d lo_, hi_;
  bool use_is_inside_ = false;  ///< gmsh::model::isInside answers for this face
};

}  // namespace meshopt::gmsh_io

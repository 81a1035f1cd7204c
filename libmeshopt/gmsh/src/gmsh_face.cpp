// Gmsh faces as parameterized surfaces (Gmsh 4.8 C++ API).
#include "meshopt/gmsh/gmsh_face.h"

#include <gmsh.h>

#include <vector>

namespace meshopt::gmsh_io {

GmshFace::GmshFace(int tag) : tag_(tag) {
  std::vector<double> lo, hi;
  gmsh::model::getParametrizationBounds(2, tag, lo, hi);
  lo_ = Eigen::Vector2d(lo.at(0), lo.at(1));
  hi_ = Eigen::Vector2d(hi.at(0), hi.at(1));
  // isInside is only implemented for some kernels/faces: trust it only if it
  // accepts the centre of the box or rejects a point far outside it.
  const Eigen::Vector2d c = 0.5 * (lo_ + hi_), far = hi_ + 10.0 * (hi_ - lo_) + Eigen::Vector2d::Ones();
  try {
    const int in_far = gmsh::model::isInside(2, tag, {far.x(), far.y()});
    const int in_c = gmsh::model::isInside(2, tag, {c.x(), c.y()});
    use_is_inside_ = in_far == 0 && (in_c == 0 || in_c == 1);
  } catch (...) {
    use_is_inside_ = false;
  }
}

Eigen::Vector3d GmshFace::value(const Eigen::Vector2d& u) const {
  std::vector<double> xyz;
  gmsh::model::getValue(2, tag_, {u.x(), u.y()}, xyz);
  return {xyz.at(0), xyz.at(1), xyz.at(2)};
}

SurfacePoint GmshFace::evaluate(const Eigen::Vector2d& u, int order) const {
  SurfacePoint p;
  const std::vector<double> uv{u.x(), u.y()};
  p.x = value(u);
  std::vector<double> d;
  gmsh::model::getDerivative(2, tag_, uv, d);
  for (int k = 0; k < 3; ++k) {
    p.d(k, 0) = d.at(k);
    p.d(k, 1) = d.at(3 + k);
  }
  if (order >= 2) {
    // Gmsh returns [uu, vv, uv] (see gmsh.h, getSecondDerivative).
    gmsh::model::getSecondDerivative(2, tag_, uv, d);
    for (int k = 0; k < 3; ++k) {
      p.duu[k] = d.at(k);
      p.dvv[k] = d.at(3 + k);
      p.duv[k] = d.at(6 + k);
    }
  }
  return p;
}

bool GmshFace::contains(const Eigen::Vector2d& u) const {
  return (u.array() >= lo_.array()).all() && (u.array() <= hi_.array()).all();
}

bool GmshFace::contains_exactly(const Eigen::Vector2d& u) const {
  return contains(u) && (!use_is_inside_ || gmsh::model::isInside(2, tag_, {u.x(), u.y()}) > 0);
}

}  // namespace meshopt::gmsh_io

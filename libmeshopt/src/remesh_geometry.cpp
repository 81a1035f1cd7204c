// The projection hint of the remesher (see remesh_geometry.h).
#include "meshopt/remesh_geometry.h"

#include <algorithm>

#include "meshopt/parametric_star.h"

namespace meshopt {

bool ProjectionHint::proves_inside(int face, const Eigen::Vector2d& uv, const Eigen::Vector2d& max_span,
                                   bool trimmed_inside) const {
  std::vector<const std::array<GeometryPoint, 3>*> on_face;
  for (const auto& t : triangles) {
    if (t[0].entity != face || t[1].entity != face || t[2].entity != face) continue;
    const Eigen::Vector2d lo = t[0].param.cwiseMin(t[1].param).cwiseMin(t[2].param);
    const Eigen::Vector2d hi = t[0].param.cwiseMax(t[1].param).cwiseMax(t[2].param);
    if (((hi - lo).array() < max_span.array()).all()) on_face.push_back(&t);
  }
  bool inside = false;
  for (const auto* t : on_face) {
    inside = inside || in_triangle(uv, (*t)[0].param, (*t)[1].param, (*t)[2].param);
    if (!trimmed_inside) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d &a = (*t)[k].param, &b = (*t)[(k + 1) % 3].param;
      const bool shared = std::any_of(on_face.begin(), on_face.end(), [&](const auto* o) {
        for (int l = 0; l < 3 && o != t; ++l)
          if ((*o)[l].param == b && (*o)[(l + 1) % 3].param == a) return true;
        return false;
      });
      if (!shared && segment_distance(uv, a, b) < kTrimmingMargin * (b - a).norm()) return false;
    }
  }
  return inside;
}

}  // namespace meshopt

#include "tspline/deform/boundary_deformation.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "tspline/errors.h"
#include "tspline/spline/tspline_fit.h"

namespace tspline {

double BoundaryDeformation::max_residual() const {
  double m = 0.0;
  for (const Eigen::Vector2d& r : residual) m = std::max(m, r.norm());
  return m;
}

BoundaryDeformation fit_boundary_deformation(const std::vector<Eigen::Vector2d>& old,
                                             const std::vector<Eigen::Vector2d>& moved) {
  if (old.size() != moved.size())
    throw InputError("the moved boundary has " + std::to_string(moved.size()) + " vertices, the old one " +
                     std::to_string(old.size()));
  if (old.empty()) throw InputError("the boundary has no vertices");
  for (std::size_t i = 0; i < old.size(); ++i)
    if (!old[i].allFinite() || !moved[i].allFinite())
      throw InputError("vertex " + std::to_string(i) + " of the boundary has a coordinate that is not finite");
  const double n = static_cast<double>(old.size());
  Eigen::Vector2d p0 = Eigen::Vector2d::Zero(), q0 = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < old.size(); ++i) p0 += old[i], q0 += moved[i];
  p0 /= n, q0 /= n;
  // Normal equations about the centroids: A C = Q with C = sum dp dp^T, Q = sum dq dp^T.
  Eigen::Matrix2d C = Eigen::Matrix2d::Zero(), Q = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < old.size(); ++i) {
    const Eigen::Vector2d dp = old[i] - p0, dq = moved[i] - q0;
    C += dp * dp.transpose();
    Q += dq * dp.transpose();
  }
  BoundaryDeformation d;
  // C is singular only for collinear points; relative to its scale (trace^2).
  const double det = C.determinant(), tr = C.trace();
  if (old.size() >= 3 && det > 1e-12 * tr * tr) d.A = Q * C.inverse();
  d.b = q0 - d.A * p0;
  d.residual.resize(old.size());
  for (std::size_t i = 0; i < old.size(); ++i) d.residual[i] = moved[i] - d.affine(old[i]);
  return d;
}

namespace {

// The residual at chord parameter t of `side`: linear between the chain's vertices.
Eigen::Vector2d side_residual(const BoundaryMap& bm, const BoundaryDeformation& d, Side side, double t) {
  const std::vector<double>& params = bm.chain_params(side);
  const std::size_t n = bm.polygon().vertices.size();
  const std::size_t first = bm.corners().index[static_cast<int>(side)];
  auto r = [&](std::size_t j) -> const Eigen::Vector2d& { return d.residual[(first + j) % n]; };
  t = std::clamp(t, 0.0, 1.0);
  const auto it = std::upper_bound(params.begin(), params.end(), t);
  if (it == params.end()) return r(params.size() - 1);
  const std::size_t j = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - params.begin(), 1)) - 1;
  const double w = (t - params[j]) / (params[j + 1] - params[j]);
  return (1.0 - w) * r(j) + w * r(j + 1);
}

}  // namespace

Eigen::Vector2d residual_extension(const BoundaryMap& bm, const BoundaryDeformation& d, const Eigen::Vector2d& uv) {
  if (d.residual.size() != bm.polygon().vertices.size())
    throw InputError("the deformation has " + std::to_string(d.residual.size()) + " vertices, the boundary " +
                     std::to_string(bm.polygon().vertices.size()));
  const double u = uv.x(), v = uv.y();
  // Side parameters (boundary_map.h): Bottom t = u, Right t = v, Top t = 1 - u, Left t = 1 - v.
  const Eigen::Vector2d rb = side_residual(bm, d, Side::Bottom, u), rt = side_residual(bm, d, Side::Top, 1.0 - u);
  const Eigen::Vector2d rl = side_residual(bm, d, Side::Left, 1.0 - v), rr = side_residual(bm, d, Side::Right, v);
  const auto& c = bm.corners().index;
  const Eigen::Vector2d r00 = d.residual[c[0]], r10 = d.residual[c[1]], r11 = d.residual[c[2]], r01 = d.residual[c[3]];
  return (1 - v) * rb + v * rt + (1 - u) * rl + u * rr -
         ((1 - u) * (1 - v) * r00 + u * (1 - v) * r10 + u * v * r11 + (1 - u) * v * r01);
}

TSplineMap warm_start_map(const TSplineMap& old, const BoundaryMap& old_boundary, const BoundaryDeformation& d) {
  // The interpolation is linear in the targets and reproduces the space, and
  // A S_old + b is the map of the control points A P + b (the functions sum to
  // 1): only the residual's extension needs the solve.
  std::vector<Eigen::Vector2d> P = old.control_points();
  for (Eigen::Vector2d& p : P) p = d.affine(p);
  if (d.max_residual() > 0.0) {
    const TSplineMap r = interpolate_map(
        old.mesh(), [&](const Eigen::Vector2d& uv) { return residual_extension(old_boundary, d, uv); });
    for (std::size_t i = 0; i < P.size(); ++i) P[i] += r.control_points()[i];
  }
  TSplineMap out = old;
  out.set_control_points(std::move(P));
  return out;
}

}  // namespace tspline

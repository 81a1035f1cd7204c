#include "tspline/validity/map_quality.h"

#include "tspline/detail/quadrature.h"
#include "tspline/spline/bezier_extraction.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace tspline {

double mean_ratio_jacobian(const Eigen::Matrix2d& J) {
  const double f = J.squaredNorm();
  return f > 0.0 ? 2.0 * J.determinant() / f : 0.0;
}

double scaled_jacobian(const Eigen::Matrix2d& J) {
  const double n = J.col(0).norm() * J.col(1).norm();
  return n > 0.0 ? J.determinant() / n : 0.0;
}

MapQualityStats map_quality(const TSplineMap& map, int gauss, std::vector<CellMapQuality>* per_cell) {
  std::vector<double> gp, gw;
  detail::gauss_points_01(gauss, gp, gw);
  const TMesh& mesh = map.mesh();
  MapQualityStats s;
  s.min_det = std::numeric_limits<double>::infinity();
  s.max_det = -std::numeric_limits<double>::infinity();
  double sum = 0.0;
  if (per_cell) per_cell->assign(mesh.num_cells(), CellMapQuality{});
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
    CellMapQuality q;
    q.min_det = std::numeric_limits<double>::infinity();
    for (double a : gp)
      for (double b : gp) {
        const Eigen::Vector2d uv(lo.x() + a * (hi.x() - lo.x()), lo.y() + b * (hi.y() - lo.y()));
        const Eigen::Matrix2d J = map.derivatives(uv, 1, c).J;
        const double det = J.determinant(), jr = mean_ratio_jacobian(J), js = scaled_jacobian(J);
        q.min_mean_ratio = std::min(q.min_mean_ratio, jr);
        q.min_det = std::min(q.min_det, det);
        q.min_scaled = std::min(q.min_scaled, js);
        ++s.points;
        if (!(det > 0.0)) ++s.nonpositive_det;
        sum += jr;
        s.max_det = std::max(s.max_det, det);
      }
    s.min_mean_ratio = std::min(s.min_mean_ratio, q.min_mean_ratio);
    s.min_det = std::min(s.min_det, q.min_det);
    s.min_scaled = std::min(s.min_scaled, q.min_scaled);
    if (per_cell) (*per_cell)[c] = q;
  }
  s.mean_mean_ratio = s.points ? sum / static_cast<double>(s.points) : 0.0;
  return s;
}

DenseMapQuality dense_map_quality(const TSplineMap& map, int k) {
  if (k < 1) throw std::invalid_argument("dense_map_quality: k must be >= 1");
  DenseMapQuality q;
  q.samples_per_edge = k;
  const BezierExtraction extraction(map.basis());
  for (const BezierElement& e : extraction.elements()) {
    ++q.elements;
    for (int j = 0; j <= k; ++j)
      for (int i = 0; i <= k; ++i) {
        const Eigen::Vector2d uv(e.lo.x() + (e.hi.x() - e.lo.x()) * i / k, e.lo.y() + (e.hi.y() - e.lo.y()) * j / k);
        const Eigen::Matrix2d J = map.derivatives(uv, 1, e.cell).J;
        const double jr = mean_ratio_jacobian(J);
        ++q.points;
        if (!(J.determinant() > 0.0)) ++q.nonpositive_det;
        if (jr < q.min_mean_ratio) q.min_mean_ratio = jr, q.worst_at = uv;
        q.min_scaled = std::min(q.min_scaled, scaled_jacobian(J));
      }
  }
  return q;
}

}  // namespace tspline

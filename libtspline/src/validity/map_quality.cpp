#include "tspline/validity/map_quality.h"

#include "tspline/detail/quadrature.h"
#include "tspline/detail/tensor_grid.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/element_map.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include "toolkit/errors.h"

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
  return map_quality(map, BezierExtraction(map.basis()), gauss, per_cell);
}

MapQualityStats map_quality(const TSplineMap& map, const BezierExtraction& extraction, int gauss,
                            std::vector<CellMapQuality>* per_cell) {
  std::vector<double> gp, gw;
  detail::gauss_points_01(gauss, gp, gw);
  const TMesh& mesh = map.mesh();
  const int nc = static_cast<int>(mesh.num_cells());
  // Each Gauss point of a cell on the Bezier element of the cell that holds it
  // (the elements tile the cell), evaluated from the element's coefficients.
  const std::vector<Eigen::Vector2d>& P = map.control_points();
  std::vector<CellMapQuality> cells(static_cast<std::size_t>(nc));
  std::vector<double> cell_sum(static_cast<std::size_t>(nc), 0.0), cell_max_det(static_cast<std::size_t>(nc));
  std::vector<std::size_t> cell_nonpositive(static_cast<std::size_t>(nc), 0);
  detail::parallel_ranges(static_cast<std::size_t>(nc), detail::pool_threads(), [&](std::size_t b, std::size_t end, int) {
    CellMapEvaluator cell_map(extraction, P);
    for (std::size_t cu = b; cu < end; ++cu) {
      const int c = static_cast<int>(cu);
      const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
      cell_map.set_cell(c);
      CellMapQuality q;
      q.min_det = std::numeric_limits<double>::infinity();
      double sum = 0.0, max_det = -std::numeric_limits<double>::infinity();
      std::size_t nonpositive = 0;
      for (double a : gp)
        for (double bb : gp) {
          const Eigen::Vector2d uv(lo.x() + a * (hi.x() - lo.x()), lo.y() + bb * (hi.y() - lo.y()));
          const Eigen::Matrix2d J = cell_map.at(uv).J;
          const double det = J.determinant(), jr = mean_ratio_jacobian(J), js = scaled_jacobian(J);
          q.min_mean_ratio = std::min(q.min_mean_ratio, jr);
          q.min_det = std::min(q.min_det, det);
          q.min_scaled = std::min(q.min_scaled, js);
          if (!(det > 0.0)) ++nonpositive;
          sum += jr;
          max_det = std::max(max_det, det);
        }
      cells[cu] = q, cell_sum[cu] = sum, cell_max_det[cu] = max_det, cell_nonpositive[cu] = nonpositive;
    }
  }, 64);
  MapQualityStats s;
  s.min_det = std::numeric_limits<double>::infinity();
  s.max_det = -std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (int c = 0; c < nc; ++c) {
    const CellMapQuality& q = cells[c];
    s.points += gp.size() * gp.size();
    s.nonpositive_det += cell_nonpositive[c];
    sum += cell_sum[c];
    s.max_det = std::max(s.max_det, cell_max_det[c]);
    s.min_mean_ratio = std::min(s.min_mean_ratio, q.min_mean_ratio);
    s.min_det = std::min(s.min_det, q.min_det);
    s.min_scaled = std::min(s.min_scaled, q.min_scaled);
  }
  s.mean_mean_ratio = s.points ? sum / static_cast<double>(s.points) : 0.0;
  if (per_cell) *per_cell = std::move(cells);
  return s;
}

DenseMapQuality dense_map_quality(const TSplineMap& map, int k) {
  if (k < 1) throw toolkit::InputError("dense_map_quality: k must be >= 1");
  return dense_map_quality(BezierExtraction(map.basis()), map.control_points(), k);
}

DenseMapQuality dense_map_quality(const BezierExtraction& extraction, const std::vector<Eigen::Vector2d>& P, int k) {
  if (k < 1) throw toolkit::InputError("dense_map_quality: k must be >= 1");
  const std::vector<BezierElement>& es = extraction.elements();
  // The (k + 1) x (k + 1) points of every element as a tensor grid: the map's
  // Bernstein coefficients per element and sum factorization (tensor_grid.h),
  // instead of the basis functions point by point.
  const int m = k + 1;
  std::vector<double> pts(m), wts(m, 1.0);
  for (int i = 0; i <= k; ++i) pts[i] = static_cast<double>(i) / k;
  detail::TensorGrid grid;
  grid.set(pts, wts);
  const std::size_t n = grid.size();
  const int threads = detail::pool_threads();
  std::vector<DenseMapQuality> part(static_cast<std::size_t>(threads));
  detail::parallel_ranges(es.size(), threads, [&](std::size_t begin, std::size_t end, int slot) {
    DenseMapQuality& q = part[slot];
    std::vector<double> buf(9 * n), scratch(8 * static_cast<std::size_t>(m));
    double* x = buf.data();
    double *xs = x + n, *xt = xs + n, *y = xt + n, *ys = y + n, *yt = ys + n, *w = yt + n, *ws = w + n, *wt = ws + n;
    for (std::size_t ke = begin; ke < end; ++ke) {
      const BezierElement& e = es[ke];
      ++q.elements;
      // S - c = (X - c w) / w: coefficients relative to a control point of the
      // element, so that far-from-origin coordinates do not cancel in the derivatives.
      const ElementMap em(e, P);
      detail::tensor_values(grid, em.X, x, xs, xt, scratch.data());
      detail::tensor_values(grid, em.Y, y, ys, yt, scratch.data());
      detail::tensor_values(grid, em.W, w, ws, wt, scratch.data());
      const double hx = e.hi.x() - e.lo.x(), hy = e.hi.y() - e.lo.y();
      for (int j = 0; j <= k; ++j)
        for (int i = 0; i <= k; ++i) {
          const std::size_t p = static_cast<std::size_t>(i + m * j);
          // S_s = (X_s - X w_s / w) / w, S_t alike; J = [S_s / hx, S_t / hy].
          const double iw = 1.0 / w[p];
          Eigen::Matrix2d J;
          J << (xs[p] - x[p] * ws[p] * iw) * iw / hx, (xt[p] - x[p] * wt[p] * iw) * iw / hy,
              (ys[p] - y[p] * ws[p] * iw) * iw / hx, (yt[p] - y[p] * wt[p] * iw) * iw / hy;
          const double jr = mean_ratio_jacobian(J);
          ++q.points;
          if (!(J.determinant() > 0.0)) ++q.nonpositive_det;
          if (jr < q.min_mean_ratio)
            q.min_mean_ratio = jr,
            q.worst_at = {e.lo.x() + hx * i / k, e.lo.y() + hy * j / k};
          q.min_scaled = std::min(q.min_scaled, scaled_jacobian(J));
        }
    }
  }, 16);
  // Merged in element order: the first worst point wins, as element by element.
  DenseMapQuality q;
  q.samples_per_edge = k;
  for (const DenseMapQuality& p : part) {
    q.elements += p.elements;
    q.points += p.points;
    q.nonpositive_det += p.nonpositive_det;
    if (p.min_mean_ratio < q.min_mean_ratio) q.min_mean_ratio = p.min_mean_ratio, q.worst_at = p.worst_at;
    q.min_scaled = std::min(q.min_scaled, p.min_scaled);
  }
  return q;
}

}  // namespace tspline

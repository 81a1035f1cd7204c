#include "tspline/spline/element_map.h"

#include <algorithm>
#include <array>
#include <limits>

namespace tspline {

ElementMap::ElementMap(const BezierElement& e, const std::vector<Eigen::Vector2d>& P)
    : origin(P[e.functions.front()]), lo(e.lo), hi(e.hi) {
  for (Eigen::Index r = 0; r < e.C.rows(); ++r) {
    const Eigen::Vector2d d = P[e.functions[r]] - origin;
    for (int k = 0; k < 16; ++k) X[k] += d.x() * e.C(r, k), Y[k] += d.y() * e.C(r, k), W[k] += e.C(r, k);
  }
}

MapDerivatives ElementMap::at_local(double s, double t) const {
  const std::array<double, 4> bs = bernstein3(s), bt = bernstein3(t);
  const double rs = 1.0 - s, rt = 1.0 - t;
  const double ds[4] = {-3.0 * rs * rs, 3.0 * rs * rs - 6.0 * s * rs, 6.0 * s * rs - 3.0 * s * s, 3.0 * s * s};
  const double dt[4] = {-3.0 * rt * rt, 3.0 * rt * rt - 6.0 * t * rt, 6.0 * t * rt - 3.0 * t * t, 3.0 * t * t};
  double v[3] = {}, vs[3] = {}, vt[3] = {};
  const double* c[3] = {X, Y, W};
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const double b = bs[i] * bt[j], bS = ds[i] * bt[j], bT = bs[i] * dt[j];
      for (int f = 0; f < 3; ++f) {
        const double a = c[f][i + 4 * j];
        v[f] += a * b, vs[f] += a * bS, vt[f] += a * bT;
      }
    }
  const double iw = 1.0 / v[2], hx = hi.x() - lo.x(), hy = hi.y() - lo.y();
  MapDerivatives d;
  d.x = origin + Eigen::Vector2d(v[0] * iw, v[1] * iw);
  d.J << (vs[0] - v[0] * vs[2] * iw) * iw / hx, (vt[0] - v[0] * vt[2] * iw) * iw / hy,
      (vs[1] - v[1] * vs[2] * iw) * iw / hx, (vt[1] - v[1] * vt[2] * iw) * iw / hy;
  return d;
}

MapDerivatives ElementMap::at(const Eigen::Vector2d& uv) const {
  return at_local((uv.x() - lo.x()) / (hi.x() - lo.x()), (uv.y() - lo.y()) / (hi.y() - lo.y()));
}

void CellMapEvaluator::set_cell(int c) {
  if (c == cell_) return;
  cell_ = c;
  elements_.clear();
  const std::vector<BezierElement>& es = extraction_.elements();
  for (std::size_t k = extraction_.cell_begin(c); k < extraction_.cell_begin(c + 1); ++k)
    elements_.emplace_back(es[k], P_);
}

MapDerivatives CellMapEvaluator::at(const Eigen::Vector2d& uv) const {
  // The elements tile the cell row by row: the first whose closed box holds uv.
  // A point off the cell by round-off takes the element nearest to it.
  const ElementMap* best = &elements_.front();
  double best_distance = std::numeric_limits<double>::infinity();
  for (const ElementMap& e : elements_) {
    const double dx = std::max({e.lo.x() - uv.x(), uv.x() - e.hi.x(), 0.0});
    const double dy = std::max({e.lo.y() - uv.y(), uv.y() - e.hi.y(), 0.0});
    if (dx == 0.0 && dy == 0.0) return e.at(uv);
    if (dx + dy < best_distance) best_distance = dx + dy, best = &e;
  }
  return best->at(uv);
}

}  // namespace tspline

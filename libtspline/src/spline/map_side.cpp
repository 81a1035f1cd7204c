#include "tspline/spline/map_side.h"

#include "tspline/errors.h"

namespace tspline {

namespace {

// The point of parameter t on side `side` (as side_point_uv,
// multipatch_parameterization.h).
Eigen::Vector2d side_uv(int side, double t) {
  switch (side) {
    case 0:
      return {t, 0.0};
    case 1:
      return {1.0, t};
    case 2:
      return {1.0 - t, 1.0};
    default:
      return {0.0, 1.0 - t};
  }
}

// Sides 0 and 2 fix eta, sides 1 and 3 fix xi.
bool fixes_eta(int side) { return side % 2 == 0; }

}  // namespace

MapSide::MapSide(const TSplineMap& map, int side) : map_(map), side_(side) {
  if (side < 0 || side > 3) throw InputError("MapSide: side must be 0, 1, 2 or 3");
}

const std::vector<MapSide::Term>& MapSide::terms(int cell) const {
  const auto found = cells_.find(cell);
  if (found != cells_.end()) return found->second;
  std::vector<Term>& out = cells_[cell];
  const TSplineBasis& basis = map_.basis();
  const double fixed = side_ == 0 || side_ == 3 ? 0.0 : 1.0;
  for (const int a : basis.functions_on_cell(cell)) {
    const BlendingFunction& f = basis.function(a);
    const std::array<double, 5>& knots = fixes_eta(side_) ? f.knots_eta : f.knots_xi;
    // TSplineBasis::evaluate skips a function whose factor vanishes; a factor
    // of +0 computed anyway adds +0 to the sum and to S: nothing either.
    if (cubic_bspline_vanishes(knots, fixed)) continue;
    const double v = cubic_bspline(knots, fixed);
    if (v != 0.0) out.push_back({a, v});
  }
  return out;
}

Eigen::Vector2d MapSide::at(double t) const {
  const Eigen::Vector2d uv = side_uv(side_, t);
  const TSplineBasis& basis = map_.basis();
  const std::vector<Term>& ts = terms(basis.locate(uv));
  const double free = fixes_eta(side_) ? uv.x() : uv.y();
  // TSplineBasis::evaluate and TSplineMap::derivatives (order 0), term for
  // term: N = u w, S = sum N in the cell's order, R = N / S, then sum R P.
  thread_local std::vector<double> n;
  n.assign(ts.size(), 0.0);
  double S = 0.0;
  for (std::size_t k = 0; k < ts.size(); ++k) {
    const BlendingFunction& f = basis.function(ts[k].function);
    const std::array<double, 5>& knots = fixes_eta(side_) ? f.knots_xi : f.knots_eta;
    if (cubic_bspline_vanishes(knots, free)) continue;
    const double u = cubic_bspline(knots, free);
    n[k] = fixes_eta(side_) ? u * ts[k].side_factor : ts[k].side_factor * u;
    S += n[k];
  }
  if (!(S > 0.0)) throw InternalError("MapSide::at: the blending functions vanish at the point");
  const double inv = 1.0 / S;
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < ts.size(); ++k)
    if (n[k] != 0.0) x += (n[k] * inv) * map_.control_points()[ts[k].function];
  return x;
}

}  // namespace tspline

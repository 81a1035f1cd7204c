// Chord-length map between the four polygon chains and the sides of [0,1]^2.
#include "tspline/boundary/boundary_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "tspline/errors.h"

namespace tspline {

BoundaryMap::BoundaryMap(Polygon ccw_polygon, Corners corners)
    : polygon_(std::move(ccw_polygon)), corners_(std::move(corners)) {
  const std::size_t n = polygon_.vertices.size();
  const auto& c = corners_.index;
  if (n < 4) throw toolkit::InputError("BoundaryMap: polygon has fewer than 4 vertices");
  // The corners must be distinct, in range, and in CCW (cyclically increasing) order.
  int descents = 0;
  for (int k = 0; k < 4; ++k) {
    if (c[k] >= n) throw toolkit::InputError("BoundaryMap: corner index out of range");
    descents += c[(k + 1) % 4] <= c[k];
  }
  if (descents != 1) throw toolkit::InputError("BoundaryMap: corners are not distinct and in CCW order");

  for (int s = 0; s < 4; ++s) {
    auto& pts = chain_points_[s];
    auto& par = chain_params_[s];
    const std::size_t a = c[s], b = c[(s + 1) % 4];
    const std::size_t count = (b + n - a) % n + 1;  // vertices a..b inclusive, wrapping
    pts.reserve(count);
    par.reserve(count);
    double len = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t i = (a + k) % n;
      if (k > 0) len += (polygon_.vertices[i] - pts.back()).norm();
      pts.push_back(polygon_.vertices[i]);
      par.push_back(len);  // cumulative length for now
    }
    chain_length_[s] = len;
    // Normalize to chord parameters; the last one is set to exactly 1 (the
    // division could round it to 1 - ulp).
    for (double& t : par) t /= len;
    par.back() = 1.0;
    for (std::size_t k = 1; k < count; ++k) {
      if (!(par[k] > par[k - 1])) {
        throw NumericalError("BoundaryMap: chord parameters are not increasing on side " + std::to_string(s) +
                             " at file vertex " + std::to_string(polygon_.file_index[(a + k) % n]) +
                             " (edge too short relative to the chain length)");
      }
    }
  }
}

Eigen::Vector2d BoundaryMap::point(Side side, double t) const {
  if (!(t >= 0.0 && t <= 1.0)) throw toolkit::InputError("BoundaryMap::point: t must be in [0,1]");
  const auto& par = chain_params(side);
  const auto& pts = chain_points(side);
  // Segment k with par[k] <= t < par[k+1] (k = last segment when t == 1).
  const std::size_t k =
      static_cast<std::size_t>(std::upper_bound(par.begin(), par.end(), t) - par.begin()) - 1;
  if (t == par[k]) return pts[k];  // exact at vertices, including both corners
  const double w = (t - par[k]) / (par[k + 1] - par[k]);
  return pts[k] + w * (pts[k + 1] - pts[k]);
}

Eigen::Vector2d BoundaryMap::point_at(const Eigen::Vector2d& uv) const {
  const double u = uv.x(), v = uv.y();
  if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0))
    throw toolkit::InputError("BoundaryMap::point_at: (u, v) is outside [0,1]^2");
  // Order matters only at the parametric corners, where both choices agree:
  // (0,0) = Bottom t=0, (1,0) = Bottom t=1, (1,1) = Right t=1, (0,1) = Top t=1.
  if (v == 0.0) return point(Side::Bottom, u);
  if (u == 1.0) return point(Side::Right, v);
  if (v == 1.0) return point(Side::Top, 1.0 - u);
  if (u == 0.0) return point(Side::Left, 1.0 - v);
  throw toolkit::InputError("BoundaryMap::point_at: (u, v) is not on the boundary of [0,1]^2");
}

const std::vector<Eigen::Vector2d>& BoundaryMap::chain_points(Side side) const {
  return chain_points_[static_cast<int>(side)];
}

const std::vector<double>& BoundaryMap::chain_params(Side side) const {
  return chain_params_[static_cast<int>(side)];
}

double BoundaryMap::chain_length(Side side) const { return chain_length_[static_cast<int>(side)]; }

std::pair<std::size_t, std::size_t> BoundaryMap::vertices_between(Side side, double t0, double t1) const {
  const auto& par = chain_params(side);
  const auto first = static_cast<std::size_t>(std::upper_bound(par.begin(), par.end(), t0) - par.begin());
  const auto last = static_cast<std::size_t>(std::lower_bound(par.begin(), par.end(), t1) - par.begin());
  return {first, std::max(first, last)};
}

}  // namespace tspline

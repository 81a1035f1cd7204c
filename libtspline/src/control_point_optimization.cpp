#include "tspline/control_point_optimization.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "meshopt/affine_objective.h"

namespace tspline {

bool touches_border(const BlendingFunction& f) {
  auto open_end = [](const std::array<double, 5>& k) {
    return (k[0] == 0.0 && k[3] == 0.0) || (k[1] == 1.0 && k[4] == 1.0);
  };
  return open_end(f.knots_xi) || open_end(f.knots_eta);
}

namespace {

// Sparse "gradient of R_alpha at Gauss point g" data, stored both ways.
struct GaussData {
  std::vector<double> weight;                 // per Gauss point
  std::vector<Eigen::Matrix2d> J;             // current Jacobian per Gauss point
  std::vector<std::size_t> fn_offsets;        // per function: range into fn_points/fn_grads
  std::vector<int> fn_points;
  std::vector<Eigen::Vector2d> fn_grads;
};

// Gauss data of the included cells; gradients are kept only for free functions.
GaussData build_gauss_data(const TSplineMap& map, int gauss, const std::vector<char>& is_free,
                           const std::vector<char>& cell_included) {
  std::vector<double> gp, gw;
  gauss_points_01(gauss, gp, gw);
  const TMesh& mesh = map.mesh();
  const TSplineBasis& basis = map.basis();
  GaussData d;
  std::vector<std::vector<std::pair<int, Eigen::Vector2d>>> per_fn(basis.size());
  BasisValues v;
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    if (!cell_included[c]) continue;
    const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
    for (std::size_t a = 0; a < gp.size(); ++a)
      for (std::size_t b = 0; b < gp.size(); ++b) {
        const Eigen::Vector2d uv(lo.x() + gp[a] * (hi.x() - lo.x()), lo.y() + gp[b] * (hi.y() - lo.y()));
        basis.evaluate(c, uv, v, 1);
        const int g = static_cast<int>(d.weight.size());
        // Every cell counts equally whatever its size, like the cells of the
        // T-mesh objective: the weight is the Gauss weight on the unit cell.
        d.weight.push_back(gw[a] * gw[b]);
        Eigen::Matrix2d J = Eigen::Matrix2d::Zero();
        for (std::size_t k = 0; k < v.ids.size(); ++k) {
          const Eigen::Vector2d grad(v.R_xi[k], v.R_eta[k]);
          const Eigen::Vector2d& P = map.control_points()[v.ids[k]];
          J.col(0) += grad.x() * P;
          J.col(1) += grad.y() * P;
          if (is_free[v.ids[k]] && (grad.x() != 0.0 || grad.y() != 0.0)) per_fn[v.ids[k]].push_back({g, grad});
        }
        d.J.push_back(J);
      }
  }
  d.fn_offsets.assign(1, 0);
  for (const auto& list : per_fn) {
    for (const auto& [g, grad] : list) d.fn_points.push_back(g), d.fn_grads.push_back(grad);
    d.fn_offsets.push_back(d.fn_points.size());
  }
  return d;
}

}  // namespace

ControlPointOptimizationReport optimize_control_points(TSplineMap& map, const ControlPointOptimizationOptions& opt) {
  ControlPointOptimizationReport rep;
  std::vector<CellMapQuality> cells;
  rep.before = map_quality(map, opt.gauss, &cells);
  const TSplineBasis& basis = map.basis();
  const TMesh& mesh = map.mesh();
  // Free: interior functions (vanishing on the border) that are non-zero on a
  // cell with J_r below region_below (all interior functions if region_below <= 0).
  std::vector<char> is_free(basis.size(), 0);
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
    if (opt.region_below > 0.0 && cells[c].min_mean_ratio >= opt.region_below) continue;
    for (int a : basis.functions_on_cell(c))
      if (!touches_border(basis.function(a))) is_free[a] = 1;
  }
  // Cells whose Jacobian a free control point changes.
  std::vector<char> cell_included(mesh.num_cells(), 0);
  for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c)
    for (int a : basis.functions_on_cell(c))
      if (is_free[a]) {
        cell_included[c] = 1;
        break;
      }
  GaussData d = build_gauss_data(map, opt.gauss, is_free, cell_included);
  std::vector<Eigen::Vector2d> P = map.control_points();
  std::vector<int> free;
  for (int a = 0; a < static_cast<int>(basis.size()); ++a) {
    if (is_free[a])
      free.push_back(a);
    else
      ++rep.fixed_points;
  }
  rep.free_points = free.size();
  // Active set (as in meshopt::smooth): a point is visited again only if it or a
  // function sharing one of its Gauss points moved by more than the tolerance.
  std::vector<std::vector<int>> at_point(d.weight.size());
  for (int a : free)
    for (std::size_t k = d.fn_offsets[a]; k < d.fn_offsets[a + 1]; ++k) at_point[d.fn_points[k]].push_back(a);
  std::vector<char> active(basis.size(), 0);
  for (int a : free) active[a] = 1;
  std::vector<meshopt::AffineTerm> terms;
  for (int sweep = 0; sweep < opt.max_sweeps; ++sweep) {
    double max_move = 0.0;
    for (int a : free) {
      if (!active[a]) continue;
      active[a] = 0;
      const std::size_t b = d.fn_offsets[a], e = d.fn_offsets[a + 1];
      if (b == e) continue;
      // J_g = (J_g - P_a grad^T) + P_a grad^T: S0 = J_rest, c = grad (W = I).
      terms.clear();
      // Local length: the physical distance between neighbouring control
      // points, ~ |J| times a quarter of the parametric support width.
      const BlendingFunction& fa = basis.function(a);
      const double span = 0.125 * ((fa.knots_xi[4] - fa.knots_xi[0]) + (fa.knots_eta[4] - fa.knots_eta[0]));
      double jsum = 0.0;
      for (std::size_t k = b; k < e; ++k) {
        const int g = d.fn_points[k];
        const Eigen::Vector2d& grad = d.fn_grads[k];
        meshopt::AffineTerm t;
        t.S0 = d.J[g] - P[a] * grad.transpose();
        t.c = grad;
        t.weight = d.weight[g];
        t.power = opt.power;
        terms.push_back(t);
        jsum += d.J[g].norm() / std::sqrt(2.0);
      }
      const double length = span * jsum / static_cast<double>(e - b);
      const Eigen::Vector2d moved = meshopt::optimize_affine_point(P[a], terms, length, opt.node);
      const Eigen::Vector2d delta = moved - P[a];
      if (delta.squaredNorm() == 0.0) continue;
      for (std::size_t k = b; k < e; ++k) d.J[d.fn_points[k]] += delta * d.fn_grads[k].transpose();
      P[a] = moved;
      const double rel = delta.norm() / length;
      max_move = std::max(max_move, rel);
      if (rel >= opt.relative_tolerance)
        for (std::size_t k = b; k < e; ++k)
          for (int n : at_point[d.fn_points[k]]) active[n] = 1;
    }
    rep.sweeps = sweep + 1;
    if (max_move < opt.relative_tolerance) {
      rep.converged = true;
      break;
    }
  }
  map.set_control_points(std::move(P));
  rep.after = map_quality(map, opt.gauss);
  return rep;
}

}  // namespace tspline

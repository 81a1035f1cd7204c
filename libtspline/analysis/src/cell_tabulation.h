#pragma once
// Private to tspline_analysis: one analysis cell's functions and its geometry
// map tabulated at the cell's quadrature points, for the assembly
// (poisson_assembly.cpp), the errors and the estimator (poisson_estimator.cpp).
//
// Every function here, analysis (hierarchical B-spline) or geometry (T-spline
// blending function N_a before normalization), is a product N[kx](x) N[ky](y).
// A cell's functions share few distinct knot vectors (4 per direction and
// level for the analysis functions), and the quadrature points of the cell's
// pieces lie on few distinct x and y lines. So each distinct factor is
// evaluated (cubic_bspline, as the bases do) once per distinct coordinate,
// instead of twice per function and point.
#include <Eigen/Core>
#include <array>
#include <span>
#include <stdexcept>
#include <vector>

#include "tspline/analysis/analysis_space.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/tspline_map.h"
#include "toolkit/errors.h"

namespace tspline::detail {

/// Index of `value` in `list`, appended if absent (the lists are short).
template <class List, class T>
std::size_t index_of(List& list, const T& value) {
  for (std::size_t i = 0; i < list.size(); ++i)
    if (list[i] == value) return i;
  list.push_back(value);
  return list.size() - 1;
}

/// A univariate factor's value and derivatives at one coordinate.
struct Factor {
  double v = 0.0, d = 0.0, dd = 0.0;
};

/// The factors of nf tensor-product functions at the distinct coordinates xs, ys.
class TensorFactors {
 public:
  /// knots_x(k), knots_y(k): the knot vectors of function k. order 1 or 2.
  template <class KnotsX, class KnotsY>
  void build(std::size_t nf, KnotsX knots_x, KnotsY knots_y, const std::vector<double>& xs,
             const std::vector<double>& ys, int order) {
    knx_.clear();
    kny_.clear();
    kx_.resize(nf);
    ky_.resize(nf);
    for (std::size_t k = 0; k < nf; ++k) {
      kx_[k] = index_of(knx_, knots_x(k));
      ky_[k] = index_of(kny_, knots_y(k));
    }
    tabulate(knx_, xs, ux_, order);
    tabulate(kny_, ys, uy_, order);
  }
  /// Factor in x of function k at distinct coordinate i (and in y).
  const Factor& x(std::size_t i, std::size_t k) const { return ux_[i * knx_.size() + kx_[k]]; }
  const Factor& y(std::size_t i, std::size_t k) const { return uy_[i * kny_.size() + ky_[k]]; }

 private:
  static void tabulate(const std::vector<std::array<double, 5>>& knots, const std::vector<double>& ts,
                       std::vector<Factor>& out, int order) {
    out.resize(ts.size() * knots.size());
    for (std::size_t i = 0; i < ts.size(); ++i)
      for (std::size_t j = 0; j < knots.size(); ++j) {
        Factor& u = out[i * knots.size() + j];
        u.v = cubic_bspline(knots[j], ts[i], &u.d, order >= 2 ? &u.dd : nullptr);
      }
  }
  std::vector<std::array<double, 5>> knx_, kny_;  // distinct knot vectors in x and y
  std::vector<std::size_t> kx_, ky_;              // per function: its factors
  std::vector<Factor> ux_, uy_;                   // [coordinate][factor]
};

/// One cell of a patch tabulated at its quadrature points: its analysis
/// functions (ids, ascending) and the geometry map.
class CellTabulation {
 public:
  /// Cell c of `space` (on `map`) at the points qp, derivatives up to `order` (1 or 2).
  void set(const TSplineMap& map, const PatchSpace& space, int c, const std::vector<QuadraturePoint>& qp, int order) {
    map_ = &map;
    order_ = order;
    xs_.clear();
    ys_.clear();
    qx_.resize(qp.size());
    qy_.resize(qp.size());
    for (std::size_t q = 0; q < qp.size(); ++q) {
      qx_[q] = index_of(xs_, qp[q].uv.x());
      qy_[q] = index_of(ys_, qp[q].uv.y());
    }
    const HierarchicalBasis& basis = space.basis();
    ids = basis.functions_on_cell(c);
    analysis_.build(
        ids.size(), [&](std::size_t k) -> const auto& { return basis.function(ids[k]).knots_xi; },
        [&](std::size_t k) -> const auto& { return basis.function(ids[k]).knots_eta; }, xs_, ys_, order);
    const TSplineBasis& gb = map.basis();
    gids_ = &gb.functions_on_cell(space.geometry_cell(c));
    geometry_.build(
        gids_->size(), [&](std::size_t k) -> const auto& { return gb.function((*gids_)[k]).knots_xi; },
        [&](std::size_t k) -> const auto& { return gb.function((*gids_)[k]).knots_eta; }, xs_, ys_, order);
  }

  /// The cell's analysis functions (basis().functions_on_cell).
  std::span<const int> ids;

  /// Factors of analysis function k (of ids) at quadrature point q.
  const Factor& x(std::size_t q, std::size_t k) const { return analysis_.x(qx_[q], k); }
  const Factor& y(std::size_t q, std::size_t k) const { return analysis_.y(qy_[q], k); }

  /// S, J and (order 2) the second derivatives at quadrature point q. With
  /// S = A / W, A = sum N_a P_a, W = sum N_a (TSplineBasis: R_a = N_a / W),
  /// differentiating A = S W: S_i = (A_i - S W_i) / W,
  /// S_ij = (A_ij - S_i W_j - S_j W_i - S W_ij) / W.
  MapDerivatives geometry(std::size_t q) const {
    // Derivatives of N_a (and sums) in the order 1, x, y, xx, xy, yy.
    const std::size_t nd = order_ >= 2 ? 6 : 3;
    const std::vector<Eigen::Vector2d>& P = map_->control_points();
    std::array<double, 6> Ws{};
    std::array<Eigen::Vector2d, 6> As;
    for (Eigen::Vector2d& v : As) v.setZero();
    for (std::size_t k = 0; k < gids_->size(); ++k) {
      const Factor &a = geometry_.x(qx_[q], k), &b = geometry_.y(qy_[q], k);
      const std::array<double, 6> n{a.v * b.v, a.d * b.v, a.v * b.d, a.dd * b.v, a.d * b.d, a.v * b.dd};
      const Eigen::Vector2d& p = P[(*gids_)[k]];
      for (std::size_t i = 0; i < nd; ++i) {
        Ws[i] += n[i];
        As[i] += n[i] * p;
      }
    }
    const double W = Ws[0], Wx = Ws[1], Wy = Ws[2], Wxx = Ws[3], Wxy = Ws[4], Wyy = Ws[5];
    if (!(W > 0.0)) throw toolkit::InternalError("Poisson: the blending functions vanish at a quadrature point");
    MapDerivatives d;
    d.x = As[0] / W;
    d.J.col(0) = (As[1] - d.x * Wx) / W;
    d.J.col(1) = (As[2] - d.x * Wy) / W;
    if (nd == 6) {
      d.xixi = (As[3] - 2.0 * d.J.col(0) * Wx - d.x * Wxx) / W;
      d.xieta = (As[4] - d.J.col(0) * Wy - d.J.col(1) * Wx - d.x * Wxy) / W;
      d.etaeta = (As[5] - 2.0 * d.J.col(1) * Wy - d.x * Wyy) / W;
    }
    return d;
  }

 private:
  const TSplineMap* map_ = nullptr;
  int order_ = 1;
  const std::vector<int>* gids_ = nullptr;  // the geometry cell's functions
  std::vector<double> xs_, ys_;             // distinct quadrature coordinates
  std::vector<std::size_t> qx_, qy_;        // per quadrature point: its coordinates
  TensorFactors analysis_, geometry_;
};

}  // namespace tspline::detail

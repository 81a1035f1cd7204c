#pragma once
// The map on Bezier elements (bezier_extraction.h) in Bernstein form, for
// evaluation at many points: per element 48 coefficients, relative to an
// origin (one of the element's control points) so that coordinates far from
// (0, 0) do not cancel in the derivatives; then about 150 multiply-adds per
// point for S and its Jacobian, instead of evaluating the blending functions
// point by point (TSplineMap::derivatives, about ten times as much).
//
// On element e with N_a = sum_k C_e(a, k) B_k (k = i + 4 j):
//   X = sum_k X_k B_k, X_k = sum_a C_e(a, k) (P_a - o),  w = sum_k w_k B_k,
//   S = o + X / w,  dS/ds = (X_s - X w_s / w) / w  (the rational map, Eq. 6).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

/// The map on one Bezier element.
struct ElementMap {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< o: a control point of the element
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();  ///< the element's box
  double X[16] = {}, Y[16] = {}, W[16] = {};  ///< Bernstein coefficients of X, Y (relative to o) and w

  ElementMap() = default;
  /// The element e of the map with control points P.
  ElementMap(const BezierElement& e, const std::vector<Eigen::Vector2d>& P);

  /// S and its Jacobian dS/d(xi, eta) at local coordinates (s, t) in [0, 1]^2
  /// (second derivatives are not set).
  MapDerivatives at_local(double s, double t) const;
  /// The same at a parametric point of the element's box (its boundary included).
  MapDerivatives at(const Eigen::Vector2d& uv) const;
};

/// The map on one T-mesh cell at a time: the cell's elements, evaluated at any
/// parametric point of the closed cell. A cell's points on the boundary
/// between two of its elements take the first element that holds them
/// (the map is C2 across knot lines inside a cell, so both give S and J to
/// round-off).
class CellMapEvaluator {
 public:
  /// Keeps references: extraction and P must outlive the evaluator.
  CellMapEvaluator(const BezierExtraction& extraction, const std::vector<Eigen::Vector2d>& P)
      : extraction_(extraction), P_(P) {}
  /// Makes cell c current (no work if it already is).
  void set_cell(int c);
  int cell() const { return cell_; }
  /// S and J at a parametric point of the current cell.
  MapDerivatives at(const Eigen::Vector2d& uv) const;

 private:
  const BezierExtraction& extraction_;
  const std::vector<Eigen::Vector2d>& P_;
  int cell_ = -1;
  std::vector<ElementMap> elements_;
};

}  // namespace tspline

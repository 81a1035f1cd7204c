#pragma once
// Bezier extraction of the cubic T-spline basis (Scott, Borden, Verhoosel,
// Sederberg, Hughes, "Isogeometric finite element data structures based on
// Bezier extraction of T-splines", IJNME 2011).
//
// A T-mesh cell is not always a polynomial patch of every blending function
// that covers it: near T-junctions the knot lines of a function (its local knot
// vectors, tspline_basis.h) can cross the interior of a cell. A Bezier element
// is a cell split by every knot line of the functions whose support meets the
// cell; on each element every such function N_a = N[knots_xi] x N[knots_eta] is
// one polynomial of bidegree (3,3), written in the tensor-product Bernstein
// basis of the element:
//
//   N_a|_e(xi, eta) = sum_{i,j=0..3} C_e(a, i + 4 j) B_i^3(s) B_j^3(t),
//   s = (xi - lo.x) / (hi.x - lo.x),  t = (eta - lo.y) / (hi.y - lo.y),
//   B_i^3(s) = binom(3, i) s^i (1 - s)^(3 - i).
//
// C_e is the extraction operator of the element (one row per function). The
// element bounds are exact dyadic numbers (integer T-mesh coordinates / kRoot).
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "tspline/spline/tspline_basis.h"

namespace tspline {

struct BezierElement {
  int cell = -1;                                 ///< the T-mesh cell containing the element
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();  ///< parametric lower-left corner
  Eigen::Vector2d hi = Eigen::Vector2d::Zero();  ///< parametric upper-right corner
  std::vector<int> functions;                    ///< blending functions non-zero on the element (sorted)
  /// functions.size() x 16: row r holds the Bernstein coefficients of
  /// N_{functions[r]} on the element, column i + 4 j for B_i(s) B_j(t).
  Eigen::Matrix<double, Eigen::Dynamic, 16, Eigen::RowMajor> C;

  /// Local coordinates (s, t) in [0,1]^2 of a parametric point.
  Eigen::Vector2d local(const Eigen::Vector2d& uv) const {
    return {(uv.x() - lo.x()) / (hi.x() - lo.x()), (uv.y() - lo.y()) / (hi.y() - lo.y())};
  }
};

/// The map's homogeneous Bezier points on the element, for control points P
/// (one per blending function): with N_a = sum_k C(a,k) B_k on the element,
/// X = sum_a P_a N_a and w = sum_a N_a (R = N / sum N, Eq. 6) are
/// sum_k X_k B_k and sum_k w_k B_k, X_k = sum_a C(a,k) P_a, w_k = sum_a C(a,k).
/// Row k = i + 4 j holds (X_k, w_k); the Bezier point itself is X_k / w_k.
Eigen::Matrix<double, 16, 3> homogeneous_bezier_points(const BezierElement& e,
                                                       const std::vector<Eigen::Vector2d>& P);

/// The split abscissae of cell c in one direction: the cell's own bounds and
/// every knot of the functions on c strictly inside it, sorted (>= 2 values).
void cell_element_breaks(const TSplineBasis& basis, int c, std::vector<double>& xi_breaks,
                         std::vector<double>& eta_breaks);

/// The Bezier elements of cell c (row by row, xi fastest), with their
/// extraction operators. The elements tile the cell exactly.
std::vector<BezierElement> extract_cell(const TSplineBasis& basis, int c);

/// Bernstein coefficients of the cubic B-spline with the given 5 knots on the
/// interval [a, b], which must lie inside one knot span (or outside the support).
std::array<double, 4> bspline_bernstein(const std::array<double, 5>& knots, double a, double b);

/// The Bezier elements of every cell, cells in order.
class BezierExtraction {
 public:
  explicit BezierExtraction(const TSplineBasis& basis);
  const std::vector<BezierElement>& elements() const { return elements_; }
  /// Elements of cell c: indices [cell_begin(c), cell_begin(c + 1)).
  std::size_t cell_begin(int c) const { return cell_begin_[c]; }

 private:
  std::vector<BezierElement> elements_;
  std::vector<std::size_t> cell_begin_;
};

/// A basis's extraction as given, or made here if none is given (for
/// functions that take an extraction made already by their caller).
class ExtractionOrOwn {
 public:
  ExtractionOrOwn(const TSplineBasis& basis, const BezierExtraction* given)
      : own_(given ? std::nullopt : std::optional<BezierExtraction>(std::in_place, basis)),
        extraction_(given ? given : &*own_) {}
  ExtractionOrOwn(const ExtractionOrOwn&) = delete;
  ExtractionOrOwn& operator=(const ExtractionOrOwn&) = delete;
  const BezierExtraction& get() const { return *extraction_; }

 private:
  std::optional<BezierExtraction> own_;
  const BezierExtraction* extraction_;
};

/// A quadrature point of a cell: parametric position and weight (parametric
/// area measure: the weights of a cell sum to its area).
struct QuadraturePoint {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double weight = 0.0;
};

/// n x n Gauss points (n = 1..6) on every Bezier element of cell c of `basis`.
/// Gauss quadrature over a whole cell crossed by a knot line integrates a
/// function with a kink in its third derivative there; per element the
/// integrand is smooth, and n points integrate polynomials of bidegree 2n - 1
/// exactly. If `geometry` is given (a basis whose T-mesh is coarser, the cell
/// g of which contains c), the elements are also split by the knot lines of
/// the functions on g that cross c, so that the geometry map is smooth on each.
void cell_quadrature(const TSplineBasis& basis, int c, int n, std::vector<QuadraturePoint>& out,
                     const TSplineBasis* geometry = nullptr, int g = -1);

/// n x n Gauss points on the box [lo, hi] (a cell of an analysis space that is
/// polynomial on it, e.g. hierarchical B-splines) split by the knot lines of the
/// geometry's functions on its cell g (which contains the box) that cross it,
/// so that the geometry map is smooth on every piece.
void box_quadrature(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int n, std::vector<QuadraturePoint>& out,
                    const TSplineBasis& geometry, int g);

/// Values of the four cubic Bernstein polynomials at s.
std::array<double, 4> bernstein3(double s);

}  // namespace tspline

#pragma once
// Certified validity of the T-spline map: det J > 0 on every Bezier element,
// proved on the whole element and not only at quadrature points (the method
// Gmsh uses for curved finite elements: Johnen, Remacle, Geuzaine, "Geometrical
// validity of curvilinear finite elements", J. Comput. Phys. 233, 2013).
//
// On a Bezier element e (bezier_extraction.h) the map is S = X / w with
// X = sum_a P_a N_a and w = sum_a N_a, polynomials of bidegree (3,3) in the
// element's local coordinates (s, t). With subscripts for derivatives,
//
//   det dS/d(s,t) = D / w^3,
//   D = w det(X_s, X_t) - w_t det(X_s, X) - w_s det(X, X_t),
//
// and D has bidegree (8,8) (w det(X_s, X_t): (3+2+3, 3+3+2)). Since w > 0 on
// the domain, sign det J = sign D. D is written in the Bernstein basis (81
// coefficients) by exact Bernstein product and derivative formulas. Bernstein
// polynomials are non-negative and sum to one, so
//   * all coefficients > 0 proves D > 0 on the element;
//   * the corner coefficients are the values at the corners, so a negative
//     corner coefficient of the element or of a sub-patch proves det J < 0 there;
//   * otherwise the patch is split at s = 1/2 and t = 1/2 (de Casteljau), whose
//     coefficients converge to the values, and each quarter is examined in turn,
//     down to a depth limit (then "undecided": not certified).
// A coefficient counts as positive only above a round-off margin,
// relative_tolerance (1e-10) times a bound of |D| (the same products of the
// largest absolute coefficients), and a corner value as negative only below
// minus that margin. The arithmetic is ordinary floating point, not interval
// arithmetic: the margin is some 1e3-1e4 times the accumulated round-off of the
// extraction and the products, and an element is left uncertified only where
// det J comes within about 1e-10 of its scale of zero (a degenerate map).
//
// Lower bound: with d_min the smallest coefficient over the final sub-patches
// and w_min <= w <= w_max the extremes of w's Bernstein coefficients,
//   det J >= d_min / w_max^3 if d_min >= 0, and >= d_min / w_min^3 otherwise,
// in local coordinates; dividing by the element's mean of det J (5x5 Gauss
// quadrature of D / w^3, exact when w is constant, which it is away from
// T-junctions) gives the scale-free relative lower bound reported, in (0, 1]
// for a certified element (1 only for a constant det J; up to the quadrature
// error of the mean where w varies).
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

struct CertificationOptions {
  int max_depth = 8;                  ///< subdivision levels at most (each level halves both directions)
  double relative_tolerance = 1e-10;  ///< round-off margin relative to ElementJacobian::scale
};

enum class ElementStatus { Certified, Invalid, Undecided };

struct ElementCertificate {
  ElementStatus status = ElementStatus::Undecided;
  /// Rigorous lower bound of det J on the element, parametric coordinates.
  double det_lower_bound = 0.0;
  /// Mean of det J over the element (parametric coordinates).
  double det_mean = 0.0;
  /// det_lower_bound / det_mean (-infinity if det_mean <= 0).
  double relative_lower_bound = 0.0;
  /// Invalid: parametric point where det J < 0, and det J there.
  Eigen::Vector2d negative_at = Eigen::Vector2d::Zero();
  double negative_det = 0.0;
  int depth = 0;            ///< deepest subdivision level used
  std::size_t patches = 0;  ///< sub-patches examined
};

ElementCertificate certify_element(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                   const CertificationOptions& options = {});

/// An element that is not certified.
struct CertificationFailure {
  int cell = -1;
  std::size_t element = 0;  ///< index in the map's BezierExtraction
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
  ElementCertificate certificate;
};

struct MapCertification {
  std::size_t elements = 0;
  std::size_t certified = 0;
  std::size_t invalid = 0;    ///< proven det J < 0 somewhere
  std::size_t undecided = 0;  ///< neither at the depth limit
  /// Min over all elements of the relative lower bound (> 0 iff certified valid,
  /// up to elements with zero mean; -infinity if some element has mean <= 0).
  double min_relative_lower_bound = 0.0;
  double min_det_lower_bound = 0.0;  ///< min over elements, parametric coordinates
  int max_depth_used = 0;
  std::vector<char> cell_certified;  ///< per T-mesh cell: all its elements certified
  /// Per T-mesh cell, the minimum over its elements of det_lower_bound and of
  /// relative_lower_bound (ElementCertificate); NaN for a cell none of whose
  /// elements was examined (certify_map with `only`).
  std::vector<double> cell_det_lower_bound, cell_relative_lower_bound;
  std::vector<CertificationFailure> failures;
  double seconds = 0.0;
  bool certified_valid() const { return elements > 0 && certified == elements; }
};

/// Certifies every Bezier element of every cell.
MapCertification certify_map(const TSplineMap& map, const CertificationOptions& options = {});
/// The same on an extraction made once (of a basis with num_cells cells) and
/// the control points P. With `only` (one flag per element), only the flagged
/// elements are examined: the counts and bounds are theirs (a local problem,
/// where the other elements do not change). The elements are examined in
/// parallel (detail/thread_pool.h); the result does not depend on the threads.
MapCertification certify_map(const BezierExtraction& extraction, std::size_t num_cells,
                             const std::vector<Eigen::Vector2d>& P, const CertificationOptions& options = {},
                             const std::vector<char>* only = nullptr);

}  // namespace tspline

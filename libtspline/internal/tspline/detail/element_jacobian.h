#pragma once
// Internal to libtspline: the Jacobian determinant of the map on one Bezier
// element as a Bernstein polynomial, D = w det(X_s, X_t) - w_t det(X_s, X)
// - w_s det(X, X_t) of bidegree (8,8) (validity/map_certification.h explains
// the method). Not part of the public interface.
#include <Eigen/Core>
#include <vector>

#include "tspline/detail/bernstein.h"
#include "tspline/spline/bezier_extraction.h"

namespace tspline::detail {

/// The Jacobian of the map on one Bezier element in Bernstein form.
struct ElementJacobian {
  BernsteinPoly numerator;  ///< D, bidegree (8,8), local coordinates
  BernsteinPoly weight;     ///< w, bidegree (3,3)
  double scale = 0.0;       ///< bound of |D| from the magnitudes of the factors (round-off scale)
  /// det J in parametric coordinates at local (s, t): D / (w^3 h_xi h_eta).
  double det_param(const BezierElement& e, double s, double t) const;
};

/// D and w for element e of the map with control points P (the control points
/// are taken relative to their mean on the element: det J is translation
/// invariant and this avoids cancellation far from the origin). Without
/// `numerator`, D is not made (numerator has degree (0,0) and value 0): w and
/// the scale only, the same doubles.
ElementJacobian element_jacobian(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                 bool numerator = true);

}  // namespace tspline::detail

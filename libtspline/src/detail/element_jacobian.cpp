// The Jacobian numerator of a Bezier element; see tspline/detail/element_jacobian.h.
#include "tspline/detail/element_jacobian.h"

#include <algorithm>

namespace tspline::detail {

namespace {

double max_abs(const BernsteinPoly& p) { return p.max_abs_coefficient(); }

}  // namespace

// ---------------------------------------------------------------------------
// The Jacobian numerator of an element
// ---------------------------------------------------------------------------
double ElementJacobian::det_param(const BezierElement& e, double s, double t) const {
  const double w = weight(s, t);
  return numerator(s, t) / (w * w * w * (e.hi.x() - e.lo.x()) * (e.hi.y() - e.lo.y()));
}

ElementJacobian element_jacobian(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                 bool numerator) {
  const Eigen::Index nf = e.C.rows();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (Eigen::Index r = 0; r < nf; ++r) centre += P[e.functions[r]];
  if (nf > 0) centre /= static_cast<double>(nf);
  BernsteinPoly X(3, 3), Y(3, 3), W(3, 3);
  for (Eigen::Index r = 0; r < nf; ++r) {
    const Eigen::Vector2d p = P[e.functions[r]] - centre;
    for (int k = 0; k < 16; ++k) {
      const double b = e.C(r, k);
      X.c[k] += p.x() * b;
      Y.c[k] += p.y() * b;
      W.c[k] += b;
    }
  }
  const BernsteinPoly Xs = bernstein_ds(X), Ys = bernstein_ds(Y), Xt = bernstein_dt(X), Yt = bernstein_dt(Y);
  const BernsteinPoly Ws = bernstein_ds(W), Wt = bernstein_dt(W);
  ElementJacobian J;
  J.weight = W;
  if (numerator && Ws.is_zero() && Wt.is_zero()) {
    // w constant (the functions sum to 1 on the element): the products with
    // w_t and w_s below are +0 in every coefficient, and subtracting them
    // changes none: D = w det(X_s, X_t), the same doubles.
    J.numerator =
        bernstein_product(W, bernstein_axpy(bernstein_product(Xs, Yt), -1.0, bernstein_product(Ys, Xt)));
  } else if (numerator) {
    // det(X_s, X_t), det(X_s, X), det(X, X_t)
    const BernsteinPoly d_st = bernstein_axpy(bernstein_product(Xs, Yt), -1.0, bernstein_product(Ys, Xt));
    const BernsteinPoly d_s0 = bernstein_axpy(bernstein_product(Xs, Y), -1.0, bernstein_product(Ys, X));
    const BernsteinPoly d_0t = bernstein_axpy(bernstein_product(X, Yt), -1.0, bernstein_product(Y, Xt));
    J.numerator =
        bernstein_axpy(bernstein_axpy(bernstein_product(W, d_st), -1.0, bernstein_product(Wt, d_s0)), -1.0,
                       bernstein_product(Ws, d_0t));
  } else {
    J.numerator = BernsteinPoly(0, 0);
  }
  // |D| <= the same expression with every factor replaced by its largest
  // absolute coefficient (Bernstein coefficients of a product are convex
  // combinations of products of coefficients).
  const double xs = std::max(max_abs(Xs), max_abs(Ys)), xt = std::max(max_abs(Xt), max_abs(Yt));
  const double x0 = std::max(max_abs(X), max_abs(Y));
  J.scale = 2.0 * (max_abs(W) * xs * xt + max_abs(Wt) * xs * x0 + max_abs(Ws) * x0 * xt);
  return J;
}

}  // namespace tspline::detail

// The built-in manufactured Poisson problems (see manufactured_problems.h).
#include "tspline/analysis/manufactured_problems.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "tspline/errors.h"

namespace tspline {

namespace {

constexpr double kPi = std::numbers::pi;

std::string fmt(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

/// The bounding box of every patch's control points.
struct Box {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
};

Box control_box(const AnalysisGeometry& geometry) {
  Box b;
  for (const TSplineMap* m : geometry.patches)
    for (const Eigen::Vector2d& p : m->control_points()) {
      b.lo = b.lo.cwiseMin(p);
      b.hi = b.hi.cwiseMax(p);
    }
  return b;
}

ManufacturedProblem sinsin(const Box& b, double L) {
  ManufacturedProblem s;
  const double xl = b.lo.x(), yl = b.lo.y(), k = kPi / L;
  s.problem.exact = [=](double x, double y) { return std::sin(k * (x - xl)) * std::sin(k * (y - yl)); };
  s.problem.exact_gradient = [=](double x, double y) {
    return Eigen::Vector2d(k * std::cos(k * (x - xl)) * std::sin(k * (y - yl)),
                           k * std::sin(k * (x - xl)) * std::cos(k * (y - yl)));
  };
  s.problem.f = [=](double x, double y) { return 2 * k * k * std::sin(k * (x - xl)) * std::sin(k * (y - yl)); };
  s.u = "sin(pi X) sin(pi Y), X = (x - x_lo) / L, Y = (y - y_lo) / L";
  s.f = "2 pi^2 / L^2 sin(pi X) sin(pi Y)";
  s.constants = {{"x_lo", xl}, {"y_lo", yl}, {"L", L}};
  return s;
}

ManufacturedProblem polynomial(const Box& b, double L) {
  ManufacturedProblem s;
  const double xl = b.lo.x(), yl = b.lo.y();
  s.problem.exact = [=](double x, double y) {
    const double X = (x - xl) / L, Y = (y - yl) / L;
    return X * X * X + X * X * Y - 2 * Y * Y * Y + X * Y;
  };
  s.problem.exact_gradient = [=](double x, double y) -> Eigen::Vector2d {
    const double X = (x - xl) / L, Y = (y - yl) / L;
    return {(3 * X * X + 2 * X * Y + Y) / L, (X * X - 6 * Y * Y + X) / L};
  };
  s.problem.f = [=](double x, double y) { return (-6 * (x - xl) / L + 10 * (y - yl) / L) / (L * L); };
  s.u = "X^3 + X^2 Y - 2 Y^3 + X Y, X = (x - x_lo) / L, Y = (y - y_lo) / L";
  s.f = "(-6 X + 10 Y) / L^2";
  s.constants = {{"x_lo", xl}, {"y_lo", yl}, {"L", L}};
  return s;
}

ManufacturedProblem gaussian(const Box& b) {
  ManufacturedProblem p;
  const double x0 = 0.5 * (b.lo.x() + b.hi.x()), y0 = 0.5 * (b.lo.y() + b.hi.y());
  const double s = 0.1 * (b.hi - b.lo).norm(), s2 = s * s;
  p.problem.exact = [=](double x, double y) { return std::exp(-((x - x0) * (x - x0) + (y - y0) * (y - y0)) / s2); };
  p.problem.exact_gradient = [=](double x, double y) {
    const double u = std::exp(-((x - x0) * (x - x0) + (y - y0) * (y - y0)) / s2);
    return Eigen::Vector2d(-2 * (x - x0) / s2 * u, -2 * (y - y0) / s2 * u);
  };
  p.problem.f = [=](double x, double y) {
    const double r2 = (x - x0) * (x - x0) + (y - y0) * (y - y0);
    return std::exp(-r2 / s2) * (4 / s2 - 4 * r2 / (s2 * s2));
  };
  p.u = "exp(-((x - x0)^2 + (y - y0)^2) / s^2)";
  p.f = "u (4 / s^2 - 4 ((x - x0)^2 + (y - y0)^2) / s^4)";
  p.constants = {{"x0", x0}, {"y0", y0}, {"s", s}};
  p.choice = "(x0, y0) = centre of the bounding box of the control points of every patch, s = 0.1 x its diagonal";
  return p;
}

}  // namespace

const std::vector<std::string>& manufactured_problem_names() {
  static const std::vector<std::string> names{"gaussian", "sinsin", "polynomial"};
  return names;
}

ManufacturedProblem manufactured_problem(const std::string& name, const AnalysisGeometry& geometry) {
  const Box b = control_box(geometry);
  const double L = (b.hi - b.lo).maxCoeff(), D = (b.hi - b.lo).norm();
  if (!(L > 0.0) || !std::isfinite(D) || !((b.hi - b.lo).minCoeff() > 0.0))
  {
    std::string message = "`problem` ";
    message += name;
    message += ": the control points span no area (bounding box ";
    message += fmt(b.hi.x() - b.lo.x());
    message += " x ";
    message += fmt(b.hi.y() - b.lo.y());
    message += ")";
    throw InputError(message);
  }
  ManufacturedProblem p;
  if (name == "sinsin")
    p = sinsin(b, L);
  else if (name == "polynomial")
    p = polynomial(b, L);
  else if (name == "gaussian")
    p = gaussian(b);
  else
    throw InputError("unknown problem '" + name + "' (expected gaussian, sinsin or polynomial)");
  p.name = name;
  p.problem.g = p.problem.exact;
  if (p.choice.empty())
    p.choice = "(x_lo, y_lo) = lower-left corner of the bounding box of the control points of every patch, L = its "
               "longer side";
  return p;
}

}  // namespace tspline

#pragma once
// The built-in manufactured problems of `tspline poisson --problem NAME`
// (g = u; f = -Laplace u and the gradient of u analytic), scaled to the WHOLE
// domain of a map of any number of patches: with (x_lo, y_lo) the lower-left
// corner of the bounding box of every patch's control points, (x0, y0) its
// centre, L the longer of its sides and D its diagonal,
//   X = (x - x_lo) / L, Y = (y - y_lo) / L   (the identity on the unit square),
//   sinsin:      u = sin(pi X) sin(pi Y),                 f = 2 pi^2 / L^2 u;
//   polynomial:  u = X^3 + X^2 Y - 2 Y^3 + X Y,           f = (-6 X + 10 Y) / L^2
//                (in the discrete space when the map is affine);
//   gaussian:    u = exp(-((x - x0)^2 + (y - y0)^2) / s^2), s = 0.1 D,
//                f = u (4 / s^2 - 4 ((x - x0)^2 + (y - y0)^2) / s^4)
//                (the paper's experiment, whose formula was lost: our choice).
#include <string>
#include <utility>
#include <vector>

#include "tspline/analysis/analysis_space.h"
#include "tspline/analysis/poisson_solver.h"

namespace tspline {

struct ManufacturedProblem {
  PoissonProblem problem;
  std::string name;     ///< "sinsin", "polynomial" or "gaussian"
  std::string u, f;     ///< the formulas, for reports
  std::string g = "u";
  /// The constants of the formulas (x_lo, y_lo, L; x0, y0, s), for reports.
  std::vector<std::pair<std::string, double>> constants;
  std::string choice;   ///< how the constants were chosen
};

/// Names of the built-in problems.
const std::vector<std::string>& manufactured_problem_names();

/// \throw InputError for an unknown name or control points that span no area.
ManufacturedProblem manufactured_problem(const std::string& name, const AnalysisGeometry& geometry);

}  // namespace tspline

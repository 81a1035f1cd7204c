// Example 4: adaptive isogeometric Poisson solve with your own f and g.
//
//   example_poisson TSPLINE.json
//
// Solves -Laplace(u) = f in the domain, u = g on its boundary, on the geometry
// of a T-spline file (one patch, or a multi-patch map of `tspline param` on a
// domain with holes: the same code, the patches glued C0 across their
// interfaces), refining adaptively with the residual estimator
// eta_e^2 = int_e h_e^2 (f + Laplace u_h)^2 and marking eta_e > gamma max eta.
// Here u = exp(x) sin(y) is harmonic (f = 0) and known, so the errors are
// printed next to the estimator.
#include <cmath>
#include <cstdio>
#include <exception>

#include "tspline/io/multipatch_file.h"
#include "tspline/analysis/poisson.h"

int run(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: example_poisson TSPLINE.json\n");
    return 2;
  }
  // The patches and their interfaces (a single map: one patch, none).
  const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(argv[1]);
  tspline::AnalysisGeometry geometry;
  for (const tspline::io::LoadedTSpline& t : maps.patches) geometry.patches.push_back(&t.map);
  geometry.interfaces = maps.interfaces;

  // The problem: any callables of (x, y). The exact solution is optional; with
  // it the solver reports L2 and H1 errors (its gradient is optional too:
  // without it central differences are used).
  tspline::PoissonProblem p;
  p.f = [](double, double) { return 0.0; };
  p.g = [](double x, double y) { return std::exp(x) * std::sin(y); };
  p.exact = p.g;
  p.exact_gradient = [](double x, double y) {
    return Eigen::Vector2d(std::exp(x) * std::sin(y), std::exp(x) * std::cos(y));
  };

  tspline::AdaptiveSolveOptions o;
  o.refine = tspline::AdaptiveSolveOptions::Refine::Adaptive;
  o.steps = 5;
  o.gamma = 0.5;
  // The callback sees every step: here we print a table row.
  std::printf("%5s %8s %12s %12s %12s\n", "step", "dofs", "eta", "L2", "H1");
  const auto steps = tspline::solve_adaptive(geometry, p, o, [](const tspline::PoissonStep& s, const auto&, const auto&) {
    std::printf("%5d %8zu %12.4e %12.4e %12.4e\n", s.step, s.dofs, s.eta, s.errors.l2, s.errors.h1);
  }).steps;
  // The spaces are nested (hierarchical B-splines), so the H1 error of the
  // Galerkin solution cannot grow from one step to the next.
  bool ok = steps.size() == 5;
  for (std::size_t k = 1; k < steps.size(); ++k) ok = ok && steps[k].errors.h1 <= steps[k - 1].errors.h1 * (1 + 1e-9);
  ok = ok && steps.back().errors.h1 < 0.5 * steps.front().errors.h1;
  std::printf("H1 error reduced by %.1fx\n", steps.front().errors.h1 / steps.back().errors.h1);
  return ok ? 0 : 1;
}

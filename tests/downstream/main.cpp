// Downstream check of the installed package: parameterize an ellipse, write the
// T-spline file, read it back, and solve a Poisson problem on it (one uniform refinement). Exits 0 only
// if every result is right; prints what it checked.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/io/tspline_file.h"
#include "tspline/analysis/poisson.h"

int main() {
  // Ellipse with semi-axes 2 and 1, 128 vertices, counter-clockwise.
  tspline::Polygon ellipse;
  const int n = 128;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * std::numbers::pi * i / n;
    ellipse.vertices.emplace_back(2.0 * std::cos(t), std::sin(t));
    ellipse.file_index.push_back(static_cast<std::size_t>(i));
  }
  const tspline::ParameterizationResult r = tspline::run_parameterization(ellipse, {}, {});
  if (!r.map || !r.valid()) {
    std::puts("FAIL: the ellipse's map is not valid");
    return 1;
  }
  const auto path = std::filesystem::temp_directory_path() / "tspline_downstream_check.json";
  tspline::io::TSplineFileMeta meta;
  meta.boundary = r.front.boundary.polygon();
  meta.corners = r.front.boundary.corners().index;
  tspline::io::write_tspline_file(path.string(), *r.map, meta);
  const tspline::io::LoadedTSpline back = tspline::io::read_tspline_file(path.string());
  std::filesystem::remove(path);
  const Eigen::Vector2d uv(0.3, 0.7);
  const double diff = (back.map.point(uv) - r.map->point(uv)).norm();
  // u = x^2 - y^2 is harmonic: f = 0, g = u.
  tspline::PoissonProblem p;
  p.f = [](double, double) { return 0.0; };
  p.g = [](double x, double y) { return x * x - y * y; };
  p.exact = p.g;
  tspline::AdaptiveSolveOptions o;
  o.refine = tspline::AdaptiveSolveOptions::Refine::Uniform;
  o.steps = 2;
  const std::vector<tspline::PoissonStep> steps = tspline::solve_adaptive(back.map, p, o).steps;
  const double e0 = steps.front().errors.l2 / steps.front().errors.l2_exact;
  const double e1 = steps.back().errors.l2 / steps.back().errors.l2_exact;
  std::printf("cells %zu, min J_r %.3f, file round trip %.1e, Poisson relative L2 error %.2e -> %.2e\n",
              r.map->mesh().num_cells(), r.quality.min_mean_ratio, diff, e0, e1);
  // One uniform refinement of a smooth problem: the error drops by about 2^4.
  if (diff != 0.0 || steps.size() != 2 || !(e1 < e0 / 4.0)) {
    std::puts("FAIL");
    return 1;
  }
  std::puts("downstream check passed");
  return 0;
}

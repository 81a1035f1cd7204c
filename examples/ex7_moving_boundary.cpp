// Example 7: a moving boundary, re-parameterized at each step from the previous
// map (shape optimization, moving domains).
//
//   example_moving_boundary [POLYGON] [OUT_DIR]
//
// The coastline (default: Puerto Rico, 235 vertices) is deformed in 20 steps by
// a smooth displacement field, 5 % of its diameter in total. Each step maps the
// moved polygon from the previous map (tspline::reparameterize: same T-mesh,
// knots and corners, the interior started from the old map moved with the
// boundary), solves a Poisson problem on it and prints the certified det J
// bound, the whole-map J_r and the solution's error. The first and last maps
// are drawn into OUT_DIR (default moving_boundary_out) as first.png, last.png.
// The same from the command line: tspline param MOVED.txt --from OLD/tspline.json --out NEW.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "tspline/analysis/manufactured_problems.h"
#include "tspline/analysis/poisson.h"
#include "tspline/deform/reparameterization.h"
#include "tspline/io/param_output.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/io/render.h"

namespace {

// Writes the map's files into dir and draws its J_r picture into png.
void draw(const tspline::ParameterizationResult& r, const std::string& dir, const std::string& png) {
  tspline::io::write_param_outputs(r, dir, tspline::io::param_report(r, "example 7"), 4);
  tspline::io::RenderOptions o;
  o.view = tspline::io::RenderView::Jacobian;
  tspline::io::render_png(dir, png, o);
}

// Relative L2 error of the Poisson solution on the map (u = sin sin, scaled to the domain).
double poisson_error(const tspline::TSplineMap& map) {
  const tspline::ManufacturedProblem mp = tspline::manufactured_problem("sinsin", tspline::AnalysisGeometry(map));
  const tspline::PoissonSolution u = tspline::solve_poisson(map, map.mesh(), mp.problem);
  const tspline::PoissonErrors e = tspline::compute_errors(u, mp.problem);
  return e.l2 / e.l2_exact;
}

}  // namespace

int run(int argc, char** argv) {
  const std::string input = argc > 1 ? argv[1] : std::string(TSPLINE_DATA_DIR) + "/coastlines/puerto_rico.txt";
  const std::filesystem::path out = argc > 2 ? argv[2] : "moving_boundary_out";
  const int steps = 20;
  const tspline::Polygon file = tspline::io::read_polygon(input);
  Eigen::Vector2d lo = file.vertices.front(), hi = lo;
  for (const auto& v : file.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double D = (hi - lo).norm();
  const Eigen::Vector2d c = 0.5 * (lo + hi);
  // Vertex x of the file at step k: x + (k / steps) u(x), |u(x)| <= 0.05 D.
  auto moved = [&](const Eigen::Vector2d& x, int k) {
    const double s = 0.05 * D * k / steps / std::sqrt(2.0);
    return Eigen::Vector2d(x.x() + s * std::sin(2.0 * M_PI * (x.y() - c.y()) / D + 0.3),
                           x.y() + s * std::cos(2.0 * M_PI * (x.x() - c.x()) / D));
  };

  // Step 0: the map from scratch (one patch, default options).
  tspline::ParameterizationResult map = tspline::run_parameterization(file, {}, {});
  const double cold_jr = map.dense_quality.min_mean_ratio;
  std::filesystem::create_directories(out);
  draw(map, (out / "step_00").string(), (out / "first.png").string());
  std::printf("%4s %8s %6s %10s %10s %9s %12s\n", "step", "seconds", "cells", "certified", "det bound", "J_r",
              "Poisson L2");
  std::printf("%4d %8s %6zu %10s %10.3g %9.4f %12.3e\n", 0, "cold", map.map->mesh().num_cells(),
              map.certified_valid() ? "yes" : "NO", map.certification.min_relative_lower_bound, cold_jr,
              poisson_error(*map.map));
  bool ok = map.certified_valid();
  int same_tmesh = 0;
  for (int k = 1; k <= steps; ++k) {
    // The moved polygon in the previous map's numbering (its stored polygon is
    // counter-clockwise; file_index says which vertex of the file each one is).
    const tspline::Polygon& old = map.front.boundary.polygon();
    tspline::Polygon now = old;
    for (std::size_t i = 0; i < now.vertices.size(); ++i) now.vertices[i] = moved(file.vertices[old.file_index[i]], k);
    const auto t0 = std::chrono::steady_clock::now();
    tspline::ParameterizationResult next = tspline::reparameterize(
        *map.map, old, map.front.boundary.corners().index, now, {}, {}, map.dense_quality.min_mean_ratio);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    same_tmesh += next.map->mesh().num_cells() == map.map->mesh().num_cells();
    std::printf("%4d %8.3f %6zu %10s %10.3g %9.4f %12.3e\n", k, seconds, next.map->mesh().num_cells(),
                next.certified_valid() ? "yes" : "NO", next.certification.min_relative_lower_bound,
                next.dense_quality.min_mean_ratio, poisson_error(*next.map));
    // Every map certified and at least half as good as the cold start.
    ok = ok && next.certified_valid() && next.dense_quality.min_mean_ratio >= 0.5 * cold_jr;
    map = std::move(next);
  }
  draw(map, (out / "step_20").string(), (out / "last.png").string());
  std::printf("%d of %d steps kept the T-mesh; pictures %s and %s\n", same_tmesh, steps,
              (out / "first.png").string().c_str(), (out / "last.png").string().c_str());
  return ok ? 0 : 1;
}

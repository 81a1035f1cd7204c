// Warm starts of a moving boundary against cold starts (tspline param --from).
//
//   bench_moving_boundary POLYGON [STEPS] [AMPLITUDE]
//
// The polygon's vertices move by a smooth field, AMPLITUDE (default 0.05) times
// the diameter at the last of STEPS (default 20) equal steps. Each step maps the
// moved polygon twice, in one process: from the previous step's map
// (reparameterize) and from scratch (run_parameterization, one patch, default
// options), and prints both times, their ratio, whole-map J_r (dense sample and
// Gauss points), certification, cells and whether the T-mesh stayed the same.
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "tspline/deform/reparameterization.h"
#include "tspline/io/polygon_reader.h"

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool same_tmesh(const tspline::TMesh& a, const tspline::TMesh& b) {
  if (a.num_cells() != b.num_cells()) return false;
  for (int c = 0; c < static_cast<int>(a.num_cells()); ++c)
    if (a.cell_min(c) != b.cell_min(c) || a.cell_max(c) != b.cell_max(c)) return false;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_moving_boundary POLYGON [STEPS] [AMPLITUDE]\n");
    return 2;
  }
  try {
    const int steps = argc > 2 ? std::atoi(argv[2]) : 20;
    const double amplitude = argc > 3 ? std::atof(argv[3]) : 0.05;
    const tspline::Polygon file = tspline::io::read_polygon(argv[1]);
    Eigen::Vector2d lo = file.vertices.front(), hi = lo;
    for (const auto& v : file.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const double D = (hi - lo).norm();
    const Eigen::Vector2d c = 0.5 * (lo + hi);
    // The displacement at step k of the file's vertex x: (k / steps) u(x), |u| <= amplitude D.
    auto moved = [&](const Eigen::Vector2d& x, int k) {
      const double s = amplitude * D * k / steps / std::sqrt(2.0);
      return Eigen::Vector2d(x.x() + s * std::sin(2.0 * M_PI * (x.y() - c.y()) / D + 0.3),
                             x.y() + s * std::cos(2.0 * M_PI * (x.x() - c.x()) / D));
    };
    const tspline::ParameterizationOptions opt;
    const tspline::AdaptiveOptions ad;
    auto t0 = std::chrono::steady_clock::now();
    tspline::ParameterizationResult prev = tspline::run_parameterization(file, opt, ad);
    std::printf("%s: %zu vertices, cold start %.3f s, %zu cells, whole-map J_r %.4f, %s\n", argv[1],
                file.vertices.size(), seconds_since(t0), prev.map->mesh().num_cells(),
                prev.dense_quality.min_mean_ratio, prev.certified_valid() ? "certified" : "NOT certified");
    std::printf("%4s %9s %9s %7s %8s %8s %6s %6s %7s %7s %5s\n", "step", "warm_s", "cold_s", "ratio", "Jr_warm",
                "Jr_cold", "cert_w", "cert_c", "cells_w", "cells_c", "same");
    double worst_ratio = 0.0, max_warm = 0.0;
    for (int k = 1; k <= steps; ++k) {
      const tspline::Polygon& old = prev.front.boundary.polygon();
      tspline::Polygon now = old;  // the previous map's numbering (CCW, file_index)
      for (std::size_t i = 0; i < now.vertices.size(); ++i) now.vertices[i] = moved(file.vertices[old.file_index[i]], k);
      tspline::Polygon now_file = file;
      for (auto& v : now_file.vertices) v = moved(v, k);
      t0 = std::chrono::steady_clock::now();
      tspline::ParameterizationResult warm = tspline::reparameterize(
          *prev.map, old, prev.front.boundary.corners().index, now, opt, ad, prev.dense_quality.min_mean_ratio);
      const double tw = seconds_since(t0);
      t0 = std::chrono::steady_clock::now();
      const tspline::ParameterizationResult cold = tspline::run_parameterization(now_file, opt, ad);
      const double tc = seconds_since(t0);
      std::printf("%4d %9.4f %9.4f %7.3f %8.4f %8.4f %6s %6s %7zu %7zu %5s\n", k, tw, tc, tw / tc,
                  warm.dense_quality.min_mean_ratio, cold.dense_quality.min_mean_ratio,
                  warm.certified_valid() ? "yes" : "NO", cold.certified_valid() ? "yes" : "NO",
                  warm.map->mesh().num_cells(), cold.map->mesh().num_cells(),
                  same_tmesh(warm.map->mesh(), prev.map->mesh()) ? "yes" : "no");
      if (std::getenv("BENCH_STAGES")) {
        for (const tspline::StageTime& st : warm.front.times) std::printf("  %s %.4f", st.stage.c_str(), st.seconds);
        std::printf("\n");
      }
      std::fflush(stdout);
      worst_ratio = std::max(worst_ratio, tw / tc);
      max_warm = std::max(max_warm, tw);
      prev = std::move(warm);
    }
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    std::printf("slowest warm step %.3f s, largest warm/cold ratio %.3f, peak RSS %.0f MiB\n", max_warm, worst_ratio,
                u.ru_maxrss / 1024.0);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_moving_boundary: %s\n", e.what());
    return 1;
  }
}

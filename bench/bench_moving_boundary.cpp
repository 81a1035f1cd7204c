// Warm starts of a moving boundary against cold starts (tspline param --from).
//
//   [LAYOUT=single|auto|quad] bench_moving_boundary POLYGON [STEPS] [AMPLITUDE]
//
// The polygon's vertices move by a smooth field, AMPLITUDE (default 0.05) times
// the diameter at the last of STEPS (default 20) equal steps. Each step maps the
// moved polygon twice, in one process: from the previous step's map
// (reparameterize, or reparameterize_layout for a multi-patch map) and from
// scratch (parameterize_domain with the LAYOUT choice, default single, and
// otherwise default options), and prints both times, their ratio, whole-map J_r (dense sample and
// Gauss points), certification, cells and whether the T-mesh stayed the same.
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "tspline/deform/layout_reparameterization.h"
#include "tspline/deform/reparameterization.h"
#include "tspline/pipeline/domain_parameterization.h"
#include "tspline/io/polygon_reader.h"
#include "toolkit/timing.h"

namespace {

using toolkit::seconds_since;

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
    tspline::DomainParameterizationOptions choice;
    choice.layout = tspline::parse_layout_mode(std::getenv("LAYOUT") ? std::getenv("LAYOUT") : "single");
    // A run's figures: whole-map J_r (dense sample and Gauss points), certified, cells, patches.
    struct Figures {
      double jr;
      bool certified;
      std::size_t cells, patches;
    };
    auto figures = [](const tspline::DomainParameterization& r) {
      if (r.patches) {
        std::size_t cells = 0;
        for (const auto& p : r.patches->patches) cells += p.map->mesh().num_cells();
        return Figures{std::min(r.patches->min_mean_ratio_dense(), r.patches->min_mean_ratio_gauss()),
                       r.patches->certified_valid(), cells, r.patches->patches.size()};
      }
      return Figures{r.single->dense_quality.min_mean_ratio, r.single->certified_valid(),
                     r.single->map->mesh().num_cells(), std::size_t{1}};
    };
    auto same_tmeshes = [](const tspline::DomainParameterization& a, const tspline::DomainParameterization& b) {
      if (!a.patches) return same_tmesh(a.single->map->mesh(), b.single->map->mesh());
      for (std::size_t p = 0; p < a.patches->patches.size(); ++p)
        if (!same_tmesh(a.patches->patches[p].map->mesh(), b.patches->patches[p].map->mesh())) return false;
      return true;
    };
    // The file's ring moved to step k, in the numbering of `ring` (CCW, file_index).
    auto moved_ring = [&](const tspline::Polygon& ring, int k) {
      tspline::Polygon now = ring;
      for (std::size_t i = 0; i < now.vertices.size(); ++i) now.vertices[i] = moved(file.vertices[ring.file_index[i]], k);
      return now;
    };
    auto t0 = std::chrono::steady_clock::now();
    tspline::DomainParameterization prev = tspline::parameterize_domain({file, {}}, opt, ad, choice);
    const Figures f0 = figures(prev);
    std::printf("%s: %zu vertices, layout %s (%zu patches), cold start %.3f s, %zu cells, whole-map J_r %.4f, %s\n",
                argv[1], file.vertices.size(), prev.layout.c_str(), f0.patches, seconds_since(t0), f0.cells, f0.jr,
                f0.certified ? "certified" : "NOT certified");
    std::printf("%4s %9s %9s %7s %8s %8s %6s %6s %7s %7s %5s\n", "step", "warm_s", "cold_s", "ratio", "Jr_warm",
                "Jr_cold", "cert_w", "cert_c", "cells_w", "cells_c", "same");
    double worst_ratio = 0.0, max_warm = 0.0;
    for (int k = 1; k <= steps; ++k) {
      tspline::Polygon now_file = file;
      for (auto& v : now_file.vertices) v = moved(v, k);
      t0 = std::chrono::steady_clock::now();
      tspline::DomainParameterization warm;
      warm.layout = prev.layout;
      if (prev.patches) {
        const tspline::MultiPatchResult& R = *prev.patches;
        tspline::PreviousLayout old;
        old.domain = R.domain;
        for (const auto& p : R.patches) {
          old.maps.push_back(&*p.map);
          old.polygons.push_back(p.front.boundary.polygon());
          old.corners.push_back(p.front.boundary.corners().index);
          old.reference_mean_ratio.push_back(p.dense_quality.min_mean_ratio);
        }
        old.interfaces = R.layout.interfaces;
        old.cuts = R.layout.cuts;
        warm.patches = tspline::reparameterize_layout(old, {moved_ring(R.domain.outer, k), {}}, opt, ad);
      } else {
        const tspline::ParameterizationResult& r = *prev.single;
        warm.single = tspline::reparameterize(*r.map, r.front.boundary.polygon(), r.front.boundary.corners().index,
                                              moved_ring(r.front.boundary.polygon(), k), opt, ad,
                                              r.dense_quality.min_mean_ratio);
      }
      const double tw = seconds_since(t0);
      if (std::getenv("BENCH_STAGES") && warm.single) {
        for (const tspline::StageTime& st : warm.single->front.times) std::printf("  %s %.4f", st.stage.c_str(), st.seconds);
        std::printf("\n");
      }
      t0 = std::chrono::steady_clock::now();
      // NO_COLD=1: warm steps only (for profiling), each compared with the first map.
      const tspline::DomainParameterization cold =
          std::getenv("NO_COLD") ? tspline::DomainParameterization{} : tspline::parameterize_domain({now_file, {}}, opt, ad, choice);
      const double tc = seconds_since(t0);
      const Figures fw = figures(warm), fc = cold.single || cold.patches ? figures(cold) : f0;
      std::printf("%4d %9.4f %9.4f %7.3f %8.4f %8.4f %6s %6s %7zu %7zu %5s\n", k, tw, tc, tw / tc, fw.jr, fc.jr,
                  fw.certified ? "yes" : "NO", fc.certified ? "yes" : "NO", fw.cells, fc.cells,
                  same_tmeshes(warm, prev) ? "yes" : "no");
      if (std::getenv("BENCH_WORST") && warm.patches) {
        std::size_t w = 0;
        const auto& ps = warm.patches->patches;
        for (std::size_t p = 1; p < ps.size(); ++p)
          if (ps[p].dense_quality.min_mean_ratio < ps[w].dense_quality.min_mean_ratio) w = p;
        const auto& poly = ps[w].front.boundary.polygon();
        std::size_t optimized = 0;
        for (const auto& r : ps) optimized += r.control_points_optimized;
        std::printf("  %zu of %zu patches optimized; worst patch %zu: J_r %.4f, %zu vertices, corners", optimized,
                    ps.size(), w, ps[w].dense_quality.min_mean_ratio, poly.vertices.size());
        for (std::size_t c : ps[w].front.boundary.corners().index)
          std::printf(" (%.4f, %.4f)", poly.vertices[c].x(), poly.vertices[c].y());
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

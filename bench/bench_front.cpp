// Benchmark of each stage of the front half (boundary, T-mesh, Coons,
// optimization) on one domain at one resolution. Prints one table row:
//   cells vertices boundary_s tmesh_s coons_s optimization_s sweeps(all stages) peak_MiB inverted
// Usage: bench_front POLYGON INIT_LEVEL TOL_REL [MAX_SWEEPS [CORNER_TRIALS]]
// ("boundary" includes the automatic corner trials). On stderr: the corner
// trials and the nested stages (FrontResult::stages).
// Run one size per process so the peak memory (getrusage) belongs to that size.
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/parameterization.h"

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s POLYGON INIT_LEVEL TOL_REL [MAX_SWEEPS]\n", argv[0]);
    return 1;
  }
  tspline::ParameterizationOptions opt;
  opt.initial_level = std::atoi(argv[2]);
  opt.tolerance_relative = std::atof(argv[3]);
  if (argc > 4) opt.smoothing.max_sweeps = std::atoi(argv[4]);
  if (argc > 5) opt.corner_trials = std::atoi(argv[5]);
  const auto poly = tspline::io::read_polygon(argv[1]);
  const tspline::FrontResult r = tspline::run_front(poly, opt);
  double t[4] = {0, 0, 0, 0};
  for (const auto& s : r.times) {
    if (s.stage == "boundary") t[0] = s.seconds;
    if (s.stage == "tmesh") t[1] = s.seconds;
    if (s.stage == "coons") t[2] = s.seconds;
    if (s.stage == "optimization") t[3] = s.seconds;
  }
  // On stderr: each corner trial's figures, and where each nested stage
  // started (carried over or Coons) with its inverted cells.
  for (const auto& c : r.corner_trials)
    std::fprintf(stderr, "corner trial %zu,%zu,%zu,%zu: %zu inverted cells, min/mean quality %.4g / %.4g\n",
                 c.corners[0], c.corners[1], c.corners[2], c.corners[3], c.inverted_cells, c.min_mean_ratio,
                 c.mean_mean_ratio);
  for (std::size_t k = 0; k < r.stages.size(); ++k) {
    const tspline::FrontStage& s = r.stages[k];
    std::fprintf(stderr, "stage %zu: %zu cells, from %s with %zu inverted cells", k + 1, s.cells,
                 s.carried ? "the previous stage" : "Coons", s.start_inverted);
    if (s.other_start_inverted) std::fprintf(stderr, " (the other start %zu)", *s.other_start_inverted);
    std::fprintf(stderr, ", %zu at the end, %d sweeps\n", s.end_inverted, s.sweeps);
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("%9zu %9zu %9.4f %9.4f %9.4f %9.4f %6d %9.1f %8zu\n", r.mesh.num_cells(), r.mesh.num_vertices(), t[0],
              t[1], t[2], t[3], r.total_sweeps, ru.ru_maxrss / 1024.0, r.quality_optimized.inverted_cells);
  return 0;
}

#pragma once
// Shared by the benchmarks that take `POLYGON INIT_LEVEL [TOL_REL]`: the
// stopwatches, and the front half (T-mesh, Coons, optimization) at that
// resolution with one corner trial.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/parameterization.h"
#include "toolkit/timing.h"

namespace bench {

using since_t = double (*)(toolkit::Clock::time_point);
inline constexpr since_t since = toolkit::seconds_since;

/// A stopwatch of consecutive stages: each call returns the seconds since the
/// previous call (the first: since construction) and starts the next stage.
class Laps {
 public:
  double operator()() {
    const toolkit::Clock::time_point now = toolkit::Clock::now();
    const double seconds = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return seconds;
  }

 private:
  toolkit::Clock::time_point start_ = toolkit::Clock::now();
};

/// The front half for POLYGON INIT_LEVEL [TOL_REL = 1e-6]; empty (after a usage
/// line on stderr) if the arguments are missing.
inline std::optional<tspline::FrontResult> front_from_args(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s POLYGON INIT_LEVEL [TOL_REL]\n", argv[0]);
    return std::nullopt;
  }
  tspline::ParameterizationOptions opt;
  opt.initial_level = std::atoi(argv[2]);
  opt.tolerance_relative = argc > 3 ? std::atof(argv[3]) : 1e-6;
  opt.corner_trials = 1;
  return tspline::run_front(tspline::io::read_polygon(argv[1]), opt);
}

}  // namespace bench

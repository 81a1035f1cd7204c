#pragma once
// Wall time per pipeline stage, for the reports' `times`.
#include <chrono>
#include <string>
#include <vector>

#include "tspline/pipeline/parameterization.h"

namespace tspline::detail {

/// Accumulates wall time per stage into `times`: stop(stage) adds the time
/// since the last stop (or since construction) to that stage; stages may be
/// entered several times.
class StageClock {
 public:
  explicit StageClock(std::vector<StageTime>& times) : times_(times) {}
  void stop(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    for (StageTime& t : times_)
      if (t.stage == stage) return void(t.seconds += dt);
    times_.push_back({stage, dt});
  }
  /// Counts from now (time spent waiting elsewhere goes to no stage).
  void restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::vector<StageTime>& times_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace tspline::detail

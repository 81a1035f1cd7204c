#pragma once
// Wall-clock timing of the stages that the libraries report (seconds in
// reports and progress lines).
#include <chrono>

namespace toolkit {

using Clock = std::chrono::steady_clock;

/// Seconds of wall time since t0.
inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace toolkit

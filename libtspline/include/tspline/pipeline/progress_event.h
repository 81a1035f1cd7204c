#pragma once
// Progress of the parameterization as typed events. The library reports what
// happens; the caller decides what to show (the `tspline` program prints steps
// and notes as log lines, rewrites sweeps and untangling stages in place on a
// terminal, and emits every event as a JSON line with --json).
#include <cstddef>
#include <functional>
#include <string>
#include <utility>

namespace tspline {

struct ProgressEvent {
  enum class Kind {
    Step,        ///< a step of the pipeline finished; `text` says what it did
    Note,        ///< something the user should know: cleaned input, a warning
    Sweep,       ///< one Gauss-Seidel sweep of the T-mesh optimization
    Untangling,  ///< one epsilon stage of the map's global untangling
    /// Nothing to show: a concurrent corner trial is still working (sent
    /// instead of its sweeps). A receiver that stops runs on request (Ctrl-C)
    /// throws from here, as from any other event, and the run ends with it.
    Heartbeat,
  };
  Kind kind = Kind::Step;
  /// Pipeline stage: "cleaning", "corners", "boundary", "tmesh", "coons",
  /// "optimization", "repair", "boundary_curve", "untangling", "map",
  /// "refinement", "stop"; of a multi-patch run also "layout", "patches",
  /// "interfaces" (the patches' steps have their own stages, the text begins
  /// "patch P: ") and, from the apps, "report".
  std::string stage;
  std::string text;         ///< one human-readable line
  int iteration = -1;       ///< adaptive round of the map (-1 in the front half)
  int count = -1;           ///< Sweep: the sweep (from 0); Untangling: the eps stage (from 0)
  double value = 0.0;       ///< Sweep: max relative node move; Untangling: eps
  std::size_t defects = 0;  ///< Sweep: tangled nodes; Untangling: samples with det J <= 0
};

/// Called from the thread that runs the pipeline or from its worker threads
/// (the concurrent corner trials), never from two threads at once. An
/// exception thrown by the callback stops the run and reaches its caller.
using ProgressCallback = std::function<void(const ProgressEvent&)>;

/// Kind::Step or Kind::Note events, if `callback` is set.
inline void report_step(const ProgressCallback& callback, std::string stage, std::string text, int iteration = -1,
                        ProgressEvent::Kind kind = ProgressEvent::Kind::Step) {
  if (!callback) return;
  ProgressEvent e;
  e.kind = kind;
  e.stage = std::move(stage);
  e.text = std::move(text);
  e.iteration = iteration;
  callback(e);
}

}  // namespace tspline

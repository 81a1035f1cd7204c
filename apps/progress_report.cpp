// Progress::report: the library's progress events (tspline/pipeline/progress_event.h)
// printed by the tspline program. Apart from progress.cpp so that the meshopt
// program, which shares Progress, does not depend on libtspline.
#include <iostream>

#include "interrupt.h"
#include "param_options.h"
#include "progress.h"
#include "tspline/pipeline/progress_event.h"

namespace tspline_app {

void Progress::report(const tspline::ProgressEvent& e) {
  throw_if_interrupted();  // also from the worker threads of the corner trials (their errors are rethrown)
  using Kind = tspline::ProgressEvent::Kind;
  if (e.kind == Kind::Heartbeat) return;  // nothing to show; the interrupt check above is its purpose
  const bool transient_kind = e.kind == Kind::Sweep || e.kind == Kind::Untangling;
  switch (mode_) {
    case OutputMode::Quiet: return;
    case OutputMode::Human: {
      // The library names options by field (`max_adapt`); this program by flag.
      const std::string text =
          e.text.find('`') == std::string::npos ? e.text : with_option_names(e.text, Spelling::Cli);
      if (transient_kind) return transient(text);
      return log(text);
    }
    case OutputMode::Json: {
      if (e.kind == Kind::Sweep && !(e.count < 3 || e.count % 50 == 0)) return;
      // Steps and notes keep the plain log lines' event name, with their stage and kind.
      static const char* const names[] = {"log", "log", "sweep", "untangling_stage"};
      nlohmann::json j{{"event", names[static_cast<int>(e.kind)]}, {"stage", e.stage}, {"message", e.text}};
      if (e.kind == Kind::Step || e.kind == Kind::Note) j["kind"] = e.kind == Kind::Step ? "step" : "note";
      if (e.iteration >= 0) j["iteration"] = e.iteration;
      if (e.kind == Kind::Sweep) j.update({{"sweep", e.count}, {"max_relative_move", e.value}, {"tangled_nodes", e.defects}});
      if (e.kind == Kind::Untangling)
        j.update({{"untangling_stage", e.count}, {"eps", e.value}, {"nonpositive_samples", e.defects}});
      std::cout << j.dump() << std::endl;
      return;
    }
  }
}

}  // namespace tspline_app

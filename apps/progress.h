#pragma once
// What the long-running commands (param, poisson) print while they work, in one
// of three modes:
//  * Human (default): log lines on stdout; on a terminal, the per-sweep lines of
//    the optimization and the progress bars are transient (rewritten in place
//    on one line) and the rest stays; off a terminal the transient lines are
//    dropped, so logs stay short.
//  * Quiet (--quiet): nothing but errors (on stderr).
//  * Json (--json): one JSON object per line on stdout (NDJSON), for programs:
//    {"event":"log","message":...}, {"event":"progress","task":...,"done":k,"total":n},
//    the library's progress events (log lines with "stage" and "kind", and
//    {"event":"sweep",...}, {"event":"untangling_stage",...}),
//    and the command's own events ({"event":"iteration",...}, {"event":"step",...},
//    {"event":"result",...}). Errors still go to stderr as one line, with the exit code.
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

namespace tspline {
struct ProgressEvent;
}

namespace tspline_app {

enum class OutputMode { Human, Quiet, Json };

/// --quiet and --json together: --json wins (it is already free of human text).
OutputMode output_mode(bool quiet, bool json);

class Progress {
 public:
  explicit Progress(OutputMode mode);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  OutputMode mode() const { return mode_; }
  bool human() const { return mode_ == OutputMode::Human; }

  /// A log line (stays).
  /// log(), report() and progress() throw toolkit::Interrupted after a SIGINT (interrupt.h).
  void log(const std::string& line);
  /// A library progress event: steps and notes are log lines; sweeps and
  /// untangling stages are transient in human mode, and in Json mode
  /// {"event":"log","kind":"step"|"note","stage":...,"message":...} and
  /// {"event":"sweep"|"untangling_stage","stage":...,...}
  /// (sweeps: the first three and every 50th, like the human log off a terminal).
  /// Defined in progress_report.cpp (the tspline program only).
  void report(const tspline::ProgressEvent& e);
  /// A progress bar "task [#####.....] done/total" (transient in human mode).
  void progress(const std::string& task, long done, long total);
  /// A structured event: printed in Json mode only (its "event" key names it).
  void event(const nlohmann::json& e);
  /// Ends a transient line, if one is showing (before other output).
  void settle();

 private:
  void transient(const std::string& text);
  OutputMode mode_;
  bool tty_;
  bool transient_showing_ = false;
};

}  // namespace tspline_app

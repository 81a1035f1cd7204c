#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "interrupt.h"

namespace tspline_app {

OutputMode output_mode(bool quiet, bool json) {
  if (json) return OutputMode::Json;
  return quiet ? OutputMode::Quiet : OutputMode::Human;
}

Progress::Progress(OutputMode mode) : mode_(mode), tty_(::isatty(STDOUT_FILENO) == 1) {}

Progress::~Progress() { settle(); }

void Progress::settle() {
  if (!transient_showing_) return;
  std::cout << "\r\033[K" << std::flush;  // carriage return, clear to the end of the line
  transient_showing_ = false;
}

void Progress::transient(const std::string& text) {
  if (!tty_) return;
  std::cout << "\r\033[K" << text << std::flush;
  transient_showing_ = true;
}

void Progress::log(const std::string& line) {
  throw_if_interrupted();  // each report is a point where Ctrl-C stops the run (interrupt.h)
  switch (mode_) {
    case OutputMode::Quiet: return;
    case OutputMode::Json: std::cout << nlohmann::json{{"event", "log"}, {"message", line}}.dump() << std::endl; return;
    case OutputMode::Human:
      settle();
      std::cout << line << std::endl;
      return;
  }
}

void Progress::progress(const std::string& task, long done, long total) {
  throw_if_interrupted();
  switch (mode_) {
    case OutputMode::Quiet: return;
    case OutputMode::Json:
      std::cout << nlohmann::json{{"event", "progress"}, {"task", task}, {"done", done}, {"total", total}}.dump()
                << std::endl;
      return;
    case OutputMode::Human: {
      const int width = 30;
      const int filled = total > 0 ? static_cast<int>(std::clamp(done * width / total, 0L, long{width})) : 0;
      char counts[64];
      std::snprintf(counts, sizeof counts, "] %ld/%ld", done, total);
      transient(task + " [" + std::string(filled, '#') + std::string(width - filled, '.') + counts);
      return;
    }
  }
}

void Progress::event(const nlohmann::json& e) {
  if (mode_ == OutputMode::Json) std::cout << e.dump() << std::endl;
}

}  // namespace tspline_app

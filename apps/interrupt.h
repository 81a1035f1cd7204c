#pragma once
// Ctrl-C for the long-running commands: the first SIGINT (or SIGTERM) only sets
// a flag, and the run stops at its next progress report (a log line or a
// progress bar, see progress.cpp) by throwing toolkit::Interrupted, which
// unwinds normally: outputs are only ever written through temporary files and
// renamed when complete (toolkit/io/atomic_file.h), so no half-written file is
// left, and the program exits 130. A second signal ends the process at once
// (the default action), for a stage that reports no progress for long.

namespace tspline_app {

/// Installs the handlers (once per process).
void install_interrupt_handlers();

/// Whether a SIGINT or SIGTERM has arrived since install_interrupt_handlers().
bool interrupt_requested();

/// \throw toolkit::Interrupted naming the signal if one has arrived.
void throw_if_interrupted();

}  // namespace tspline_app

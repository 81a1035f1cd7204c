#include "interrupt.h"

#include <csignal>
#include <string>

#include "toolkit/errors.h"

namespace tspline_app {
namespace {

// The signal number, 0 if none: written only by the handler (lock-free, so
// async-signal-safe).
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_signal(int sig) { g_signal = sig; }

}  // namespace

void install_interrupt_handlers() {
  struct sigaction sa = {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  // SA_RESETHAND: the handler runs once; a second signal takes the default
  // action (the process ends). SA_RESTART: a read or write in progress goes on
  // (the first signal only sets the flag).
  sa.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interrupt_requested() { return g_signal != 0; }

void throw_if_interrupted() {
  const int sig = g_signal;
  if (sig == 0) return;
  const std::string name = sig == SIGINT ? "SIGINT (Ctrl-C)" : sig == SIGTERM ? "SIGTERM" : "a signal";
  throw toolkit::Interrupted("stopped by " + name +
                             "; no output is half-written (outputs are renamed into place only when complete)");
}

}  // namespace tspline_app

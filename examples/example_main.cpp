// The main() of every example (examples/CMakeLists.txt compiles this file into
// each): it calls the example's run() and turns a library error into one line
// on stderr and an exit code, as the tspline program does.
//
// Library errors are exceptions with a message that names the problem, one
// vocabulary for all libraries (toolkit/errors.h; libmeshopt throws the same):
// InputError (bad input or options, exit 1), IoError (a file could not be read
// or written, exit 2), NumericalError (e.g. a singular system, exit 3);
// anything else is a bug in the library (InternalError, exit 4).
#include <cstdio>
#include <exception>

#include "toolkit/errors.h"

int run(int argc, char** argv);  // the example

namespace {

/// The exit code for a library error: 1 to 3 for the errors a caller can act
/// on, 4 for anything else (a bug).
int exit_code_for(const std::exception& e) {
  if (dynamic_cast<const toolkit::InputError*>(&e)) return 1;
  if (dynamic_cast<const toolkit::IoError*>(&e)) return 2;
  if (dynamic_cast<const toolkit::NumericalError*>(&e)) return 3;
  return 4;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    const int code = exit_code_for(e);
    std::fprintf(stderr, "%s: %s\n", code == 4 ? "internal error" : "error", e.what());
    return code;
  }
}

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

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const toolkit::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  } catch (const toolkit::IoError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const toolkit::NumericalError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return 4;
  }
}

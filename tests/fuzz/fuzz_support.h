#pragma once
// What every fuzz target accepts: the toolkit's own errors (a clear message for
// bad input). Anything else escaping the library is reported as a crash.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "toolkit/errors.h"

namespace fuzz {

[[noreturn]] inline void fail(const char* what) {
  std::fprintf(stderr, "fuzz target: %s\n", what);
  std::abort();
}

template <class F>
void expect_toolkit_errors_only(F&& f) {
  try {
    f();
  } catch (const toolkit::InputError&) {
  } catch (const toolkit::IoError&) {
  } catch (const toolkit::NumericalError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz target: unexpected exception: %s\n", e.what());
    std::abort();
  }
}

}  // namespace fuzz

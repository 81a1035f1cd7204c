#pragma once
// Typed exceptions of libtspline. User-facing preconditions throw these; the
// message is one line that names the problem (the apps print it verbatim).
#include <stdexcept>
#include <string>

namespace tspline {

/// Invalid user input: a malformed or invalid polygon, bad corner indices, bad options.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A file could not be read or written.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A numerical procedure failed in a way the caller must know about.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tspline

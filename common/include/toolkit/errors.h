#pragma once
// The exception types of all libraries of the toolkit (libmeshopt, libtspline
// and their I/O): one vocabulary, so that a program maps any error to an exit
// code in one place (apps/exit_codes.h). Each message is one line that names
// the problem; the programs print it verbatim.
//
// As in pmp-library (pmp/exceptions.h), bad input derives from
// std::invalid_argument: code that only knows the standard hierarchy still
// catches it as what it is. The other errors are std::runtime_errors.
#include <stdexcept>
#include <string>

namespace toolkit {

/// Invalid input from the caller or user: a malformed file, an invalid
/// polygon or mesh, options out of range. Exit code 1 in the programs.
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A file could not be read or written. Exit code 2.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A numerical procedure failed in a way the caller must know about (e.g. a
/// singular system). Exit code 3.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A broken invariant: a bug in the toolkit, never the caller's data (a
/// T-mesh that lost its 2:1 balance, blending functions that vanish inside
/// the domain). Exit code 4 in the programs ("internal error"). Data and
/// option errors are InputError, whatever function finds them.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// The run was stopped on request (SIGINT / SIGTERM) before it finished; no
/// output was written. Exit code 130 in the programs (128 + SIGINT), the shell's
/// convention for a run ended by Ctrl-C.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace toolkit

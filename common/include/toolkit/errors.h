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

/// The shape of every toolkit exception: a standard exception `Base` with its
/// constructors (one message). `Tag` makes each use its own type, so that a
/// catch clause tells them apart.
template <class Base, class Tag>
class Error : public Base {
 public:
  using Base::Base;
};

/// Invalid input from the caller or user: a malformed file, an invalid
/// polygon or mesh, options out of range. Exit code 1 in the programs.
using InputError = Error<std::invalid_argument, struct InputErrorTag>;

/// A file could not be read or written. Exit code 2.
using IoError = Error<std::runtime_error, struct IoErrorTag>;

/// A numerical procedure failed in a way the caller must know about (e.g. a
/// singular system). Exit code 3.
using NumericalError = Error<std::runtime_error, struct NumericalErrorTag>;

/// A broken invariant: a bug in the toolkit, never the caller's data (a
/// T-mesh that lost its 2:1 balance, blending functions that vanish inside
/// the domain). Exit code 4 in the programs ("internal error"). Data and
/// option errors are InputError, whatever function finds them.
using InternalError = Error<std::logic_error, struct InternalErrorTag>;

/// The run was stopped on request (SIGINT / SIGTERM) before it finished; no
/// output was written. Exit code 130 in the programs (128 + SIGINT), the shell's
/// convention for a run ended by Ctrl-C.
using Interrupted = Error<std::runtime_error, struct InterruptedTag>;

}  // namespace toolkit

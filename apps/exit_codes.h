#pragma once
// The exit codes of both programs (tspline, meshopt) and the one place that
// maps an exception to its code and its one-line message:
//   0  success
//   1  invalid input (file content, options; toolkit::InputError)
//   2  a file could not be read or written (toolkit::IoError)
//   3  the run finished but its result is not valid (the program's own check),
//      or a numerical step failed (toolkit::NumericalError)
//   4  unexpected internal error (any other exception: a bug)
//   130 interrupted by SIGINT or SIGTERM (toolkit::Interrupted; 128 + SIGINT)
#include <exception>
#include <functional>
#include <string>

namespace tspline_app {

enum ExitCode : int {
  kExitOk = 0,
  kExitInput = 1,
  kExitIo = 2,
  kExitInvalidResult = 3,
  kExitInternal = 4,
  kExitInterrupted = 130,
};

/// The exit code for an exception, and in `message` (if given) the line to
/// print: "error: WHAT", "internal error: WHAT" or "interrupted: WHAT".
/// Also handles exceptions that are not std::exceptions (Gmsh 4.8 throws
/// std::string). \pre e is not null.
int exit_code_for(const std::exception_ptr& e, std::string* message = nullptr);

/// For a `catch (...)` block: prints "PROGRAM: " and the message of the
/// exception being handled on stderr (one line) and returns its exit code.
/// `spell`, if given, rewrites the message first (the libraries name options by
/// their fields in backquotes; the program says its flags: with_option_names).
int report_current_exception(const std::string& program,
                             const std::function<std::string(std::string)>& spell = {});

}  // namespace tspline_app

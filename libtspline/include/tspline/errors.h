#pragma once
// The exception types of libtspline are the toolkit's own (toolkit/errors.h,
// shared with libmeshopt): the names below are the same classes, so that
// `catch (const tspline::InputError&)` also catches libmeshopt's input errors.
#include "toolkit/errors.h"

namespace tspline {

using toolkit::InputError;      ///< invalid user input (a std::invalid_argument)
using toolkit::InternalError;   ///< a broken invariant, a bug (a std::logic_error)
using toolkit::Interrupted;     ///< the run was stopped on request (SIGINT)
using toolkit::IoError;         ///< a file could not be read or written
using toolkit::NumericalError;  ///< a numerical procedure failed

}  // namespace tspline

// The module's exceptions, one hierarchy mirroring the C++ ones (toolkit/errors.h):
//   tspline.Error (Exception)      any error the library reports
//   tspline.InputError (Error, ValueError)        toolkit::InputError: invalid input or options
//   tspline.IoError (Error, OSError)              toolkit::IoError: a file could not be read or written
//   tspline.NumericalError (Error, ArithmeticError) toolkit::NumericalError: a numerical step failed
//   tspline.InternalError (Error, RuntimeError)   toolkit::InternalError: a broken invariant (a bug)
// with the messages of the command line. Ctrl-C during a run raises
// KeyboardInterrupt, as anywhere in Python.
#include "toolkit/errors.h"

#include <Python.h>

#include "bindings.h"
#include "param_options.h"

namespace tspline_python {
namespace {

/// A new exception class tspline.NAME with these bases, added to the module.
/// The reference returned is kept for the life of the process (never released:
/// the translator below may run until the interpreter ends).
PyObject* new_exception(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = std::string("tspline.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (!type) throw py::error_already_set();
  m.attr(name) = py::reinterpret_borrow<py::object>(type);
  return type;
}

}  // namespace

void bind_errors(py::module_& m) {
  static PyObject *error, *input_error, *io_error, *numerical_error, *internal_error;
  error = new_exception(m, "Error", py::make_tuple(py::handle(PyExc_Exception)),
                        "Any error that the tspline library reports.");
  input_error =
      new_exception(m, "InputError", py::make_tuple(py::handle(error), py::handle(PyExc_ValueError)),
                    "Invalid input or options (a domain that is not a simple polygon, an option out of "
                    "range, a malformed file); the command line's exit code 1.");
  io_error = new_exception(m, "IoError", py::make_tuple(py::handle(error), py::handle(PyExc_OSError)),
                           "A file could not be read or written; the command line's exit code 2.");
  numerical_error =
      new_exception(m, "NumericalError", py::make_tuple(py::handle(error), py::handle(PyExc_ArithmeticError)),
                    "A numerical step failed (e.g. a singular system); the command line's exit code 3.");
  internal_error =
      new_exception(m, "InternalError", py::make_tuple(py::handle(error), py::handle(PyExc_RuntimeError)),
                    "A broken invariant inside the library (a bug: please report it); the command line's "
                    "exit code 4.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const toolkit::InputError& e) {
      // The library names options by field (`initial_level`); Python by keyword.
      PyErr_SetString(input_error,
                      tspline_app::with_option_names(e.what(), tspline_app::Spelling::Python).c_str());
    } catch (const toolkit::IoError& e) {
      PyErr_SetString(io_error, e.what());
    } catch (const toolkit::NumericalError& e) {
      PyErr_SetString(numerical_error, e.what());
    } catch (const toolkit::InternalError& e) {
      PyErr_SetString(internal_error, e.what());
    } catch (const toolkit::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });
}

}  // namespace tspline_python

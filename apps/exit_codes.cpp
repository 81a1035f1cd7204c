#include "exit_codes.h"

#include <iostream>
#include <string>

#include "toolkit/errors.h"

namespace tspline_app {

int exit_code_for(const std::exception_ptr& e, std::string* message) {
  std::string line;
  int code = kExitInternal;
  try {
    std::rethrow_exception(e);
  } catch (const toolkit::InputError& x) {
    code = kExitInput, line = std::string("error: ") + x.what();
  } catch (const toolkit::IoError& x) {
    code = kExitIo, line = std::string("error: ") + x.what();
  } catch (const toolkit::NumericalError& x) {
    code = kExitInvalidResult, line = std::string("error: ") + x.what();
  } catch (const toolkit::Interrupted& x) {
    code = kExitInterrupted, line = std::string("interrupted: ") + x.what();
  } catch (const std::exception& x) {
    line = std::string("internal error: ") + x.what();
  } catch (const std::string& x) {  // Gmsh 4.8 throws strings
    line = "internal error: " + x;
  } catch (...) {
    line = "internal error: an exception of unknown type";
  }
  // One line: a message that spans lines (a library's multi-line text) is joined.
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  if (message) *message = line;
  return code;
}

int report_current_exception(const std::string& program, const std::function<std::string(std::string)>& spell) {
  std::string line;
  const int code = exit_code_for(std::current_exception(), &line);
  if (spell) line = spell(std::move(line));
  std::cerr << program << ": " << line << std::endl;
  return code;
}

}  // namespace tspline_app

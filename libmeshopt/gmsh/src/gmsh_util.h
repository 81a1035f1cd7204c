#pragma once
// Helpers of the Gmsh adapter (internal): message building and the message of
// the exception Gmsh threw.
#include <sstream>
#include <string>

namespace meshopt::gmsh_io {

/// Concatenates with operator<< (avoids GCC 12's false -Wrestrict on "literal" + std::string).
template <class... T>
std::string cat(const T&... parts) {
  std::ostringstream s;
  (s << ... << parts);
  return s.str();
}

/// The message of the exception being handled: Gmsh 4.8 throws std::string
/// (and sometimes int) besides std::exception.
inline std::string gmsh_error() {
  try {
    throw;
  } catch (const std::exception& e) {
    return e.what();
  } catch (const std::string& s) {
    return s;
  } catch (const char* s) {
    return s;
  } catch (int code) {
    return cat("Gmsh error code ", code);
  } catch (...) {
    return "unknown Gmsh error";
  }
}

}  // namespace meshopt::gmsh_io

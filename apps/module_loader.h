#pragma once
// The tspline program's optional parts (GDAL's GIS reader, Gmsh's quad mesher)
// as modules loaded at their first use (gis_module.cpp, gmsh_module.cpp): a
// run that needs neither does not load them and their hundred libraries each.
#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "tspline/errors.h"

namespace tspline_app {

struct ModuleSpec {
  const char* file;         ///< "libtspline_gis.so"
  const char* env;          ///< the variable that may give its path: "TSPLINE_GIS_MODULE"
  const char* entry;        ///< its extern "C" function returning the table: "tspline_gis_backend"
  const char* needed_by;    ///< what needs it, for messages: "GIS input"
  const char* kind;         ///< what it is, for messages: "GDAL module"
  const char* from_bindir;  ///< its installed folder relative to the program's
};

/// The module's table of functions, from the first of: the path in spec.env,
/// the program's folder, the installed folder. Kept loaded to the end.
/// \throw tspline::IoError naming the module, the places tried and spec.env.
template <class Table>
const Table* load_module(const ModuleSpec& spec) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* p = std::getenv(spec.env); p && *p) candidates.emplace_back(p);
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(program.parent_path() / spec.file);
    candidates.push_back(program.parent_path() / spec.from_bindir / spec.file);
  }
  std::string tried;
  for (const fs::path& c : candidates) {
    tried += (tried.empty() ? "" : ", ") + c.string();
    if (!fs::exists(c, ec)) continue;
    void* handle = ::dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      throw tspline::IoError(std::string(spec.needed_by) + " needs the " + spec.kind + " " + c.string() +
                             ", which cannot be loaded: " + (why ? why : "unknown error"));
    }
    using Entry = const Table* (*)();
    const auto entry = reinterpret_cast<Entry>(::dlsym(handle, spec.entry));
    if (!entry)
      throw tspline::IoError(std::string(spec.needed_by) + ": " + c.string() + " is not tspline's " +
                             spec.kind + " (no " + spec.entry + ")");
    return entry();
  }
  throw tspline::IoError(std::string(spec.needed_by) + " needs the " + spec.kind + " " + spec.file +
                         ", found in none of: " + tried + " (set " + spec.env + " to its path)");
}

}  // namespace tspline_app

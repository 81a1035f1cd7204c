#include "program_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "tspline/errors.h"

#ifndef TSPLINE_MODULES_FROM_BINDIR
#define TSPLINE_MODULES_FROM_BINDIR "../lib/tspline"
#endif

namespace tspline_app {

void* load_program_module(const ProgramModule& m) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* p = std::getenv(m.variable); p && *p) candidates.emplace_back(p);
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(program.parent_path() / m.file);
    candidates.push_back(program.parent_path() / TSPLINE_MODULES_FROM_BINDIR / m.file);
  }
  const std::string what = std::string(m.needed_for) + " needs the " + m.library + " module ";
  std::string tried;
  for (const fs::path& c : candidates) {
    tried += (tried.empty() ? "" : ", ") + c.string();
    if (!fs::exists(c, ec)) continue;
    void* handle = ::dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      throw tspline::IoError(what + c.string() +
                             ", which cannot be loaded: " + (why ? why : "unknown error"));
    }
    if (void* entry = ::dlsym(handle, m.entry)) return entry;
    throw tspline::IoError(std::string(m.needed_for) + ": " + c.string() + " is not tspline's " + m.library +
                           " module (no " + m.entry + ")");
  }
  throw tspline::IoError(what + m.file + ", found in none of: " + tried + " (set " + m.variable +
                         " to its path)");
}

}  // namespace tspline_app

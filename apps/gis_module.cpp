// The tspline program's GIS reader: GDAL's (libtspline's io/src/gis_gdal.cpp),
// built as the module libtspline_gis.so and loaded at the first GIS input.
// Linked before libtspline_io, this gis_backend() takes the place of the one
// linked into the libraries, so the program does not load GDAL and the hundred
// libraries it needs at every start (0.09 s of each run, most of them on text
// polygons). The module is looked for in TSPLINE_GIS_MODULE (a path), next to
// the program (the build tree), and where `cmake --install` puts it.
#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "tspline/detail/gis_backend.h"
#include "tspline/errors.h"

#ifndef TSPLINE_GIS_MODULE_FROM_BINDIR
#define TSPLINE_GIS_MODULE_FROM_BINDIR "../lib/tspline"
#endif

namespace tspline::io::detail {
namespace {

namespace fs = std::filesystem;

constexpr const char* kModule = "libtspline_gis.so";

const GisBackend* load() {
  std::vector<fs::path> candidates;
  if (const char* p = std::getenv("TSPLINE_GIS_MODULE"); p && *p) candidates.emplace_back(p);
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(program.parent_path() / kModule);
    candidates.push_back(program.parent_path() / TSPLINE_GIS_MODULE_FROM_BINDIR / kModule);
  }
  std::string tried;
  for (const fs::path& c : candidates) {
    tried += (tried.empty() ? "" : ", ") + c.string();
    if (!fs::exists(c, ec)) continue;
    void* handle = ::dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      throw IoError("GIS input needs the GDAL module " + c.string() +
                    ", which cannot be loaded: " + (why ? why : "unknown error"));
    }
    // (Kept loaded to the end: GDAL keeps its drivers registered.)
    using Entry = const GisBackend* (*)();
    const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "tspline_gis_backend"));
    if (!entry)
      throw IoError("GIS input: " + c.string() + " is not tspline's GDAL module (no tspline_gis_backend)");
    return entry();
  }
  throw IoError(std::string("GIS input needs the GDAL module ") + kModule + ", found in none of: " + tried +
                " (set TSPLINE_GIS_MODULE to its path)");
}

}  // namespace

const GisBackend& gis_backend() {
  // Loaded once (thread-safe); a failure is thrown again at every call.
  static const GisBackend* const backend = load();
  return *backend;
}

}  // namespace tspline::io::detail

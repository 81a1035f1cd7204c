// The tspline program's GIS reader: GDAL's (libtspline's io/src/gis_gdal.cpp),
// built as the module libtspline_gis.so and loaded at the first GIS input.
// Linked before libtspline_io, this gis_backend() takes the place of the one
// linked into the libraries, so the program does not load GDAL and the hundred
// libraries it needs at every start (0.09 s of each run, most of them on text
// polygons). The module is looked for in TSPLINE_GIS_MODULE (a path), next to
// the program (the build tree), and where `cmake --install` puts it
// (module_loader.h).
#include "module_loader.h"
#include "tspline/detail/gis_backend.h"

#ifndef TSPLINE_MODULE_FROM_BINDIR
#define TSPLINE_MODULE_FROM_BINDIR "../lib/tspline"
#endif

namespace tspline::io::detail {

const GisBackend& gis_backend() {
  // Loaded once (thread-safe); a failure is thrown again at every call.
  // (Kept loaded to the end: GDAL keeps its drivers registered.)
  static const GisBackend* const backend =
      tspline_app::load_module<GisBackend>({"libtspline_gis.so", "TSPLINE_GIS_MODULE", "tspline_gis_backend",
                                            "GIS input", "GDAL module", TSPLINE_MODULE_FROM_BINDIR});
  return *backend;
}

}  // namespace tspline::io::detail

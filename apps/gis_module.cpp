// The tspline program's GIS reader: GDAL's (libtspline's io/src/gis_gdal.cpp),
// built as the module libtspline_gis.so and loaded at the first GIS input
// (program_module.h). Linked before libtspline_io, this gis_backend() takes
// the place of the one linked into the libraries, so the program does not
// load GDAL and the hundred libraries it needs at every start (0.09 s of each
// run, most of them on text polygons).
#include "program_module.h"
#include "tspline/detail/gis_backend.h"

namespace tspline::io::detail {

const GisBackend& gis_backend() {
  // Loaded once (thread-safe); a failure is thrown again at every call.
  static const GisBackend* const backend = [] {
    using Entry = const GisBackend* (*)();
    return reinterpret_cast<Entry>(tspline_app::load_program_module(
        {"libtspline_gis.so", "TSPLINE_GIS_MODULE", "tspline_gis_backend", "GIS input", "GDAL"}))();
  }();
  return *backend;
}

}  // namespace tspline::io::detail

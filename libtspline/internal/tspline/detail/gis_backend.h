#pragma once
// Internal to libtspline's I/O and the tspline program, not part of the public
// interface. The GIS part of read_domain and read_geojson_domain (gis_reader.h),
// GDAL's, as a table of functions: in the libraries it is linked in
// (io/src/gis_gdal.cpp defines gis_backend()); the tspline program defines
// gis_backend() itself and loads gis_gdal.cpp, built as the module
// libtspline_gis.so, at its first GIS input (apps/gis_module.cpp), so that a
// run on a text polygon does not load GDAL and its hundred libraries.
#include <string>

#include "tspline/io/gis_reader.h"

namespace tspline::io::detail {

struct GisBackend {
  /// A GIS file or directory (is_gis_file), which exists.
  DomainInput (*read_file)(const std::string& path, const DomainReadOptions& options);
  /// GeoJSON text; `name` names it in messages.
  DomainInput (*read_geojson)(const std::string& geojson, const DomainReadOptions& options,
                              const std::string& name);
};

/// The GIS reader. \throw IoError where the program's module cannot be loaded.
const GisBackend& gis_backend();

}  // namespace tspline::io::detail

/// The module's entry: its GIS reader (gis_gdal.cpp).
extern "C" const tspline::io::detail::GisBackend* tspline_gis_backend();

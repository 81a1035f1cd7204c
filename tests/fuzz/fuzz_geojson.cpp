// libFuzzer target: GeoJSON text through GDAL in memory (read_geojson_domain,
// what the Python module uses for GeoJSON strings and dicts): Polygon,
// MultiPolygon, Feature, FeatureCollection, GeometryCollection; holes; the
// largest-area choice and a polygon index; longitude/latitude projected by
// PROJ, or kept with planar. Inputs that do not start with '{' are read as
// GeoJSON all the same. (GeoJSON files go through the same reader: fuzz_gis.)
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "tspline/io/gis_reader.h"

// GDAL's own allocations on malformed input are GDAL's (see fuzz_gis.cpp).
extern "C" const char* __lsan_default_suppressions() { return "leak:libgdal.so\nleak:libexpat.so\n"; }

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos || text[text.find_first_not_of(" \t\r\n")] != '{')
    text.insert(0, "{");
  fuzz::expect_toolkit_errors_only([&] { tspline::io::read_geojson_domain(text, {}, "fuzz.geojson"); });
  fuzz::expect_toolkit_errors_only([&] {
    tspline::io::DomainReadOptions second;
    second.planar = true;
    second.polygon_index = 1;
    tspline::io::read_geojson_domain(text, second, "fuzz.geojson");
  });
  return 0;
}

// libFuzzer target: the GeoJSON polygon reader (Polygon, MultiPolygon, Feature,
// FeatureCollection, GeometryCollection; --polygon index and the largest-area
// choice). Inputs that do not start with '{' are read as GeoJSON all the same.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "tspline/io/polygon_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos || text[text.find_first_not_of(" \t\r\n")] != '{')
    text.insert(0, "{");
  fuzz::expect_toolkit_errors_only([&] {
    std::string warnings;
    tspline::io::parse_polygon(text, "fuzz.geojson", {}, &warnings);
    tspline::io::PolygonReadOptions second;
    second.polygon_index = 1;
    tspline::io::parse_polygon(text, "fuzz.geojson", second, &warnings);
  });
  return 0;
}

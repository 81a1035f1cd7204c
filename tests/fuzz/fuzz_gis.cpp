// libFuzzer target: the GIS reader (read_domain through GDAL/OGR, with the
// projection of longitude/latitude by PROJ and the choice of layer, feature
// and polygon). The first byte of the input picks the file's format by its
// extension (GeoJSON, KML, GML, CSV with WKT); the rest is the file's content,
// written to a temporary file that GDAL opens as a user's file.
#include <unistd.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "fuzz_support.h"
#include "tspline/io/gis_reader.h"

// GDAL's drivers keep or lose some memory of their own on malformed files
// (seen: the JML driver's expat parser on a truncated <JCSDataFile>); those
// leaks are GDAL's, not ours: LeakSanitizer ignores allocations made inside
// libgdal and libexpat, and still reports any made by our reader.
extern "C" const char* __lsan_default_suppressions() { return "leak:libgdal.so\nleak:libexpat.so\n"; }

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const std::array<const char*, 4> kExtensions = {".geojson", ".kml", ".gml", ".csv"};
  const std::string path = "/tmp/tspline_fuzz_gis_" + std::to_string(::getpid()) + kExtensions[data[0] % 4];
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  fuzz::expect_toolkit_errors_only([&] { tspline::io::read_domain(path); });
  fuzz::expect_toolkit_errors_only([&] {
    tspline::io::DomainReadOptions o;
    o.planar = true;
    o.layer = "1";
    o.polygon_index = 1;
    tspline::io::read_domain(path, o);
  });
  std::remove(path.c_str());
  return 0;
}

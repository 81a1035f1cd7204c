// Domain input: text polygons here; GIS files and GeoJSON through GDAL
// (gis_gdal.cpp, reached through tspline/detail/gis_backend.h).
#include "tspline/io/gis_reader.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "tspline/detail/gis_backend.h"
#include "tspline/errors.h"
#include "tspline/io/polygon_reader.h"

namespace tspline::io {
namespace {

namespace fs = std::filesystem;

std::string lower_extension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

}  // namespace

bool is_gis_file(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return true;
  static const char* const kExtensions[] = {".shp", ".gpkg", ".kml", ".gml", ".geojson", ".json",
                                            ".fgb", ".sqlite", ".gdb", ".tab", ".mif"};
  const std::string ext = lower_extension(path);
  for (const char* e : kExtensions)
    if (ext == e) return true;
  std::ifstream f(path, std::ios::binary);
  char buf[512];
  f.read(buf, sizeof buf);
  const std::size_t n = static_cast<std::size_t>(f.gcount());
  std::size_t i = 0;
  if (n >= 3 && std::memcmp(buf, "\xEF\xBB\xBF", 3) == 0) i = 3;  // UTF-8 BOM
  if (std::memchr(buf, '\0', n)) return true;                       // binary
  while (i < n && std::isspace(static_cast<unsigned char>(buf[i]))) ++i;
  return i < n && (buf[i] == '{' || buf[i] == '<');
}

DomainInput read_domain(const std::string& path, const DomainReadOptions& options) {
  DomainInput out;
  if (!is_gis_file(path)) {
    if (options.layer || options.feature)
      throw InputError(path + ": `layer` and `feature` apply to GIS files, not to a text polygon");
    if (options.crs) throw InputError(path + ": a CRS applies to GIS data, not to a text polygon (planar)");
    // Rings separated by blank lines: the first is the outer boundary, the others are holes.
    std::vector<Polygon> rings = read_text_rings(path);
    out.outer = std::move(rings.front());
    out.holes.assign(std::make_move_iterator(rings.begin() + 1), std::make_move_iterator(rings.end()));
    out.description = {{"format", "text"}, {"crs", nullptr}, {"projection", nullptr}, {"units", "as in the file"},
                       {"holes", out.holes.size()}};
    return out;
  }
  {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw IoError("cannot read " + path + ": no such file");
  }
  return detail::gis_backend().read_file(path, options);
}

DomainInput read_geojson_domain(const std::string& geojson, const DomainReadOptions& options,
                                const std::string& name) {
  return detail::gis_backend().read_geojson(geojson, options, name);
}

}  // namespace tspline::io

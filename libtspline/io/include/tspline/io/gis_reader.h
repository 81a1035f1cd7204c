#pragma once
// Domains from GIS files through GDAL/OGR (libgdal): any polygon layer GDAL
// reads (Shapefile, GeoPackage, KML, GML, GeoJSON, ...), with its holes, in
// metres. Geographic coordinates (a layer with a geographic CRS; GeoJSON, which
// RFC 7946 defines as WGS 84 longitude/latitude) are projected with PROJ to
// the Lambert azimuthal equal-area projection centred on the chosen polygon's
// centroid, so that lengths near the domain and all areas are true; a
// projected CRS is kept as it is, and so is everything with `planar`. Text
// polygons ("x y" lines, polygon_reader.h) are planar.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"

namespace tspline::io {

struct DomainReadOptions {
  std::optional<std::string> layer;           ///< layer name, or 0-based index; default: the first with polygons
  std::optional<std::size_t> feature;         ///< 0-based feature index in the layer; default: all features
  std::optional<std::size_t> polygon_index;   ///< which polygon of those (0-based, file order); default: the largest
  bool planar = false;                        ///< keep the coordinates as they are (no projection)
  /// The coordinates' CRS instead of the layer's (anything GDAL's
  /// OGRSpatialReference::SetFromUserInput reads: "EPSG:4326", "OGC:CRS84",
  /// WKT, a PROJ string); geographic ones are projected as above. Unset: the
  /// layer's own.
  std::optional<std::string> crs;
};

/// A domain as read: the outer boundary and its holes (each a Polygon in the
/// file's order and numbering, not validated), and a description of the input
/// for report.json.
struct DomainInput {
  Polygon outer;
  std::vector<Polygon> holes;  ///< kept for multi-patch domains; the parameterization uses `outer` only
  /// {"format", "layer", "feature", "polygon", "crs", "projection": {...} or null, "units", "holes"}.
  nlohmann::json description;
};

/// True if the file is read through GDAL: a directory, a known GIS extension
/// (.shp .gpkg .kml .gml .geojson .json .fgb .sqlite .gdb .tab .mif), or content
/// that is not a text polygon (binary, XML, or JSON starting with '{').
bool is_gis_file(const std::string& path);

/// Reads a domain: GIS files through GDAL (see is_gis_file), text polygons
/// through read_polygon() (planar; `layer`/`feature` are input errors there).
/// \throw IoError if the file cannot be opened; InputError for no polygon
/// layer, a bad layer/feature/polygon choice, an unknown CRS for geographic
/// data, or coordinates that are not longitude/latitude where they must be.
DomainInput read_domain(const std::string& path, const DomainReadOptions& options = {});

/// Reads a domain from GeoJSON text in memory (a geometry, Feature or
/// FeatureCollection) as read_domain reads a .geojson file: through GDAL,
/// longitude/latitude (RFC 7946) projected to metres unless `planar` or
/// `crs` says otherwise. `name` stands for the input in messages and in the
/// description ("format": "GeoJSON").
/// \throw InputError as read_domain, and for text GDAL cannot read as GeoJSON.
DomainInput read_geojson_domain(const std::string& geojson, const DomainReadOptions& options = {},
                                const std::string& name = "GeoJSON");

}  // namespace tspline::io

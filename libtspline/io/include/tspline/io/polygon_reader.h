#pragma once
// Reading polygons from text files (GeoJSON and GIS files: gis_reader.h).
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"

namespace tspline::io {

/// Reads a text polygon: one "x y" vertex per line (whitespace or comma
/// separated), '#' starts a comment, blank lines ignored, an optional repeated
/// closing vertex dropped. Does NOT validate simplicity (see validate_polygon).
/// GeoJSON and GIS files go through GDAL (gis_reader.h: read_domain,
/// read_geojson_domain): content that starts with '{' is an InputError saying so.
/// \throw IoError if the file cannot be read; InputError for malformed content
/// (names the line number), an empty file, non-numeric or non-finite coordinates.
Polygon read_polygon(const std::string& path);

/// Same, from a string already in memory (`source_name` is used in messages).
Polygon parse_polygon(const std::string& content, const std::string& source_name);

/// Text with several rings: rings are separated by one or more blank lines
/// (lines holding only a comment do not separate), each ring as in a text
/// polygon; the first ring is the outer boundary, the others are holes. Every
/// ring keeps its own file numbering (0-based within the ring). Not validated
/// (see validate_domain). \throw InputError as parse_polygon (for an empty file).
std::vector<Polygon> parse_text_rings(const std::string& content, const std::string& source_name);

/// Same, from a file. \throw IoError if the file cannot be read.
std::vector<Polygon> read_text_rings(const std::string& path);

}  // namespace tspline::io

#pragma once
// Reading polygons from text files and GeoJSON.
#include <optional>
#include <string>
#include <vector>

#include "tspline/boundary/polygon.h"

namespace tspline::io {

/// Options for choosing a ring from GeoJSON input.
struct PolygonReadOptions {
  /// For a MultiPolygon (or a FeatureCollection with several polygons): which
  /// polygon to take, 0-based in file order. Default: the one with largest area.
  std::optional<std::size_t> polygon_index;
};

/// Reads a polygon. Format by content: GeoJSON if the first non-blank character
/// is '{', otherwise text: one "x y" vertex per line (whitespace or comma
/// separated), '#' starts a comment, blank lines ignored, an optional repeated
/// closing vertex dropped. GeoJSON: Polygon, MultiPolygon, Feature or
/// FeatureCollection; the outer ring is used (holes are ignored, with a note in
/// `warnings` if any). Does NOT validate simplicity (see validate_polygon).
/// \throw IoError if the file cannot be read; InputError for malformed content
/// (names the line number for text, the JSON path for GeoJSON), an empty file,
/// non-numeric or non-finite coordinates.
Polygon read_polygon(const std::string& path, const PolygonReadOptions& options = {},
                     std::string* warnings = nullptr);

/// Same, from a string already in memory (`source_name` is used in messages).
Polygon parse_polygon(const std::string& content, const std::string& source_name,
                      const PolygonReadOptions& options = {}, std::string* warnings = nullptr);

/// Text with several rings: rings are separated by one or more blank lines
/// (lines holding only a comment do not separate), each ring as in a text
/// polygon; the first ring is the outer boundary, the others are holes. Every
/// ring keeps its own file numbering (0-based within the ring). Not validated
/// (see validate_domain). \throw InputError as parse_polygon (for an empty file).
std::vector<Polygon> parse_text_rings(const std::string& content, const std::string& source_name);

/// Same, from a file. \throw IoError if the file cannot be read.
std::vector<Polygon> read_text_rings(const std::string& path);

}  // namespace tspline::io

#pragma once
// Reading polygons from text files and GeoJSON.
#include <optional>
#include <string>

#include "tspline/polygon.h"

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

}  // namespace tspline::io

#pragma once
// The T-spline file (tspline.json): a documented, versioned JSON format that
// another program can read (see docs/tspline_format.md).
#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "tspline/boundary/polygon.h"
#include "tspline/spline/tspline_map.h"

namespace tspline::io {

/// What the file records besides the map itself.
struct TSplineFileMeta {
  std::string source;                        ///< input file the map was built from (informative)
  Polygon boundary;                          ///< the domain polygon, CCW, with file_index
  std::array<std::size_t, 4> corners{};      ///< corner indices into `boundary` ((0,0),(1,0),(1,1),(0,1))
};

/// Writes the map atomically. Doubles are written so that they read back bit-identically.
/// \throw IoError.
void write_tspline_file(const std::string& path, const TSplineMap& map, const TSplineFileMeta& meta);

/// The text write_tspline_file writes (a version-1 document).
/// \throw InputError for inconsistent metadata.
std::string tspline_file_text(const TSplineMap& map, const TSplineFileMeta& meta);

struct LoadedTSpline {
  TSplineMap map;
  TSplineFileMeta meta;
};

/// Reads a T-spline file, rebuilds the T-mesh and basis, and checks that the
/// stored knot vectors are the ones the basis produces.
/// \throw IoError (unreadable), InputError (malformed, unsupported version,
/// inconsistent or non-finite data; the message names the JSON path).
LoadedTSpline read_tspline_file(const std::string& path);

/// The same from the file's content; `source_name` stands for the path in
/// messages. \throw InputError.
LoadedTSpline parse_tspline_file(const std::string& text, const std::string& source_name);

/// The whole content of a file. \throw IoError (a directory, unreadable).
std::string read_text_file(const std::string& path);

/// Same, from a parsed version-1 document (`name` prefixes the messages, e.g.
/// "FILE: /patches/2").
LoadedTSpline tspline_from_json(const nlohmann::json& doc, const std::string& name);

}  // namespace tspline::io

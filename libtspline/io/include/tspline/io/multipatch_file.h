#pragma once
// The multi-patch T-spline file: tspline.json format version 2
// (docs/tspline_format.md): the patches, each a complete version-1 document,
// and the interfaces between them. Single-patch maps keep version 1.
#include <optional>
#include <string>
#include <vector>

#include "tspline/io/tspline_file.h"
#include "tspline/multipatch/patch_layout.h"

namespace tspline::io {

/// The maps of a file of either version (version 1: one patch, no interfaces).
struct LoadedMaps {
  int version = 1;
  std::string source;
  std::vector<LoadedTSpline> patches;
  std::vector<Interface> interfaces;  ///< `cut` indexes `cuts`
  std::vector<Cut> cuts;
  /// Version 2: the rings the layout was built on (outer ring, then holes;
  /// counter-clockwise, with their file_index), if the file records them (a
  /// warm start of the moved domain needs them).
  std::optional<Domain> domain;
};

/// Writes a version-2 file atomically (with `domain`: its rings, as "domain"). \throw IoError; InputError for
/// inconsistent metadata (as write_tspline_file) or interfaces out of range.
void write_multipatch_file(const std::string& path, const std::vector<const TSplineMap*>& maps,
                           const std::vector<TSplineFileMeta>& metas, const std::vector<Interface>& interfaces,
                           const std::vector<Cut>& cuts, const std::string& source, const Domain* domain = nullptr);

/// Reads a version-1 or version-2 file.
/// \throw IoError, InputError (as read_tspline_file; names the JSON path, e.g. /patches/2/functions/7).
LoadedMaps read_maps_file(const std::string& path);

/// Side names in the file: "bottom", "right", "top", "left".
const char* side_name(int side);

}  // namespace tspline::io

#pragma once
// Reading back the .vtu files this toolkit writes (for `tspline render`).
#include <string>

#include "toolkit/io/vtu_writer.h"

namespace toolkit::io {

/// Reads a VTK XML unstructured grid: points (x, y), cells as point lists, and
/// every 1-component point/cell array as doubles (point_scalars /
/// cell_scalars, integer arrays included). \throw IoError naming the file.
VtuMesh read_vtu(const std::string& path);

}  // namespace toolkit::io

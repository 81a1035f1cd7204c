#pragma once
// A closed polygon as read from a file, before and after validation.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace tspline {

/// A closed polygon. `vertices` never repeats the first vertex at the end.
/// `file_index[i]` is the 0-based index that vertices[i] had in the input file's
/// own numbering (vertex lines in file order, the optional repeated closing vertex
/// not counted), so that user-given corner indices survive reorientation.
struct Polygon {
  std::vector<Eigen::Vector2d> vertices;
  std::vector<std::size_t> file_index;
};

}  // namespace tspline

#pragma once
// ParaView output: VTK XML unstructured grids (.vtu, binary appended, zlib) and
// .pvd collections. Library-neutral mesh description so callers need no VTK.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

namespace toolkit::io {

/// A polygonal/line/vertex mesh to be written as .vtu: 2D points (z = 0), or
/// 3D points if `points3d` is non-empty (then `points` must be empty).
struct VtuMesh {
  std::vector<Eigen::Vector2d> points;
  std::vector<Eigen::Vector3d> points3d;
  /// Each cell is a list of point indices. Cell type: VTK_POLYGON if >= 3
  /// indices (VTK_QUAD if exactly 4 and `quads_as_polygons` is false),
  /// VTK_LINE if 2, VTK_VERTEX if 1.
  std::vector<std::vector<int>> cells;
  bool quads_as_polygons = true;
  std::map<std::string, std::vector<double>> point_scalars;  ///< one value per point
  std::map<std::string, std::vector<double>> cell_scalars;   ///< one value per cell
  std::map<std::string, std::vector<int>> cell_ints;         ///< one value per cell (Int32)
  std::map<std::string, std::vector<int>> point_ints;        ///< one value per point (Int32)
  std::map<std::string, std::vector<Eigen::Vector2d>> point_vectors;  ///< 3-component, z = 0
};

/// Writes `mesh` to `path` atomically. \throw IoError; std::invalid_argument if
/// an array has the wrong length or a cell index is out of range.
void write_vtu(const std::string& path, const VtuMesh& mesh);

/// One dataset of a .pvd collection.
struct PvdEntry {
  double timestep = 0.0;
  std::string file;  ///< relative to the .pvd's directory
  int part = 0;
};

/// Writes a ParaView collection file atomically.
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

}  // namespace toolkit::io

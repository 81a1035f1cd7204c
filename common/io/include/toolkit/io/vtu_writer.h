#pragma once
// ParaView output: VTK XML unstructured grids (.vtu, binary appended, LZ4 or
// zlib) and .pvd collections. Library-neutral mesh description so callers need
// no VTK.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace toolkit::io {

/// How a .vtu file's arrays are compressed. VTK's XML readers read all three
/// (ParaView, VTK >= 8.1, PyVista; meshio with the lz4 package); the file
/// names its compressor. Measured on a coastline's 217 MB of surface.vtu
/// arrays in VTK's 32 KiB blocks (bench/README.md, "LZ4 files"): LZ4 0.15 s of
/// CPU to 127 MB, zlib (libdeflate, level 1) 0.73 s to 98 MB.
enum class VtuCompression {
  LZ4,   ///< vtkLZ4DataCompressor (LZ4's default speed): the fastest to write and to read
  Zlib,  ///< vtkZLibDataCompressor, level 1, the streams made by libdeflate: the smallest files
  None,  ///< the raw bytes
};
/// "lz4", "zlib" or "none".
std::string_view vtu_compression_name(VtuCompression c);
/// The compression named "lz4", "zlib" or "none". \throw InputError otherwise.
VtuCompression parse_vtu_compression(std::string_view name);

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
  std::map<std::string, std::vector<Eigen::Vector2d>> cell_vectors;   ///< 3-component, z = 0

  // Higher-order cells (VTK 9: Lagrange and Bezier cells, e.g. VTK_BEZIER_QUADRILATERAL = 77).
  /// VTK cell type of each cell; empty: inferred from the point counts as above.
  std::vector<int> cell_types;
  /// Name of a point scalar array that holds the rational weights of Bezier
  /// cells (marked as the point data's RationalWeights attribute); "" for none.
  std::string rational_weights;
  /// Degrees of each higher-order cell (cell data HigherOrderDegrees, marked as
  /// that attribute); empty for none.
  std::vector<std::array<int, 3>> higher_order_degrees;
};

/// Writes `mesh` to `path` atomically. \throw IoError; InputError if
/// an array has the wrong length or a cell index is out of range.
void write_vtu(const std::string& path, const VtuMesh& mesh,
               VtuCompression compression = VtuCompression::LZ4);
/// The same, releasing each of `mesh`'s arrays as soon as VTK has its copy
/// (the peak memory of a large mesh about halves); `mesh` is left empty.
void write_vtu(const std::string& path, VtuMesh&& mesh, VtuCompression compression = VtuCompression::LZ4);

/// The meshes one after the other as one mesh: points and cells in order (each
/// part's point indices offset by the points before it), with an Int32 cell
/// array `part_array` (if not empty) holding each cell's part index. Arrays not
/// present in every part are dropped, and so are cell types, higher-order
/// degrees and rational weights unless every part has the same.
VtuMesh merge_vtu(const std::vector<VtuMesh>& parts, const std::string& part_array = "");
/// The same, releasing each part once it is appended (`parts` is left empty).
VtuMesh merge_vtu(std::vector<VtuMesh>&& parts, const std::string& part_array = "");
/// Writes merge_vtu(parts, part_array) without making it: the parts' arrays go
/// to VTK one by one, each released once VTK has its copy, so that the parts
/// and the written grid are never whole at once (`parts` is left empty).
void write_vtu_parts(const std::string& path, std::vector<VtuMesh>&& parts,
                     const std::string& part_array = "", VtuCompression compression = VtuCompression::LZ4);
/// Writes one .vtu file of `pieces` pieces (<Piece> elements; VTK readers and
/// ParaView read them as one grid), piece i made by piece(i) when the writer
/// gets to it and released once written: only one piece is in memory at a
/// time. An exception from piece() is passed on (nothing is written).
void write_vtu_pieces(const std::string& path, int pieces, const std::function<VtuMesh(int)>& piece,
                      VtuCompression compression = VtuCompression::LZ4);

/// A piece given as parts: written as merge_vtu(parts, part_array) would give
/// it, with the part indices counted from `first_part`, without that merged
/// copy being made (each part's arrays go to VTK and are released).
struct VtuParts {
  std::vector<VtuMesh> parts;
  std::string part_array;  ///< "" for none
  int first_part = 0;
};
/// write_vtu_pieces with each piece made as parts.
void write_vtu_part_pieces(const std::string& path, int pieces, const std::function<VtuParts(int)>& piece,
                           VtuCompression compression = VtuCompression::LZ4);

/// One dataset of a .pvd collection.
struct PvdEntry {
  double timestep = 0.0;
  std::string file;  ///< relative to the .pvd's directory
  int part = 0;
};

/// Writes a ParaView collection file atomically.
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

}  // namespace toolkit::io

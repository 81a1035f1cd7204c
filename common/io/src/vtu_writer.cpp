#include "toolkit/io/vtu_writer.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkIdTypeArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkIntArray.h>
#include <vtkLZ4DataCompressor.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridAlgorithm.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <system_error>
#include <type_traits>

#include "deflate_compressor.h"
#include "toolkit/errors.h"
#include "toolkit/io/atomic_file.h"
#include "vtk_errors.h"
#include "vtk_threads.h"

namespace toolkit::io {
namespace {

using detail::error_code_text;
using detail::ErrorCollector;
using detail::vtk_message_text;

// ---------------------------------------------------------------- validation

template <class Map>
void check_lengths(const Map& arrays, std::size_t expected, const char* kind, const char* per,
                   std::set<std::string>& names) {
  for (const auto& [name, values] : arrays) {
    if (name.empty()) throw toolkit::InputError(std::string("write_vtu: ") + kind + " array has an empty name");
    if (!names.insert(name).second)
      throw toolkit::InputError("write_vtu: duplicate " + std::string(per) + " array name '" + name + "'");
    if (values.size() != expected)
      throw toolkit::InputError("write_vtu: " + std::string(kind) + " array '" + name + "' has " +
                                  std::to_string(values.size()) + " values, expected " + std::to_string(expected) +
                                  " (one per " + per + ")");
  }
}

void validate(const VtuMesh& mesh) {
  if (!mesh.points.empty() && !mesh.points3d.empty())
    throw toolkit::InputError("write_vtu: both 2D and 3D points given");
  const std::size_t np = mesh.points.size() + mesh.points3d.size();
  if (np > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw toolkit::InputError("write_vtu: too many points");
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const auto& cell = mesh.cells[c];
    if (cell.empty()) throw toolkit::InputError("write_vtu: cell " + std::to_string(c) + " has no points");
    for (int idx : cell) {
      if (idx < 0 || static_cast<std::size_t>(idx) >= np)
        throw toolkit::InputError("write_vtu: cell " + std::to_string(c) + " references point " +
                                    std::to_string(idx) + ", but there are " + std::to_string(np) + " points");
    }
  }
  std::set<std::string> point_names;
  std::set<std::string> cell_names;
  check_lengths(mesh.point_scalars, np, "point scalar", "point", point_names);
  check_lengths(mesh.point_ints, np, "point int", "point", point_names);
  check_lengths(mesh.point_vectors, np, "point vector", "point", point_names);
  check_lengths(mesh.cell_scalars, mesh.cells.size(), "cell scalar", "cell", cell_names);
  check_lengths(mesh.cell_ints, mesh.cells.size(), "cell int", "cell", cell_names);
  check_lengths(mesh.cell_vectors, mesh.cells.size(), "cell vector", "cell", cell_names);
  if (!mesh.cell_types.empty() && mesh.cell_types.size() != mesh.cells.size())
    throw toolkit::InputError("write_vtu: " + std::to_string(mesh.cell_types.size()) + " cell types for " +
                                std::to_string(mesh.cells.size()) + " cells");
  if (!mesh.higher_order_degrees.empty() && mesh.higher_order_degrees.size() != mesh.cells.size())
    throw toolkit::InputError("write_vtu: " + std::to_string(mesh.higher_order_degrees.size()) +
                                " higher-order degrees for " + std::to_string(mesh.cells.size()) + " cells");
  if (!mesh.rational_weights.empty() && !mesh.point_scalars.count(mesh.rational_weights))
    throw toolkit::InputError("write_vtu: no point scalar array '" + mesh.rational_weights +
                                "' for the rational weights");
}

// ---------------------------------------------------------------- grid building

int cell_type(const std::vector<int>& cell, bool quads_as_polygons) {
  switch (cell.size()) {
    case 1: return VTK_VERTEX;
    case 2: return VTK_LINE;
    case 4: return quads_as_polygons ? VTK_POLYGON : VTK_QUAD;
    default: return VTK_POLYGON;
  }
}

// ---------------------------------------------------------------- parts

template <class Part>
void release(Part&, auto& v) {
  if constexpr (!std::is_const_v<Part>) std::decay_t<decltype(v)>().swap(v);
}

// What a sequence of parts makes as one mesh (merge_vtu): the array names that
// every part has, and whether cell types, degrees and weights are kept.
struct PartsLayout {
  bool quads_as_polygons = true;
  std::set<std::string> point_scalars, point_ints, point_vectors, cell_scalars, cell_ints, cell_vectors;
  bool typed = true, degrees = true;
  std::string rational_weights;
  std::vector<std::size_t> point_offset;  // per part, and the total at the end
  std::size_t cells = 0, connectivity = 0;
};

template <class Map>
std::set<std::string> common_names(std::span<const VtuMesh> parts, Map VtuMesh::*member) {
  std::set<std::string> names;
  if (parts.empty()) return names;
  for (const auto& [name, values] : parts.front().*member) names.insert(name);
  for (const VtuMesh& p : parts.subspan(1))
    std::erase_if(names, [&](const std::string& n) { return !(p.*member).count(n); });
  return names;
}

PartsLayout parts_layout(std::span<const VtuMesh> parts, const std::string& part_array) {
  PartsLayout L;
  if (!parts.empty()) {
    L.quads_as_polygons = parts.front().quads_as_polygons;
    L.rational_weights = parts.front().rational_weights;
  }
  L.point_scalars = common_names(parts, &VtuMesh::point_scalars);
  L.point_ints = common_names(parts, &VtuMesh::point_ints);
  L.point_vectors = common_names(parts, &VtuMesh::point_vectors);
  L.cell_scalars = common_names(parts, &VtuMesh::cell_scalars);
  L.cell_ints = common_names(parts, &VtuMesh::cell_ints);
  L.cell_vectors = common_names(parts, &VtuMesh::cell_vectors);
  if (!part_array.empty()) {
    L.cell_scalars.erase(part_array), L.cell_vectors.erase(part_array);
    L.cell_ints.insert(part_array);
  }
  std::size_t points = 0;
  for (const VtuMesh& p : parts) {
    L.point_offset.push_back(points);
    points += p.points.size() + p.points3d.size();
    L.cells += p.cells.size();
    for (const auto& cell : p.cells) L.connectivity += cell.size();
    L.typed = L.typed && p.cell_types.size() == p.cells.size();
    L.degrees = L.degrees && p.higher_order_degrees.size() == p.cells.size();
    if (p.rational_weights != L.rational_weights) L.rational_weights.clear();
  }
  L.point_offset.push_back(points);
  if (!L.point_scalars.count(L.rational_weights)) L.rational_weights.clear();
  if (points > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw toolkit::InputError("write_vtu: too many points");
  return L;
}

// Each part's values of array `name` one after the other, through put(i, value).
template <class Part, class Map, class Put>
void gather(std::span<Part> parts, Map VtuMesh::*member, const std::string& name, Put put) {
  vtkIdType i = 0;
  for (Part& p : parts) {
    auto& values = (p.*member).at(name);
    for (const auto& x : values) put(i++, x);
    release(p, values);
  }
}

// Each cell's part index, counted from `first`.
template <class Part>
std::vector<int> part_index(std::span<Part> parts, std::size_t cells, int first = 0) {
  std::vector<int> index;
  index.reserve(cells);
  for (std::size_t k = 0; k < parts.size(); ++k)
    index.insert(index.end(), parts[k].cells.size(), first + static_cast<int>(k));
  return index;
}

// The points of every part, in part order (each part's points released once copied).
template <class Part>
void set_points(vtkUnstructuredGrid* grid, std::span<Part> parts, const PartsLayout& L) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(L.point_offset.back()));
  vtkIdType at = 0;
  for (Part& p : parts) {
    for (const Eigen::Vector2d& x : p.points) points->SetPoint(at++, x.x(), x.y(), 0.0);
    for (const Eigen::Vector3d& x : p.points3d) points->SetPoint(at++, x.x(), x.y(), x.z());
    release(p, p.points), release(p, p.points3d);
  }
  grid->SetPoints(points);
}

// The cells of every part, their point ids offset by the part's first point.
template <class Part>
void set_cells(vtkUnstructuredGrid* grid, std::span<Part> parts, const PartsLayout& L) {
  vtkNew<vtkCellArray> cells;
  vtkNew<vtkUnsignedCharArray> types;
  types->SetNumberOfTuples(static_cast<vtkIdType>(L.cells));
  // Connectivity and offsets in 32 bits where they fit (any grid below 2^31
  // point references): half the bytes to hold, compress and write (VTK writes
  // the storage's own type; readers take either).
  if (L.connectivity < static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()) &&
      L.point_offset.back() < static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    cells->Use32BitStorage();
  cells->AllocateExact(static_cast<vtkIdType>(L.cells), static_cast<vtkIdType>(L.connectivity));
  std::vector<vtkIdType> ids;
  vtkIdType c = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    Part& p = parts[k];
    const vtkIdType offset = static_cast<vtkIdType>(L.point_offset[k]);
    for (std::size_t i = 0; i < p.cells.size(); ++i) {
      const auto& cell = p.cells[i];
      ids.resize(cell.size());
      for (std::size_t j = 0; j < cell.size(); ++j) ids[j] = cell[j] + offset;
      cells->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
      const int type = L.typed ? p.cell_types[i] : cell_type(cell, L.quads_as_polygons);
      types->SetValue(c++, static_cast<unsigned char>(type));
    }
    release(p, p.cells), release(p, p.cell_types);
  }
  grid->SetCells(types, cells);
}

// The point and cell fields of the parts, gathered by name; `index`: the
// values of the part-index array `part_array` ("" for none).
template <class Part>
void add_fields(vtkUnstructuredGrid* grid, std::span<Part> parts, const PartsLayout& L, const std::string& part_array,
                const std::vector<int>& index) {
  const vtkIdType np = static_cast<vtkIdType>(L.point_offset.back()), nc = static_cast<vtkIdType>(L.cells);
  auto doubles = [&](const std::string& name, auto member, vtkIdType n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name.c_str());
    a->SetNumberOfTuples(n);
    gather(parts, member, name, [&](vtkIdType i, double x) { a->SetValue(i, x); });
    return a;
  };
  auto ints = [&](const std::string& name, auto member, vtkIdType n) {
    vtkNew<vtkIntArray> a;
    a->SetName(name.c_str());
    a->SetNumberOfTuples(n);
    if (name == part_array)
      for (vtkIdType i = 0; i < n; ++i) a->SetValue(i, index[static_cast<std::size_t>(i)]);
    else
      gather(parts, member, name, [&](vtkIdType i, int x) { a->SetValue(i, x); });
    return a;
  };
  auto vectors = [&](const std::string& name, auto member, vtkIdType n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name.c_str());
    a->SetNumberOfComponents(3);
    a->SetNumberOfTuples(n);
    gather(parts, member, name, [&](vtkIdType i, const Eigen::Vector2d& x) {
      const double t[3] = {x.x(), x.y(), 0.0};
      a->SetTypedTuple(i, t);
    });
    return a;
  };
  vtkPointData* pd = grid->GetPointData();
  for (const std::string& name : L.point_scalars) pd->AddArray(doubles(name, &VtuMesh::point_scalars, np));
  for (const std::string& name : L.point_ints) pd->AddArray(ints(name, &VtuMesh::point_ints, np));
  for (const std::string& name : L.point_vectors) pd->AddArray(vectors(name, &VtuMesh::point_vectors, np));
  if (!L.rational_weights.empty())
    pd->SetActiveAttribute(L.rational_weights.c_str(), vtkDataSetAttributes::RATIONALWEIGHTS);
  vtkCellData* cd = grid->GetCellData();
  for (const std::string& name : L.cell_scalars) cd->AddArray(doubles(name, &VtuMesh::cell_scalars, nc));
  for (const std::string& name : L.cell_ints) cd->AddArray(ints(name, &VtuMesh::cell_ints, nc));
  for (const std::string& name : L.cell_vectors) cd->AddArray(vectors(name, &VtuMesh::cell_vectors, nc));
}

// VTK's HigherOrderDegrees cell array, where the parts give cell degrees.
template <class Part>
void add_higher_order_degrees(vtkUnstructuredGrid* grid, std::span<Part> parts, const PartsLayout& L) {
  if (!L.degrees || L.cells == 0) return;
  vtkNew<vtkIntArray> a;
  a->SetName("HigherOrderDegrees");
  a->SetNumberOfComponents(3);
  a->SetNumberOfTuples(static_cast<vtkIdType>(L.cells));
  vtkIdType i = 0;
  for (Part& p : parts) {
    for (const std::array<int, 3>& d : p.higher_order_degrees) a->SetTypedTuple(i++, d.data());
    release(p, p.higher_order_degrees);
  }
  grid->GetCellData()->SetHigherOrderDegrees(a);
}

// The grid of the parts as one mesh (merge_vtu). With non-const parts
// (write_vtu(path, VtuMesh&&), write_vtu_parts) each of their arrays is
// released once VTK has its copy, so that the two are never whole at once (a
// sea of 9,000 patches: surface.vtu's mesh and its grid were 1 GB together).
template <class Part>
vtkNew<vtkUnstructuredGrid> build_grid(std::span<Part> parts, const std::string& part_array,
                                       int first_part = 0) {
  const PartsLayout L = parts_layout(std::span<const VtuMesh>(parts.data(), parts.size()), part_array);
  vtkNew<vtkUnstructuredGrid> grid;
  set_points(grid.Get(), parts, L);
  // Part indices before the parts' cells are released.
  const std::vector<int> index =
      part_array.empty() ? std::vector<int>() : part_index(parts, L.cells, first_part);
  set_cells(grid.Get(), parts, L);
  add_fields(grid.Get(), parts, L, part_array, index);
  add_higher_order_degrees(grid.Get(), parts, L);
  return grid;
}

// merge_vtu: the same rules as build_grid, into a VtuMesh.
template <class Part>
VtuMesh merge(std::span<Part> parts, const std::string& part_array) {
  const PartsLayout L = parts_layout(std::span<const VtuMesh>(parts.data(), parts.size()), part_array);
  VtuMesh out;
  out.quads_as_polygons = L.quads_as_polygons;
  out.rational_weights = L.rational_weights;
  const std::size_t np = L.point_offset.back(), nc = L.cells;
  std::vector<int> index = part_array.empty() ? std::vector<int>() : part_index(parts, nc);
  // Every array at its final size at once (growing by doubling held up to
  // twice the memory); 3D points if any part has them (the others at z = 0).
  const bool three_d = std::any_of(parts.begin(), parts.end(), [](const VtuMesh& p) { return !p.points3d.empty(); });
  if (three_d) out.points3d.reserve(np);
  else out.points.reserve(np);
  out.cells.reserve(nc);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    Part& p = parts[k];
    if (three_d) {
      for (const Eigen::Vector2d& x : p.points) out.points3d.emplace_back(x.x(), x.y(), 0.0);
      out.points3d.insert(out.points3d.end(), p.points3d.begin(), p.points3d.end());
    } else {
      out.points.insert(out.points.end(), p.points.begin(), p.points.end());
    }
    release(p, p.points), release(p, p.points3d);
    const int offset = static_cast<int>(L.point_offset[k]);
    for (auto& cell : p.cells) {
      std::vector<int> moved;  // released parts give their cells away (no second allocation)
      if constexpr (std::is_const_v<Part>) moved = cell;
      else moved = std::move(cell);
      for (int& i : moved) i += offset;
      out.cells.push_back(std::move(moved));
    }
    release(p, p.cells);
    if (L.typed) out.cell_types.insert(out.cell_types.end(), p.cell_types.begin(), p.cell_types.end());
    if (L.degrees)
      out.higher_order_degrees.insert(out.higher_order_degrees.end(), p.higher_order_degrees.begin(),
                                      p.higher_order_degrees.end());
    release(p, p.cell_types), release(p, p.higher_order_degrees);
  }
  auto collect = [&](const std::set<std::string>& names, auto member, std::size_t n) {
    for (const std::string& name : names) {
      auto& values = (out.*member)[name];
      values.reserve(n);
      gather(parts, member, name, [&](vtkIdType, const auto& x) { values.push_back(x); });
    }
  };
  collect(L.point_scalars, &VtuMesh::point_scalars, np);
  collect(L.point_ints, &VtuMesh::point_ints, np);
  collect(L.point_vectors, &VtuMesh::point_vectors, np);
  collect(L.cell_scalars, &VtuMesh::cell_scalars, nc);
  std::set<std::string> cell_ints = L.cell_ints;
  if (!part_array.empty()) cell_ints.erase(part_array);
  collect(cell_ints, &VtuMesh::cell_ints, nc);
  collect(L.cell_vectors, &VtuMesh::cell_vectors, nc);
  if (!part_array.empty()) out.cell_ints[part_array] = std::move(index);
  return out;
}

// ---------------------------------------------------------------- pvd

std::string xml_escape_attr(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (const char ch : s) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      case '\t': out += "&#9;"; break;
      case '\n': out += "&#10;"; break;
      case '\r': out += "&#13;"; break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20)
          throw toolkit::InputError("write_pvd: file name contains a control character, not allowed in XML");
        out += ch;
    }
  }
  return out;
}

std::string format_double(double x) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);  // shortest round-trip form
  if (ec != std::errc()) throw toolkit::InternalError("write_pvd: cannot format a number");
  return std::string(buf, end);
}

}  // namespace

namespace {

// A source that makes piece i of n when the writer asks for it (VTK's
// streaming: the writer writes the pieces one after the other into one file,
// and only one piece is in memory at a time).
class PieceSource : public vtkUnstructuredGridAlgorithm {
 public:
  static PieceSource* New();
  vtkTypeMacro(PieceSource, vtkUnstructuredGridAlgorithm)
  // Piece i of the file, as parts (write_vtu_pieces: one part per piece).
  std::function<VtuParts(int)> make;
  std::exception_ptr error;  // of the first piece that could not be made

 protected:
  PieceSource() { SetNumberOfInputPorts(0); }
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* out) override {
    out->GetInformationObject(0)->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
    return 1;
  }
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* out) override {
    vtkInformation* info = out->GetInformationObject(0);
    const int piece = info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
    // After a failure the pieces are empty: returning 0 would make the writer
    // ask for the piece again and again (VTK 9.1); the error is raised once
    // Write() returns, and the temporary file is removed.
    vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(info);
    if (error) return set_empty(output);
    try {
      VtuParts made = make(piece);
      for (const VtuMesh& part : made.parts) validate(part);
      vtkNew<vtkUnstructuredGrid> grid =
          build_grid(std::span<VtuMesh>(made.parts), made.part_array, made.first_part);
      output->ShallowCopy(grid);
    } catch (...) {
      error = std::current_exception();
      return set_empty(output);
    }
    return 1;
  }
  // An empty grid with (empty) points and cells: the pipeline has released the
  // previous piece, and with no cell array the writer (VTK 9.1) would write the
  // cells of its last piece from their released memory.
  static int set_empty(vtkUnstructuredGrid* output) {
    vtkNew<vtkPoints> points;
    vtkNew<vtkCellArray> cells;
    vtkNew<vtkUnsignedCharArray> types;
    output->SetPoints(points);
    output->SetCells(types, cells);
    return 1;
  }
};
vtkStandardNewMacro(PieceSource);

// The writer's compressor.
void set_compression(vtkXMLUnstructuredGridWriter* writer, VtuCompression compression) {
  switch (compression) {
    case VtuCompression::LZ4: {
      // LZ4's own default speed (acceleration 1; VTK's level 9): on a
      // coastline's surface.vtu arrays 0.15 s to 127 MB, where acceleration 9
      // (VTK's level 1) takes 0.11 s to 137 MB and libdeflate 0.73 s to 98 MB.
      vtkNew<vtkLZ4DataCompressor> compressor;
      compressor->SetAccelerationLevel(1);
      writer->SetCompressor(compressor);
      return;
    }
    case VtuCompression::Zlib: {
      // zlib streams made by libdeflate (deflate_compressor.h: twice zlib's
      // speed), level 1: about three times faster than VTK's default 5 on our
      // meshes (coordinates and quality fields) for files about 10 % larger.
      vtkNew<detail::DeflateCompressor> compressor;
      writer->SetCompressor(compressor);
      writer->SetCompressionLevel(1);
      return;
    }
    case VtuCompression::None:
      writer->SetCompressor(nullptr);
      return;
  }
  throw toolkit::InputError("write_vtu: unknown compression");
}

// Writes the grid, or the source's pieces, atomically.
void write_grid(const std::string& path, VtuCompression compression, vtkUnstructuredGrid* grid,
                PieceSource* source = nullptr, int pieces = 1) {
  write_atomic(path, [&](const std::string& tmp) {
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    vtkNew<ErrorCollector> errors;
    writer->AddObserver(vtkCommand::ErrorEvent, errors);
    // The pipeline reports the failed request again; keep that off stderr too.
    vtkNew<ErrorCollector> executive_errors;
    writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, executive_errors);
    writer->SetFileName(tmp.c_str());
    if (source) {
      writer->SetInputConnection(source->GetOutputPort());
      writer->SetNumberOfPieces(pieces);
    } else {
      writer->SetInputData(grid);
    }
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    set_compression(writer, compression);
    writer->SetHeaderTypeToUInt64();
    writer->SetIdTypeToInt64();
    // Write() returns 1 even when the file could not be opened or written:
    // the error code is what tells.
    const int ok = writer->Write();
    if (source && source->error) std::rethrow_exception(source->error);  // a piece could not be made
    const unsigned long code = writer->GetErrorCode();
    if (ok != 1 || code != vtkErrorCode::NoError || !errors->message.empty()) {
      std::string reason;
      if (code != vtkErrorCode::NoError) reason = error_code_text(code);
      if (reason.empty() || code >= vtkErrorCode::FirstVTKErrorCode) {
        const std::string text = vtk_message_text(errors->message);
        if (!text.empty()) reason += (reason.empty() ? "" : ": ") + text;
      }
      if (reason.empty()) reason = "VTK writer failed";
      throw IoError("cannot write '" + path + "': " + reason);
    }
  });
}

}  // namespace

std::string_view vtu_compression_name(VtuCompression c) {
  switch (c) {
    case VtuCompression::LZ4:
      return "lz4";
    case VtuCompression::Zlib:
      return "zlib";
    case VtuCompression::None:
      return "none";
  }
  return "?";
}

VtuCompression parse_vtu_compression(std::string_view name) {
  for (VtuCompression c : {VtuCompression::LZ4, VtuCompression::Zlib, VtuCompression::None})
    if (name == vtu_compression_name(c)) return c;
  throw toolkit::InputError("unknown .vtu compression '" + std::string(name) + "' (lz4, zlib or none)");
}

void write_vtu(const std::string& path, const VtuMesh& mesh, VtuCompression compression) {
  detail::prepare_vtk_for_threads();
  validate(mesh);  // before anything touches the file system
  vtkNew<vtkUnstructuredGrid> grid = build_grid(std::span<const VtuMesh>(&mesh, 1), "");
  write_grid(path, compression, grid);
}

void write_vtu(const std::string& path, VtuMesh&& mesh, VtuCompression compression) {
  detail::prepare_vtk_for_threads();
  validate(mesh);
  vtkNew<vtkUnstructuredGrid> grid = build_grid(std::span<VtuMesh>(&mesh, 1), "");
  mesh = VtuMesh();
  write_grid(path, compression, grid);
}

VtuMesh merge_vtu(const std::vector<VtuMesh>& parts, const std::string& part_array) {
  return merge(std::span<const VtuMesh>(parts), part_array);
}

VtuMesh merge_vtu(std::vector<VtuMesh>&& parts, const std::string& part_array) {
  VtuMesh out = merge(std::span<VtuMesh>(parts), part_array);
  parts.clear();
  return out;
}

void write_vtu_parts(const std::string& path, std::vector<VtuMesh>&& parts, const std::string& part_array,
                     VtuCompression compression) {
  detail::prepare_vtk_for_threads();
  for (const VtuMesh& p : parts) validate(p);
  vtkNew<vtkUnstructuredGrid> grid = build_grid(std::span<VtuMesh>(parts), part_array);
  parts.clear();
  write_grid(path, compression, grid);
}

void write_vtu_pieces(const std::string& path, int pieces, const std::function<VtuMesh(int)>& piece,
                      VtuCompression compression) {
  write_vtu_part_pieces(
      path, pieces,
      [&piece](int i) {
        VtuParts one;
        one.parts.push_back(piece(i));
        return one;
      },
      compression);
}

void write_vtu_part_pieces(const std::string& path, int pieces, const std::function<VtuParts(int)>& piece,
                           VtuCompression compression) {
  detail::prepare_vtk_for_threads();
  if (pieces < 1) throw toolkit::InputError("write_vtu_pieces: the number of pieces must be >= 1");
  vtkNew<PieceSource> source;
  source->make = piece;
  write_grid(path, compression, nullptr, source, pieces);
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  std::string xml;
  xml += "<?xml version=\"1.0\"?>\n";
  xml += "<VTKFile type=\"Collection\" version=\"0.1\">\n";
  xml += "  <Collection>\n";
  for (const PvdEntry& e : entries) {
    if (!std::isfinite(e.timestep)) throw toolkit::InputError("write_pvd: timestep of '" + e.file + "' is not finite");
    xml += "    <DataSet timestep=\"" + format_double(e.timestep) + "\" part=\"" + std::to_string(e.part) +
           "\" file=\"" + xml_escape_attr(e.file) + "\"/>\n";
  }
  xml += "  </Collection>\n";
  xml += "</VTKFile>\n";
  write_text_atomic(path, xml);
}

}  // namespace toolkit::io

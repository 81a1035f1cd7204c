#include "toolkit/io/vtu_writer.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <type_traits>
#include <stdexcept>
#include <string>
#include <system_error>

#include "toolkit/errors.h"
#include "toolkit/io/atomic_file.h"
#include "vtk_errors.h"

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
    if (name.empty()) throw std::invalid_argument(std::string("write_vtu: ") + kind + " array has an empty name");
    if (!names.insert(name).second)
      throw std::invalid_argument("write_vtu: duplicate " + std::string(per) + " array name '" + name + "'");
    if (values.size() != expected)
      throw std::invalid_argument("write_vtu: " + std::string(kind) + " array '" + name + "' has " +
                                  std::to_string(values.size()) + " values, expected " + std::to_string(expected) +
                                  " (one per " + per + ")");
  }
}

void validate(const VtuMesh& mesh) {
  if (!mesh.points.empty() && !mesh.points3d.empty())
    throw std::invalid_argument("write_vtu: both 2D and 3D points given");
  const std::size_t np = mesh.points.size() + mesh.points3d.size();
  if (np > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw std::invalid_argument("write_vtu: too many points");
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const auto& cell = mesh.cells[c];
    if (cell.empty()) throw std::invalid_argument("write_vtu: cell " + std::to_string(c) + " has no points");
    for (int idx : cell) {
      if (idx < 0 || static_cast<std::size_t>(idx) >= np)
        throw std::invalid_argument("write_vtu: cell " + std::to_string(c) + " references point " +
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
    throw std::invalid_argument("write_vtu: " + std::to_string(mesh.cell_types.size()) + " cell types for " +
                                std::to_string(mesh.cells.size()) + " cells");
  if (!mesh.higher_order_degrees.empty() && mesh.higher_order_degrees.size() != mesh.cells.size())
    throw std::invalid_argument("write_vtu: " + std::to_string(mesh.higher_order_degrees.size()) +
                                " higher-order degrees for " + std::to_string(mesh.cells.size()) + " cells");
  if (!mesh.rational_weights.empty() && !mesh.point_scalars.count(mesh.rational_weights))
    throw std::invalid_argument("write_vtu: no point scalar array '" + mesh.rational_weights +
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

vtkNew<vtkDoubleArray> make_double_array(const std::string& name, const std::vector<double>& v) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name.c_str());
  a->SetNumberOfComponents(1);
  a->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), v[i]);
  return a;
}

vtkNew<vtkDoubleArray> make_vector_array(const std::string& name, const std::vector<Eigen::Vector2d>& v) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name.c_str());
  a->SetNumberOfComponents(3);
  a->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double t[3] = {v[i].x(), v[i].y(), 0.0};
    a->SetTypedTuple(static_cast<vtkIdType>(i), t);
  }
  return a;
}

vtkNew<vtkIntArray> make_int_array(const std::string& name, const std::vector<int>& v) {
  vtkNew<vtkIntArray> a;
  a->SetName(name.c_str());
  a->SetNumberOfComponents(1);
  a->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), v[i]);
  return a;
}

// The grid of `mesh`. With a non-const mesh (write_vtu(path, VtuMesh&&)) each
// of its arrays is released once VTK has its copy, so that the two are never
// whole at once (a sea of 9,000 patches: surface.vtu's mesh and its grid
// were 1 GB together).
template <class Mesh>
vtkNew<vtkUnstructuredGrid> build_grid(Mesh& mesh) {
  auto release = [](auto& v) {
    if constexpr (!std::is_const_v<std::remove_reference_t<decltype(v)>>) std::decay_t<decltype(v)>().swap(v);
  };
  vtkNew<vtkUnstructuredGrid> grid;

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size() + mesh.points3d.size()));
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), mesh.points[i].x(), mesh.points[i].y(), 0.0);
  for (std::size_t i = 0; i < mesh.points3d.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), mesh.points3d[i].x(), mesh.points3d[i].y(), mesh.points3d[i].z());
  grid->SetPoints(points);
  release(mesh.points), release(mesh.points3d);

  vtkNew<vtkCellArray> cells;
  vtkNew<vtkUnsignedCharArray> types;
  types->SetNumberOfTuples(static_cast<vtkIdType>(mesh.cells.size()));
  std::size_t connectivity = 0;
  for (const auto& cell : mesh.cells) connectivity += cell.size();
  cells->AllocateExact(static_cast<vtkIdType>(mesh.cells.size()), static_cast<vtkIdType>(connectivity));
  std::vector<vtkIdType> ids;
  for (std::size_t c = 0; c < mesh.cells.size(); ++c) {
    const auto& cell = mesh.cells[c];
    ids.assign(cell.begin(), cell.end());
    cells->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
    const int type = mesh.cell_types.empty() ? cell_type(cell, mesh.quads_as_polygons) : mesh.cell_types[c];
    types->SetValue(static_cast<vtkIdType>(c), static_cast<unsigned char>(type));
  }
  grid->SetCells(types, cells);
  release(mesh.cells), release(mesh.cell_types);

  vtkPointData* pd = grid->GetPointData();
  for (auto& [name, v] : mesh.point_scalars) pd->AddArray(make_double_array(name, v)), release(v);
  for (auto& [name, v] : mesh.point_ints) pd->AddArray(make_int_array(name, v)), release(v);
  for (auto& [name, v] : mesh.point_vectors) pd->AddArray(make_vector_array(name, v)), release(v);
  if (!mesh.rational_weights.empty())
    pd->SetActiveAttribute(mesh.rational_weights.c_str(), vtkDataSetAttributes::RATIONALWEIGHTS);
  vtkCellData* cd = grid->GetCellData();
  for (auto& [name, v] : mesh.cell_scalars) cd->AddArray(make_double_array(name, v)), release(v);
  for (auto& [name, v] : mesh.cell_ints) cd->AddArray(make_int_array(name, v)), release(v);
  for (auto& [name, v] : mesh.cell_vectors) cd->AddArray(make_vector_array(name, v)), release(v);
  if (!mesh.higher_order_degrees.empty()) {
    vtkNew<vtkIntArray> a;
    a->SetName("HigherOrderDegrees");
    a->SetNumberOfComponents(3);
    a->SetNumberOfTuples(static_cast<vtkIdType>(mesh.higher_order_degrees.size()));
    for (std::size_t c = 0; c < mesh.higher_order_degrees.size(); ++c)
      a->SetTypedTuple(static_cast<vtkIdType>(c), mesh.higher_order_degrees[c].data());
    cd->SetHigherOrderDegrees(a);
    release(mesh.higher_order_degrees);
  }
  return grid;
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
          throw std::invalid_argument("write_pvd: file name contains a control character, not allowed in XML");
        out += ch;
    }
  }
  return out;
}

std::string format_double(double x) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);  // shortest round-trip form
  if (ec != std::errc()) throw std::logic_error("write_pvd: cannot format a number");
  return std::string(buf, end);
}

}  // namespace

namespace {

void write_grid(const std::string& path, vtkUnstructuredGrid* grid) {
  write_atomic(path, [&](const std::string& tmp) {
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    vtkNew<ErrorCollector> errors;
    writer->AddObserver(vtkCommand::ErrorEvent, errors);
    // The pipeline reports the failed request again; keep that off stderr too.
    vtkNew<ErrorCollector> executive_errors;
    writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, executive_errors);
    writer->SetFileName(tmp.c_str());
    writer->SetInputData(grid);
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    writer->SetCompressorTypeToZLib();
    // zlib level 1: about three times faster than VTK's default 5 on our
    // meshes (coordinates and quality fields) for files about 10 % larger.
    writer->SetCompressionLevel(1);
    writer->SetHeaderTypeToUInt64();
    writer->SetIdTypeToInt64();
    // Write() returns 1 even when the file could not be opened or written:
    // the error code is what tells.
    const int ok = writer->Write();
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

void write_vtu(const std::string& path, const VtuMesh& mesh) {
  validate(mesh);  // before anything touches the file system
  vtkNew<vtkUnstructuredGrid> grid = build_grid(mesh);
  write_grid(path, grid);
}

void write_vtu(const std::string& path, VtuMesh&& mesh) {
  validate(mesh);
  vtkNew<vtkUnstructuredGrid> grid = build_grid(mesh);
  mesh = VtuMesh();
  write_grid(path, grid);
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  std::string xml;
  xml += "<?xml version=\"1.0\"?>\n";
  xml += "<VTKFile type=\"Collection\" version=\"0.1\">\n";
  xml += "  <Collection>\n";
  for (const PvdEntry& e : entries) {
    if (!std::isfinite(e.timestep)) throw std::invalid_argument("write_pvd: timestep of '" + e.file + "' is not finite");
    xml += "    <DataSet timestep=\"" + format_double(e.timestep) + "\" part=\"" + std::to_string(e.part) +
           "\" file=\"" + xml_escape_attr(e.file) + "\"/>\n";
  }
  xml += "  </Collection>\n";
  xml += "</VTKFile>\n";
  write_text_atomic(path, xml);
}

}  // namespace toolkit::io

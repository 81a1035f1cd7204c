#include "toolkit/io/vtu_reader.h"

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkExecutive.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <filesystem>

#include "toolkit/errors.h"
#include "vtk_errors.h"
#include "vtk_threads.h"

namespace toolkit::io {

namespace {

void copy_arrays(vtkFieldData* data, vtkIdType n, std::map<std::string, std::vector<double>>& out) {
  for (int a = 0; a < data->GetNumberOfArrays(); ++a) {
    vtkDataArray* arr = vtkDataArray::SafeDownCast(data->GetAbstractArray(a));
    if (!arr || arr->GetNumberOfComponents() != 1 || arr->GetName() == nullptr) continue;
    std::vector<double>& v = out[arr->GetName()];
    v.resize(static_cast<std::size_t>(n));
    for (vtkIdType i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = arr->GetTuple1(i);
  }
}

}  // namespace

VtuMesh read_vtu(const std::string& path) {
  detail::prepare_vtk_for_threads();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw IoError("cannot read '" + path + "': no such file");
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  vtkNew<detail::ErrorCollector> errors, executive_errors;
  reader->AddObserver(vtkCommand::ErrorEvent, errors);
  reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, executive_errors);
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  if (reader->GetErrorCode() != vtkErrorCode::NoError || !errors->message.empty() || grid == nullptr) {
    std::string reason = detail::vtk_message_text(errors->message);
    if (reason.empty()) reason = detail::error_code_text(reader->GetErrorCode());
    throw IoError("cannot read '" + path + "': " + (reason.empty() ? "not a VTK XML unstructured grid" : reason));
  }
  VtuMesh out;
  const vtkIdType np = grid->GetNumberOfPoints(), nc = grid->GetNumberOfCells();
  out.points.resize(static_cast<std::size_t>(np));
  for (vtkIdType i = 0; i < np; ++i) {
    double p[3];
    grid->GetPoint(i, p);
    out.points[static_cast<std::size_t>(i)] = {p[0], p[1]};
  }
  out.cells.resize(static_cast<std::size_t>(nc));
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < nc; ++c) {
    grid->GetCellPoints(c, ids);
    auto& cell = out.cells[static_cast<std::size_t>(c)];
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) cell.push_back(static_cast<int>(ids->GetId(k)));
  }
  copy_arrays(grid->GetPointData(), np, out.point_scalars);
  // Vectors of points (3 components; the writer's 2D vectors have z = 0).
  vtkPointData* pd = grid->GetPointData();
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a) {
    vtkDataArray* arr = vtkDataArray::SafeDownCast(pd->GetAbstractArray(a));
    if (!arr || arr->GetNumberOfComponents() != 3 || arr->GetName() == nullptr) continue;
    std::vector<Eigen::Vector2d>& v = out.point_vectors[arr->GetName()];
    v.resize(static_cast<std::size_t>(np));
    for (vtkIdType i = 0; i < np; ++i) v[static_cast<std::size_t>(i)] = {arr->GetComponent(i, 0), arr->GetComponent(i, 1)};
  }
  copy_arrays(grid->GetCellData(), nc, out.cell_scalars);
  return out;
}

}  // namespace toolkit::io

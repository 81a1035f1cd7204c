#pragma once
// Output files of the front half (`tspline param`): ParaView meshes and the report.
#include <nlohmann/json.hpp>
#include <string>

#include "tspline/pipeline/parameterization.h"
#include "toolkit/io/vtu_writer.h"

namespace tspline::io {

/// The T-mesh as VTK polygons (each cell includes its hanging vertices) at the
/// given vertex positions, with cell data level, valid, min_quality and point
/// data hanging, boundary, and the parametric coordinates.
toolkit::io::VtuMesh tmesh_vtu(const TMesh& mesh, const std::vector<Eigen::Vector2d>& positions);

/// The polygon as line cells plus one vertex cell per corner; point data
/// file_index and corner (0..3 for the corners, -1 elsewhere), cell data side.
toolkit::io::VtuMesh boundary_vtu(const BoundaryMap& boundary);

/// The JSON report: counts, tolerance, corners, inverted cells after Coons and
/// after optimization, quality statistics, sweeps and per-stage wall times.
nlohmann::json front_report(const FrontResult& result, const std::string& input_path);

/// Writes parametric_tmesh.vtu, boundary.vtu and (if `physical`) physical_tmesh.vtu
/// of the front half's vertex positions (straight cell edges; valid by the
/// straight-polygon test), each atomically, into out_dir. A run with a map
/// writes physical_tmesh.vtu through the map instead (param_output.h).
void write_front_meshes(const FrontResult& result, const std::string& out_dir, bool physical = true,
                        toolkit::io::VtuCompression compression = toolkit::io::VtuCompression::LZ4);

}  // namespace tspline::io

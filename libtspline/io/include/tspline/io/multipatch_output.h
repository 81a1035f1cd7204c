#pragma once
// Output files of `tspline param` on a multi-patch map: the same files as for a
// single patch, covering every patch (cell data `patch`), tspline.json in
// format version 2 (multipatch_file.h) and a report with per-patch and total
// figures.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "toolkit/io/vtu_writer.h"
#include "tspline/multipatch/multipatch_parameterization.h"

namespace tspline::io {

/// The meshes one after the other, with an Int32 cell array `patch` (the index
/// in `parts`); arrays not present in every part are dropped, and so are cell
/// types, higher-order degrees and rational weights unless every part has them.
toolkit::io::VtuMesh merge_patches(const std::vector<toolkit::io::VtuMesh>& parts);
/// The same, releasing each part once it is appended (`parts` is left empty).
toolkit::io::VtuMesh merge_patches(std::vector<toolkit::io::VtuMesh>&& parts);

/// Report: per patch the single-patch report (param_report), per interface the
/// gap and knots, and the totals (cells, elements, functions, certification,
/// whole-map min J_r, areas, seconds).
nlohmann::json multipatch_report(const MultiPatchResult& result, const std::string& input_path, double seconds);

/// Writes tspline.json (version 2), surface.vtu, surface_bezier.vtu, control_net.vtu,
/// parametric_tmesh.vtu (patch p shifted by 1.25 p in xi), physical_tmesh.vtu,
/// boundary.vtu and report.json (last) into out_dir, each atomically. Each VTU
/// file is written in pieces of whole patches of about `piece_cells` T-mesh
/// cells (toolkit::io::write_vtu_pieces); three files are written at once (VTK
/// compresses serially), each with one piece in memory and the next one being
/// made.
void write_multipatch_outputs(const MultiPatchResult& result, const std::string& out_dir,
                              const nlohmann::json& report, int samples,
                              toolkit::io::VtuCompression compression = toolkit::io::VtuCompression::LZ4,
                              std::size_t piece_cells = 8192);

}  // namespace tspline::io

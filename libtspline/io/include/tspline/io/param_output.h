#pragma once
// Output files of `tspline param` beyond the front half: the T-spline file, the
// sampled map, the control net, the ParaView series of the adaptive iterations
// and the full report.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "toolkit/io/vtu_writer.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/validity/corner_quality.h"
#include "tspline/validity/map_quality_bounds.h"

namespace tspline::io {

/// The map sampled on every cell with k x k sub-quads. Point data:
/// mean_ratio_jacobian (J_r = 2 det J / |J|^2), det_jacobian, scaled_jacobian,
/// parametric (xi, eta). Cell data: cell (T-mesh cell id), level.
/// `extraction`: the map's Bezier extraction, if made already (here and in
/// physical_tmesh_vtu and bezier_vtu: one for all three files of a patch).
toolkit::io::VtuMesh surface_vtu(const TSplineMap& map, int samples,
                                 const BezierExtraction* extraction = nullptr);

/// The control points as vertex cells (one per function, first), then the
/// control net as line cells: T-mesh edges between the anchors of their end
/// vertices, and each border/corner extra function joined to its vertex's
/// anchor. Point data kind (0 anchor, 1 edge extra, 2 corner extra) and
/// function (index).
toolkit::io::VtuMesh control_net_vtu(const TSplineMap& map);

/// The T-mesh as the map draws it (physical_tmesh.vtu): each cell a VTK
/// polygon through its boundary sampled through the map, k segments per
/// elementary cell edge (between consecutive vertices of the cell, hanging ones
/// included), so that curved cell edges are drawn curved; the samples are shared
/// by neighbouring cells (one point per parametric position). Cell data:
/// level; valid (1 iff the certificate proves det J > 0 on the whole cell, i.e.
/// MapCertification::cell_certified; without a certificate (`certificate` null
/// or of another mesh): det J > 0 at the cell's quadrature points, from
/// `quality`; -1 without either); certified (1 certified, 0 not, -1 no certificate);
/// det_lower_bound and relative_det_lower_bound (the certified lower bound of
/// det J over the cell's Bezier elements, parametric coordinates, and divided by
/// the element mean: certify_element with `options`; NaN without a
/// certificate); min_det_jacobian and min_mean_ratio_jacobian (at the
/// quadrature points, from `quality`; NaN without). Point data: parametric (xi,
/// eta), vertex (the T-mesh vertex, -1 for samples inside an edge), hanging,
/// boundary (on the parametric square's border).
/// \throw InputError unless 1 <= k <= 64.
toolkit::io::VtuMesh physical_tmesh_vtu(const TSplineMap& map, int k, const MapCertification* certificate,
                                        const CertificationOptions& options,
                                        const std::vector<CellMapQuality>* quality,
                                        const BezierExtraction* extraction = nullptr);

/// The same for a result: its map, certificate (if AdaptiveOptions::certify
/// was on), certification options and per-cell quality.
toolkit::io::VtuMesh physical_tmesh_vtu(const ParameterizationResult& result, int k,
                                        const BezierExtraction* extraction = nullptr);

/// Writes adapt/mesh_NNN.vtu (the iteration's T-mesh drawn through its map,
/// physical_tmesh_vtu without a certificate: `valid` from the cells' quadrature
/// points if `quality` is given) and adapt/surface_NNN.vtu for each iteration (the
/// adapt/ folder is created on the first one) and,
/// on finish(), adapt.pvd listing them (timestep = iteration; part 0 the
/// physical T-mesh, part 1 the surface).
class AdaptSeriesWriter {
 public:
  AdaptSeriesWriter(std::string out_dir, int samples,
                    toolkit::io::VtuCompression compression = toolkit::io::VtuCompression::LZ4);
  void add(int iteration, const TSplineMap& map, const std::vector<CellMapQuality>* quality = nullptr);
  void finish() const;

 private:
  std::string out_dir_;
  int samples_;
  toolkit::io::VtuCompression compression_;
  std::vector<toolkit::io::PvdEntry> entries_;
};

/// The options of the whole-map quality figures of report.json: a 26 x 26
/// sample per element next to the certified bounds, refined to a 2 % gap.
QualityBoundOptions report_quality_bound_options();

/// The whole-map quality figures (map_quality_bounds.h) as report.json writes
/// them under jacobian.whole_map: for "mean_ratio" (J_r) and "scaled_jacobian"
/// the "certified_lower_bound" (holds everywhere on the map), "sampled_min" of
/// the dense sample with "samples_per_element" and "sampled_min_at", and the
/// smallest value met by the subdivision, "attained_min" and "attained_min_at"
/// (the minimum lies between the bound and it); "certified_bounds": how the
/// bounds were computed (gap targets, depths, elements that stopped at a
/// limit, seconds). Parametric locations are of the patch holding them.
nlohmann::json whole_map_quality_json(const MapQualityBounds& bounds, const QualityBoundOptions& options);

/// The worst corner of the parameter square whose two sides are the domain's
/// boundary (corner_quality.h): "scaled_jacobian", "mean_ratio",
/// "angle_degrees", "at" (x, y), "patch" and "corner"; written as
/// jacobian.whole_map.boundary_corner: the whole-map minima cannot exceed it.
nlohmann::json boundary_corner_json(const BoundaryCornerQuality& corner);

/// One line for the command line from a whole_map_quality_json object, e.g.
/// "whole map: J_r >= 0.0354 certified (min 0.0357 in a 26 x 26 sample per
/// element), scaled Jacobian >= 0.0357 certified (sample 0.0357)", and where
/// the object has a boundary_corner, what that corner allows ("; at most 0.182
/// at a boundary corner of 10.5 degrees, which the boundary fixes").
std::string whole_map_quality_summary(const nlohmann::json& whole_map);

/// The same figures over several patches from their reports' jacobian.whole_map
/// objects (one per patch; those without the figures are skipped): the minimum of each figure with the index of its patch
/// ("certified_lower_bound_patch", "attained_min_patch", "sampled_min_patch").
nlohmann::json combine_whole_map_quality_json(const std::vector<nlohmann::json>& whole_maps);

/// Full report: the front-half report plus the T-spline (functions, control
/// points, interpolation residual), J_r min/mean, quadrature points with
/// det J <= 0, the whole-map figures (certified bounds and a dense sample,
/// whole_map_quality_json), the adaptive iterations and the per-stage times.
/// The options are not written: a front end adds its own (`tspline param`
/// and Python: every option of their table, by name).
nlohmann::json param_report(const ParameterizationResult& result, const std::string& input_path);

/// The map of a result as Bezier cells (bezier_vtu.h), with the result's
/// certificate if it was certified.
toolkit::io::VtuMesh bezier_vtu(const ParameterizationResult& result,
                                const BezierExtraction* extraction = nullptr);

/// Writes parametric_tmesh.vtu, physical_tmesh.vtu (physical_tmesh_vtu with
/// `samples` segments per cell edge), boundary.vtu, tspline.json, surface.vtu,
/// surface_bezier.vtu, control_net.vtu and report.json into out_dir (each atomically).
void write_param_outputs(const ParameterizationResult& result, const std::string& out_dir,
                         const nlohmann::json& report, int samples,
                         toolkit::io::VtuCompression compression = toolkit::io::VtuCompression::LZ4);

}  // namespace tspline::io

#pragma once
// Output files of `tspline param` beyond the front half: the T-spline file, the
// sampled map, the control net, the ParaView series of the adaptive iterations
// and the full report.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tspline/pipeline/adaptive_parameterization.h"
#include "toolkit/io/vtu_writer.h"

namespace tspline::io {

/// The map sampled on every cell with k x k sub-quads. Point data:
/// mean_ratio_jacobian (J_r = 2 det J / |J|^2), det_jacobian, scaled_jacobian,
/// parametric (xi, eta). Cell data: cell (T-mesh cell id), level.
toolkit::io::VtuMesh surface_vtu(const TSplineMap& map, int samples);

/// The control points as vertex cells (one per function, first), then the
/// control net as line cells: T-mesh edges between the anchors of their end
/// vertices, and each border/corner extra function joined to its vertex's
/// anchor. Point data kind (0 anchor, 1 edge extra, 2 corner extra) and
/// function (index).
toolkit::io::VtuMesh control_net_vtu(const TSplineMap& map);

/// Writes adapt/mesh_NNN.vtu and adapt/surface_NNN.vtu for each iteration (the
/// adapt/ folder is created on the first one) and,
/// on finish(), adapt.pvd listing them (timestep = iteration; part 0 the
/// physical T-mesh, part 1 the surface).
class AdaptSeriesWriter {
 public:
  AdaptSeriesWriter(std::string out_dir, int samples);
  void add(int iteration, const TMesh& mesh, const std::vector<Eigen::Vector2d>& x, const TSplineMap& map);
  void finish() const;

 private:
  std::string out_dir_;
  int samples_;
  std::vector<toolkit::io::PvdEntry> entries_;
};

/// Full report: the front-half report plus the T-spline (functions, control
/// points, interpolation residual), J_r min/mean, quadrature points with
/// det J <= 0, the adaptive iterations and the per-stage times (the options
/// are those stored in the result).
nlohmann::json param_report(const ParameterizationResult& result, const std::string& input_path);

/// Writes parametric_tmesh.vtu, physical_tmesh.vtu, boundary.vtu, tspline.json,
/// surface.vtu, control_net.vtu and report.json into out_dir (each atomically).
void write_param_outputs(const ParameterizationResult& result, const std::string& out_dir,
                         const nlohmann::json& report, int samples);

}  // namespace tspline::io

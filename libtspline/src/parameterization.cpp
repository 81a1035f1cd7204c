#include "tspline/parameterization.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "tspline/coons.h"
#include "tspline/corners.h"
#include "tspline/errors.h"
#include "tspline/polygon_validation.h"
#include "tspline/tmesh_submesh.h"
#include "tspline/tmesh_transfer.h"

namespace tspline {

namespace {

class StageClock {
 public:
  explicit StageClock(std::vector<StageTime>& times) : times_(times) {}
  void stop(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    times_.push_back({stage, std::chrono::duration<double>(now - start_).count()});
    start_ = now;
  }

 private:
  std::vector<StageTime>& times_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

double bbox_diagonal(const Polygon& p) {
  Eigen::Vector2d lo = p.vertices.front(), hi = p.vertices.front();
  for (const auto& v : p.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return (hi - lo).norm();
}

}  // namespace

FrontResult run_front(const Polygon& input, const ParameterizationOptions& opt) {
  auto log = [&](const std::string& s) {
    if (opt.log) opt.log(s);
  };
  if (opt.initial_level < 0 || opt.initial_level > 12)
    throw InputError("--init-level must be in [0, 12], got " + std::to_string(opt.initial_level));
  if (opt.max_level < std::max(1, opt.initial_level) || opt.max_level > TMesh::kMaxLevel)
    throw InputError("--max-level must be in [max(1, init-level), " + std::to_string(TMesh::kMaxLevel) + "]");
  if (opt.tolerance_absolute && !(*opt.tolerance_absolute > 0.0 && std::isfinite(*opt.tolerance_absolute)))
    throw InputError("--tol must be a positive finite area");
  if (!(opt.tolerance_relative > 0.0 && std::isfinite(opt.tolerance_relative)))
    throw InputError("--tol-rel must be a positive finite number");

  std::vector<StageTime> times;
  StageClock clock(times);
  Polygon poly = validate_polygon(input);
  Corners corners = opt.corners ? corners_from_file_indices(poly, *opt.corners) : choose_corners(poly);
  {
    std::ostringstream s;
    s << "boundary: " << poly.vertices.size() << " vertices, corners (file indices) "
      << poly.file_index[corners.index[0]] << "," << poly.file_index[corners.index[1]] << ","
      << poly.file_index[corners.index[2]] << "," << poly.file_index[corners.index[3]]
      << (opt.corners ? " (given)" : " (automatic)");
    log(s.str());
  }
  // A corner where the polygon is straight or reflex makes the corner cell
  // degenerate or folded whatever the interior does: reject it.
  for (int k = 0; k < 4; ++k) {
    const std::size_t n = poly.vertices.size(), i = corners.index[k];
    const Eigen::Vector2d a = poly.vertices[(i + n - 1) % n], b = poly.vertices[i], c = poly.vertices[(i + 1) % n];
    const Eigen::Vector2d u = b - a, w = c - b;
    if (!(u.x() * w.y() - u.y() * w.x() > 0.0)) {
      std::ostringstream s;
      s << "corner " << k << " (file vertex " << poly.file_index[i] << ") has an inner angle of "
        << corners.inner_angle_deg[k] << " degrees: corners must be convex vertices (inner angle below 180)";
      throw InputError(s.str());
    }
  }
  FrontResult r{BoundaryMap(std::move(poly), std::move(corners))};
  clock.stop("boundary");

  r.tolerance_is_relative = !opt.tolerance_absolute.has_value();
  const double diag = bbox_diagonal(r.boundary.polygon());
  r.tolerance_area = opt.tolerance_absolute ? *opt.tolerance_absolute : opt.tolerance_relative * diag * diag;
  r.mesh = TMesh(opt.initial_level);
  r.refinement = refine_to_boundary(r.mesh, r.boundary, {r.tolerance_area, opt.max_level});
  {
    std::ostringstream s;
    s << "t-mesh: " << r.mesh.num_cells() << " cells, " << r.mesh.num_vertices() << " vertices ("
      << r.mesh.num_hanging_vertices() << " hanging), max level " << r.mesh.max_level() << ", tolerance "
      << r.tolerance_area;
    log(s.str());
    if (r.refinement.edges_over_tolerance > 0)
      log("warning: " + std::to_string(r.refinement.edges_over_tolerance) +
          " boundary edges still exceed the tolerance at the maximum level " + std::to_string(opt.max_level));
  }
  clock.stop("tmesh");

  r.coons = coons_positions(r.mesh, r.boundary);
  r.quality_coons = mesh_quality(r.mesh, r.coons);
  log("coons: " + std::to_string(r.quality_coons.inverted_cells) + " inverted cells");
  clock.stop("coons");

  r.optimized = r.coons;
  meshopt::SmoothingOptions sopt = opt.smoothing;
  if (!sopt.progress && opt.log) {
    sopt.progress = [&](int sweep, double move, std::size_t tangled) {
      if (sweep < 5 || sweep % 50 == 0) {
        std::ostringstream s;
        s << "  sweep " << sweep << ": max relative move " << move << ", tangled nodes " << tangled;
        opt.log(s.str());
      }
    };
  }
  auto optimize = [&]() {
    const meshopt::SmoothingProblem problem = build_smoothing_problem(r.mesh, true);
    r.smoothing = meshopt::smooth(r.optimized, problem, sopt);
    r.total_sweeps += r.smoothing.sweeps;
    r.quality_optimized = mesh_quality(r.mesh, r.optimized);
    std::ostringstream s;
    s << "optimization: " << r.smoothing.sweeps << " sweeps, " << r.quality_optimized.inverted_cells
      << " inverted cells, min/mean quality " << r.quality_optimized.min_quality << " / "
      << r.quality_optimized.mean_quality;
    log(s.str());
  };
  optimize();
  // Repair: cells that stay inverted lack interior freedom (typically thin
  // features of the domain). Refine them, place the new vertices in the current
  // physical mesh, re-balance and optimize again.
  for (int round = 0; round < opt.max_repair_rounds && r.quality_optimized.inverted_cells > 0; ++round) {
    const std::vector<CellQuality> q = cell_qualities(r.mesh, r.optimized);
    const TMesh coarse = r.mesh;
    std::size_t refined = 0;
    for (int c = 0; c < static_cast<int>(q.size()); ++c) {
      if (q[c].valid || coarse.cell_level(c) >= opt.max_level) continue;
      r.mesh.refine(coarse.cell_node(c));
      ++refined;
    }
    if (refined == 0) break;
    r.mesh.balance();
    r.mesh.build_topology();
    r.optimized = transfer_positions(coarse, r.optimized, r.mesh, r.boundary);
    r.repair_refined_cells.push_back(refined);
    log("repair round " + std::to_string(round + 1) + ": refined " + std::to_string(refined) +
        " inverted cells, now " + std::to_string(r.mesh.num_cells()) + " cells");
    optimize();
  }
  clock.stop("optimization");
  r.times = std::move(times);
  return r;
}

}  // namespace tspline

// The whole parameterization in named steps; see adaptive_parameterization.h.
#include "tspline/adaptive_parameterization.h"

#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <sstream>

#include "tspline/errors.h"
#include "tspline/boundary_curve.h"
#include "tspline/mesh_quality.h"

namespace tspline {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void validate(const ParameterizationOptions& opt, const AdaptiveOptions& ad) {
  auto fail = [](const std::string& what) { throw InputError(what); };
  if (!(ad.min_jacobian > 0.0 && ad.min_jacobian <= 1.0))
    fail("--min-jacobian must be in (0, 1], got " + std::to_string(ad.min_jacobian));
  if (ad.max_adapt < 0) fail("--max-adapt must be >= 0, got " + std::to_string(ad.max_adapt));
  if (ad.max_cells < 1) fail("--max-cells must be >= 1");
  if (ad.gauss < 1 || ad.gauss > 6) fail("Gauss points per direction must be in [1, 6]");
  if (ad.dense_samples < 1 || ad.dense_samples > 64) fail("dense samples per element edge must be in [1, 64]");
  if (ad.stall_rounds < 1) fail("stall rounds must be >= 1");
  if (!(ad.min_quality_gain >= 0.0)) fail("the minimum quality gain per round must be >= 0");
  if (!(ad.max_quality_fraction > 0.0)) fail("the largest fraction of cells refined for quality must be > 0");
  if (ad.certification.max_depth < 0 || ad.certification.max_depth > 20)
    fail("--cert-depth must be in [0, 20], got " + std::to_string(ad.certification.max_depth));
  const meshopt::SmoothingOptions& s = opt.smoothing;
  if (!(s.over_relaxation >= 1.0 && s.over_relaxation < 2.0))
    fail("--omega must be in [1, 2), got " + std::to_string(s.over_relaxation));
  if (s.max_sweeps < 1) fail("--max-sweeps must be >= 1, got " + std::to_string(s.max_sweeps));
  if (!(s.relative_displacement_tolerance > 0.0) || !std::isfinite(s.relative_displacement_tolerance))
    fail("--sweep-tol must be > 0, got " + std::to_string(s.relative_displacement_tolerance));
}

// Step 2: det J at the corners of the square is the cross product of the two
// boundary tangents, decided by the border control points alone.
std::string corner_problem(const TSplineMap& map, const BoundaryMap& boundary, std::vector<Eigen::Vector2d>* at) {
  const Eigen::Vector2d uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::string first;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Matrix2d J = map.jacobian(uv[k]);
    const double scale = J.col(0).norm() * J.col(1).norm();
    if (!(J.determinant() > 1e-12 * scale)) {
      at->push_back(uv[k]);
      if (!first.empty()) continue;
      std::ostringstream s;
      s << "det J <= 0 at the corner (" << uv[k].x() << "," << uv[k].y()
        << ") of the square: the boundary curve turns by a reflex angle at polygon vertex "
        << boundary.polygon().file_index[boundary.corners().index[k]]
        << " (file numbering); no interior move can fix this, choose other --corners";
      first = s.str();
    }
  }
  return first;
}

// Step 5: the cells to refine. Not certified: the cell and a ring of its
// neighbours (the fold's cause is often next door, and refining one cell of a
// fold between two only moves it). J_r < delta at a Gauss point: the cell.
std::vector<int> cells_to_refine(const TMesh& mesh, const std::vector<CellMapQuality>& q,
                                 const MapCertification& cert, const AdaptiveOptions& ad, int max_level,
                                 std::size_t* certification_only) {
  const int nc = static_cast<int>(mesh.num_cells());
  std::vector<char> mark(nc, 0);
  *certification_only = 0;
  for (int c = 0; c < nc; ++c)
    if (!(q[c].min_mean_ratio >= ad.min_jacobian)) mark[c] = 1;
  if (ad.certify)
    for (int c = 0; c < nc; ++c) {
      if (cert.cell_certified[c]) continue;
      if (!mark[c]) ++*certification_only;
      mark[c] = 1;
      for (int v : mesh.cell_polygon(c))
        for (int n : mesh.cells_around(v))
          if (n >= 0 && !mark[n]) mark[n] = 2;
    }
  std::vector<int> out;
  for (int c = 0; c < nc; ++c)
    if (mark[c] && mesh.cell_level(c) < max_level) out.push_back(c);
  return out;
}

// The ranking of iterations: certified first, then fewest Gauss points with
// det J <= 0, then good (J_r >= delta at the Gauss points), then the highest
// min J_r over the whole map (dense sample).
struct Score {
  bool certified = false;
  std::size_t nonpositive = 0;
  bool good = false;  // J_r >= delta at every Gauss point (the paper's criterion)
  double min_mean_ratio = -1.0;
  bool better_than(const Score& o) const {
    if (certified != o.certified) return certified;
    if (nonpositive != o.nonpositive) return nonpositive < o.nonpositive;
    if (good != o.good) return good;
    return min_mean_ratio > o.min_mean_ratio + 1e-12;
  }
};

// Positions for a refined T-mesh: old vertices keep theirs, new boundary
// vertices go on the polygon, new interior vertices where the map puts them.
std::vector<Eigen::Vector2d> place_new_vertices(const TMesh& coarse, const std::vector<Eigen::Vector2d>& coarse_x,
                                                const TMesh& fine, const TSplineMap& map,
                                                const BoundaryMap& boundary) {
  std::vector<Eigen::Vector2d> x(fine.num_vertices());
  for (int v = 0; v < static_cast<int>(x.size()); ++v) {
    const int old = coarse.find_vertex(fine.vertex_ipos(v));
    if (old >= 0)
      x[v] = coarse_x[old];
    else if (fine.vertex_on_boundary(v))
      x[v] = boundary.point_at(fine.vertex_param(v));
    else
      x[v] = map.point(fine.vertex_param(v));
  }
  return x;
}

}  // namespace

ParameterizationResult run_parameterization(const Polygon& polygon, const ParameterizationOptions& opt,
                                            const AdaptiveOptions& ad, const IterationCallback& on_iteration) {
  validate(opt, ad);
  auto log = [&](const std::string& s) {
    if (opt.log) opt.log(s);
  };
  // Step 1: the front half.
  ParameterizationResult r{run_front(polygon, opt), std::nullopt, {}, {}, {}, {}, {}, 0, false, {}, {}, false, {}, 0};
  FrontResult& f = r.front;
  double t_boundary = 0.0, t_fit = 0.0, t_untangle = 0.0, t_check = 0.0, t_certify = 0.0, t_refine = 0.0;

  struct Snapshot {
    TMesh mesh = TMesh(0);
    TSplineMap map = TSplineMap(TMesh(0));
    bool optimized = false;
    FitReport fit;
    MapQualityStats quality;
    DenseMapQuality dense;
    std::vector<CellMapQuality> cells;
    MapCertification certification;
    Score score;
  };
  std::optional<Snapshot> best;
  int best_it = 0;
  int last_gain_it = 0;
  std::optional<TSplineMap> previous;
  for (int it = 0;; ++it) {
    const auto t0 = std::chrono::steady_clock::now();
    AdaptIteration rec;
    // Step 2 (first round) or the transfer of step 5.
    TSplineMap map = it == 0 ? fit_tspline(f.mesh, f.optimized, f.boundary, &rec.fit)
                             : transfer_map(*previous, f.mesh, &rec.fit);
    t_fit += seconds_since(t0);
    if (it == 0) {
      // Before the boundary curve is frozen: det J > 0 at the corners of the
      // square and a simple curve. Where the spline's tangents overshoot the
      // polygon's angle at a corner, or the curve crosses itself in a narrow
      // inlet, its border spans are too coarse: refine those cells and fit
      // again from the polygon (the curve then follows the polygon closer).
      for (int round = 0;; ++round) {
        const auto tb = std::chrono::steady_clock::now();
        std::vector<Eigen::Vector2d> at;
        r.boundary_problem = corner_problem(map, f.boundary, &at);
        const BoundaryCurveCheck simple = check_boundary_curve(map);
        r.boundary_simple = simple.simple;
        if (!simple.simple) {
          at.insert(at.end(), simple.conflicts.begin(), simple.conflicts.end());
          if (r.boundary_problem.empty()) r.boundary_problem = simple.message;
        }
        t_boundary += seconds_since(tb);
        if (r.boundary_problem.empty() || round == 8) break;
        const TMesh coarse = f.mesh;
        std::vector<char> split(coarse.num_cells(), 0);
        for (const Eigen::Vector2d& uv : at) {
          const int c = map.basis().locate(uv);
          if (coarse.cell_level(c) < opt.max_level) split[c] = 1;
        }
        std::size_t refined = 0;
        for (int c = 0; c < static_cast<int>(split.size()); ++c)
          if (split[c]) f.mesh.refine(coarse.cell_node(c)), ++refined;
        if (refined == 0) break;
        f.mesh.balance();
        f.mesh.build_topology();
        f.optimized = place_new_vertices(coarse, f.optimized, f.mesh, map, f.boundary);
        log("boundary: " + r.boundary_problem + "; refined " + std::to_string(refined) +
            " border cells there and fitted again, now " + std::to_string(f.mesh.num_cells()) + " cells");
        map = fit_tspline(f.mesh, f.optimized, f.boundary, &rec.fit);
      }
      if (!r.boundary_problem.empty()) log("boundary: " + r.boundary_problem);
      else log("boundary: the boundary curve is proven simple and turns by less than 180 degrees at the corners");
    }
    // The interpolant competes with its untangled version when it is certified
    // (the untangling energy favours the mean of 1/J_r, the threshold the minimum).
    std::optional<TSplineMap> interpolant;
    MapCertification interpolant_cert;
    if (ad.optimize_control_points && ad.certify) {
      const auto t1 = std::chrono::steady_clock::now();
      interpolant_cert = certify_map(map, ad.certification);
      if (interpolant_cert.certified_valid()) interpolant = map;
      t_certify += seconds_since(t1);
    }
    // Step 3: global untangling and smoothing.
    MapCertification cert;
    if (ad.optimize_control_points) {
      const auto t1 = std::chrono::steady_clock::now();
      MapUntanglingOptions uo = ad.untangling;
      uo.certification = ad.certification;
      const MapUntanglingReport u = untangle_map(map, uo);
      cert = u.certification;
      rec.untangling = u;
      rec.untangling.certification.failures.clear();
      rec.untangling.certification.cell_certified.clear();
      rec.control_points_optimized = u.free_points > 0;
      std::ostringstream s;
      s << "untangling: " << u.free_points << " free control points, " << u.elements << " elements, " << u.stages
        << " stages, " << u.iterations << " L-BFGS iterations, samples with det J <= 0 " << u.before.nonpositive
        << " -> " << u.after.nonpositive << ", " << (u.certified ? "certified" : "not certified") << ", "
        << u.seconds << " s";
      log(s.str());
      t_untangle += seconds_since(t1);
    } else if (ad.certify) {
      const auto t1 = std::chrono::steady_clock::now();
      cert = certify_map(map, ad.certification);
      t_certify += seconds_since(t1);
    }
    // Step 4: quality.
    const auto t2 = std::chrono::steady_clock::now();
    std::vector<CellMapQuality> cells;
    MapQualityStats quality = map_quality(map, ad.gauss, &cells);
    if (interpolant) {
      std::vector<CellMapQuality> icells;
      const MapQualityStats iq = map_quality(*interpolant, ad.gauss, &icells);
      if (!cert.certified_valid() || iq.min_mean_ratio > quality.min_mean_ratio) {
        log("kept the interpolating map: certified, and its min J_r at Gauss points " +
            std::to_string(iq.min_mean_ratio) + " is higher than the untangled map's " +
            std::to_string(quality.min_mean_ratio));
        map = std::move(*interpolant);
        cert = std::move(interpolant_cert);
        quality = iq;
        cells = std::move(icells);
        rec.control_points_optimized = false;
      }
    }
    const DenseMapQuality dense = dense_map_quality(map, ad.dense_samples);
    t_check += seconds_since(t2);
    const bool certified = !ad.certify || cert.certified_valid();
    {
      std::ostringstream s;
      s << "map (iteration " << it << "): " << f.mesh.num_cells() << " cells, " << map.basis().size()
        << " functions, J_r min " << dense.min_mean_ratio << " over the whole map (dense sample), "
        << quality.min_mean_ratio << " at Gauss points; ";
      if (ad.certify)
        s << cert.certified << " of " << cert.elements << " elements certified det J > 0"
          << (certified ? ", det J >= " + std::to_string(cert.min_relative_lower_bound) + " x element mean" : "");
      log(s.str());
    }
    rec.cells = f.mesh.num_cells();
    rec.vertices = f.mesh.num_vertices();
    rec.functions = map.basis().size();
    rec.inverted_cells = f.quality_optimized.inverted_cells;
    rec.quality = quality;
    rec.dense_quality = dense;
    rec.certification = cert;
    rec.certification.cell_certified.clear();
    rec.certification.failures.clear();
    if (on_iteration) {
      std::vector<Eigen::Vector2d> x(f.mesh.num_vertices());
      for (int v = 0; v < static_cast<int>(x.size()); ++v) x[v] = map.point(f.mesh.vertex_param(v));
      on_iteration(it, f.mesh, x, map, cells);
    }
    const Score score{certified, quality.nonpositive_det,
                      quality.nonpositive_det == 0 && quality.min_mean_ratio >= ad.min_jacobian, dense.min_mean_ratio};
    // A round that certifies, validates or makes good counts as a gain, and so
    // does one that raises the whole-map min J_r by min_quality_gain.
    if (!best || score.certified != best->score.certified || score.good != best->score.good ||
        score.nonpositive < best->score.nonpositive ||
        score.min_mean_ratio > best->score.min_mean_ratio + ad.min_quality_gain * std::abs(best->score.min_mean_ratio))
      last_gain_it = it;
    if (!best || score.better_than(best->score)) {
      best = Snapshot{f.mesh, map, rec.control_points_optimized, rec.fit, quality, dense, cells, cert, score};
      best_it = it;
    }
    // Stop, or mark the cells to refine.
    std::vector<int> marked;
    const bool good = quality.nonpositive_det == 0 && quality.min_mean_ratio >= ad.min_jacobian;
    if (good && certified) {
      r.stop_reason = "det J > 0 and J_r >= " + std::to_string(ad.min_jacobian) + " at every quadrature point" +
                      (ad.certify ? ", and det J > 0 is certified on every element" : "");
    } else if (!r.boundary_problem.empty() && certified) {
      r.stop_reason = r.boundary_problem;
    } else if (!r.boundary_problem.empty()) {
      r.stop_reason = r.boundary_problem;
    } else if (it >= ad.max_adapt) {
      r.stop_reason = "reached --max-adapt " + std::to_string(ad.max_adapt);
    } else if (certified && best->score.certified && ad.min_quality_gain > 0.0 && it > last_gain_it) {
      r.stop_reason = "certified; refining the cells with J_r < " + std::to_string(ad.min_jacobian) +
                      " raised the whole-map min J_r by less than " +
                      std::to_string(static_cast<int>(100 * ad.min_quality_gain)) +
                      "% (the rest is set by the boundary and the corners)";
    } else if (it - best_it >= ad.stall_rounds) {
      r.stop_reason = "no improvement in the last " + std::to_string(ad.stall_rounds) +
                      " rounds (the remaining distortion is not one refinement can remove)";
    } else {
      marked = cells_to_refine(f.mesh, cells, cert, ad, opt.max_level, &rec.certification_marked_cells);
      if (marked.empty())
        r.stop_reason = "the cells to refine are at --max-level";
      else if (certified && static_cast<double>(marked.size()) > ad.max_quality_fraction * f.mesh.num_cells()) {
        // J_r < delta on a large part of a certified map: anisotropy that the
        // shape and the corner choice impose, which refinement only multiplies.
        r.stop_reason = "certified; J_r < " + std::to_string(ad.min_jacobian) + " in " +
                        std::to_string(marked.size()) + " of " + std::to_string(f.mesh.num_cells()) +
                        " cells, a distortion that the shape and the corners impose (refinement does not remove it)";
        marked.clear();
      }
      else if (f.mesh.num_cells() + 3 * marked.size() > ad.max_cells) {
        r.stop_reason = "refining " + std::to_string(marked.size()) + " more cells would exceed the budget of " +
                        std::to_string(ad.max_cells) + " cells (--max-cells)";
        marked.clear();
      }
    }
    rec.refined_cells = marked.size();
    if (!marked.empty() && good) ++r.certification_rounds;
    if (marked.empty()) {
      rec.seconds = seconds_since(t0);
      r.iterations.push_back(rec);
      break;
    }
    // Step 5: refine and re-balance; the next round carries this map over.
    const auto t3 = std::chrono::steady_clock::now();
    const TMesh coarse = f.mesh;
    for (int c : marked) f.mesh.refine(coarse.cell_node(c));
    f.mesh.balance();
    f.mesh.build_topology();
    previous = std::move(map);
    log("adaptive refinement " + std::to_string(it + 1) + ": refined " + std::to_string(marked.size()) +
        " cells (J_r < " + std::to_string(ad.min_jacobian) + " or not certified, with a ring of neighbours), now " +
        std::to_string(f.mesh.num_cells()) + " cells");
    t_refine += seconds_since(t3);
    rec.seconds = seconds_since(t0);
    r.iterations.push_back(rec);
  }
  // The kept iteration; its physical T-mesh is the image of the T-mesh under the map.
  r.kept_iteration = best_it;
  f.mesh = std::move(best->mesh);
  r.map.emplace(std::move(best->map));
  r.fit = best->fit;
  r.quality = best->quality;
  r.dense_quality = best->dense;
  r.cell_quality = std::move(best->cells);
  r.certification = std::move(best->certification);
  r.control_points_optimized = best->optimized;
  f.optimized.assign(f.mesh.num_vertices(), Eigen::Vector2d::Zero());
  for (int v = 0; v < static_cast<int>(f.mesh.num_vertices()); ++v) f.optimized[v] = r.map->point(f.mesh.vertex_param(v));
  f.quality_optimized = mesh_quality(f.mesh, f.optimized);
  log("adaptive refinement stopped: " + r.stop_reason + "; kept iteration " + std::to_string(best_it));
  f.times.push_back({"boundary_curve_check", t_boundary});
  f.times.push_back({"tspline_fit", t_fit});
  f.times.push_back({"map_untangling", t_untangle});
  f.times.push_back({"jacobian_check", t_check});
  f.times.push_back({"adaptive_refinement", t_refine});
  f.times.push_back({"certification", t_certify});
  return r;
}

}  // namespace tspline

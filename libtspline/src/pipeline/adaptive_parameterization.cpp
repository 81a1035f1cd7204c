// The whole parameterization in named steps; see adaptive_parameterization.h.
#include "tspline/pipeline/adaptive_parameterization.h"

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "tspline/errors.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/validity/boundary_curve.h"
#include "tspline/tmesh/mesh_quality.h"
#include "toolkit/timing.h"

namespace tspline {

namespace {

using toolkit::seconds_since;

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
        << " (file numbering); no interior move can fix this, choose other `corners`";
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
// min J_r over the whole map (dense sample and Gauss points).
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

// The adaptive loop of steps 2-5, one method per step; run() is the loop.
class AdaptiveRun {
 public:
  AdaptiveRun(ParameterizationResult& r, const ParameterizationOptions& opt, const AdaptiveOptions& ad,
              const IterationCallback& on_iteration, std::optional<WarmStart> warm = std::nullopt)
      : r_(r), f_(r.front), opt_(opt), ad_(ad), on_iteration_(on_iteration), warm_(std::move(warm)) {}

  void run() {
    for (int it = 0;; ++it) {
      const auto t0 = std::chrono::steady_clock::now();
      round_ = it;
      AdaptIteration rec;
      // A single cell gives every corner the same corner-extra interpolation
      // point (the corner cell's centre) and each side's two edge extras the
      // same one: the interpolation (Eq. 8) has no solution.
      if (it == 0 && !warm_ && f_.mesh.num_cells() == 1)
        throw InputError("initial_level 0 left the T-mesh a single cell (the boundary needed no refinement): a "
                         "cubic T-spline map needs at least 2 x 2 cells; use initial_level >= 1");
      TSplineMap map = it > 0   ? transfer_map(*previous_, f_.mesh, &rec.fit)
                       : warm_ ? std::move(warm_->map)
                               : fit_tspline(f_.mesh, f_.optimized, f_.boundary, &rec.fit);
      t_fit_ += seconds_since(t0);
      if (it == 0) {
        freeze_boundary(map, rec);
        if (ad_.stop_when_boundary_frozen)
          if (std::string why = ad_.stop_when_boundary_frozen(map); !why.empty()) {
            log("stop", "stopped: " + why);
            throw ParameterizationStopped(why);
          }
      }
      MapCertification cert;
      std::vector<CellMapQuality> cells;
      const MapQualityStats quality = untangle_and_assess(map, rec, cert, cells);
      const std::vector<int> marked = decide(it, map, rec, quality, cert, cells);
      rec.seconds = seconds_since(t0);
      if (marked.empty()) {
        r_.iterations.push_back(rec);
        break;
      }
      refine(it, marked, std::move(map));
      rec.seconds = seconds_since(t0);
      r_.iterations.push_back(rec);
    }
    keep_best();
  }

 private:
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

  void log(const char* stage, const std::string& text) const { report_step(opt_.progress, stage, text, round_); }

  // Step 2, first round only. Before the boundary curve is frozen: det J > 0 at
  // the corners of the square and a simple curve. Where the spline's tangents
  // overshoot the polygon's angle at a corner, or the curve crosses itself in a
  // narrow inlet, its border spans are too coarse: refine those cells and fit
  // again from the polygon (the curve then follows the polygon closer).
  void freeze_boundary(TSplineMap& map, AdaptIteration& rec) {
    for (int round = 0;; ++round) {
      const auto tb = std::chrono::steady_clock::now();
      std::vector<Eigen::Vector2d> at;
      r_.boundary_problem = corner_problem(map, f_.boundary, &at);
      frozen_extraction_.emplace(map.basis());
      const BoundaryCurveCheck simple = check_boundary_curve(map, *frozen_extraction_);
      r_.boundary_simple = simple.simple;
      if (!simple.simple) {
        at.insert(at.end(), simple.conflicts.begin(), simple.conflicts.end());
        if (r_.boundary_problem.empty()) r_.boundary_problem = simple.message;
      }
      t_boundary_ += seconds_since(tb);
      if (r_.boundary_problem.empty() || round == 8) break;
      std::vector<int> split;
      for (const Eigen::Vector2d& uv : at) {
        const int c = map.basis().locate(uv);
        if (f_.mesh.cell_level(c) < opt_.max_level) split.push_back(c);
      }
      std::sort(split.begin(), split.end());
      split.erase(std::unique(split.begin(), split.end()), split.end());
      if (split.empty()) break;
      const TMesh coarse = std::exchange(f_.mesh, refine_cells(f_.mesh, split));
      f_.optimized = place_new_vertices(coarse, f_.optimized, f_.mesh, map, f_.boundary);
      log("boundary_curve", "boundary: " + r_.boundary_problem + "; refined " + std::to_string(split.size()) +
                                " border cells there and fitted again, now " + std::to_string(f_.mesh.num_cells()) +
                                " cells");
      map = fit_tspline(f_.mesh, f_.optimized, f_.boundary, &rec.fit);
    }
    if (!r_.boundary_problem.empty())
      log("boundary_curve", "boundary: " + r_.boundary_problem);
    else
      log("boundary_curve", "boundary: the boundary curve is proven simple and turns by less than 180 degrees at "
                            "the corners");
  }

  // Step 3, the global untangling, and step 4, the quality of the map kept.
  // The interpolant competes with its untangled version when it is certified
  // (the untangling energy favours the mean of 1/J_r, the threshold the minimum).
  MapQualityStats untangle_and_assess(TSplineMap& map, AdaptIteration& rec, MapCertification& cert,
                                      std::vector<CellMapQuality>& cells) {
    // One Bezier extraction for every check below: the untangling moves the
    // control points only, so the map, its interpolant and the map kept share
    // the T-mesh and the basis. In the first round, the one the boundary
    // check made of this map (freeze_boundary).
    const BezierExtraction extraction = frozen_extraction_
                                            ? std::move(*std::exchange(frozen_extraction_, std::nullopt))
                                            : BezierExtraction(map.basis());
    MapQualityStats quality;
    if (!keep_warm_start(map, extraction, rec, cert, cells, quality))
      quality = untangle_and_compare(map, extraction, rec, cert, cells);
    {
      std::ostringstream s;
      s << "map (iteration " << round_ << "): " << f_.mesh.num_cells() << " cells, " << map.basis().size()
        << " functions, J_r min " << rec.dense_quality.min_mean_ratio << " over the whole map (dense sample and Gauss points), "
        << quality.min_mean_ratio << " at Gauss points; ";
      if (ad_.certify)
        s << cert.certified << " of " << cert.elements << " elements certified det J > 0"
          << (cert.certified_valid() ? ", det J >= " + std::to_string(cert.min_relative_lower_bound) + " x element mean"
                                     : "");
      log("map", s.str());
    }
    rec.cells = f_.mesh.num_cells();
    rec.vertices = f_.mesh.num_vertices();
    rec.functions = map.basis().size();
    rec.inverted_cells = f_.quality_optimized.inverted_cells;
    rec.quality = quality;
    rec.certification = cert;
    rec.certification.cell_certified.clear();
    rec.certification.failures.clear();
    if (on_iteration_) {
      std::vector<Eigen::Vector2d> x(f_.mesh.num_vertices());
      for (int v = 0; v < static_cast<int>(x.size()); ++v) x[v] = map.point(f_.mesh.vertex_param(v));
      on_iteration_(round_, f_.mesh, x, map, cells);
    }
    return quality;
  }

  // A warm start's first round: the moved map as it is, if it is certified and
  // its whole-map J_r is no lower than the previous map's (a rigid motion, no
  // motion, or one that the map follows without loss); else it is optimized.
  bool keep_warm_start(const TSplineMap& map, const BezierExtraction& extraction, AdaptIteration& rec,
                       MapCertification& cert, std::vector<CellMapQuality>& cells, MapQualityStats& quality) {
    if (!warm_ || round_ != 0 || !ad_.certify) return false;
    const auto t1 = std::chrono::steady_clock::now();
    MapCertification wc = certify_map(extraction, map.mesh().num_cells(), map.control_points(), ad_.certification);
    t_certify_ += seconds_since(t1);
    if (!wc.certified_valid()) return false;
    const auto t2 = std::chrono::steady_clock::now();
    std::vector<CellMapQuality> wcells;
    const MapQualityStats wq = map_quality(map, extraction, ad_.gauss, &wcells);
    const DenseMapQuality dense = whole_map_quality(map, wcells, &extraction);
    t_check_ += seconds_since(t2);
    const double ref = warm_->reference_mean_ratio;
    // 1e-9: round-off (a rigid motion changes J_r by a few ulps of the control points).
    if (!(dense.min_mean_ratio >= ref - (warm_->keep_loss + 1e-9) * std::max(1e-300, std::abs(ref)))) return false;
    log("warm_start", "warm start: the moved map is certified and its whole-map J_r " +
                          std::to_string(dense.min_mean_ratio) + " is within " +
                          std::to_string(100.0 * warm_->keep_loss) + " % of the previous map's " +
                          std::to_string(ref) + "; kept as moved");
    warm_kept_ = true;
    cert = std::move(wc);
    cells = std::move(wcells);
    quality = wq;
    rec.dense_quality = dense;
    rec.control_points_optimized = false;
    return true;
  }

  // The global untangling; the interpolant (or warm start) competes with its
  // untangled version when it is certified.
  MapQualityStats untangle_and_compare(TSplineMap& map, const BezierExtraction& extraction, AdaptIteration& rec,
                                       MapCertification& cert, std::vector<CellMapQuality>& cells) {
    std::optional<TSplineMap> interpolant;
    MapCertification interpolant_cert;
    const std::size_t num_cells = map.mesh().num_cells();
    if (ad_.optimize_control_points && ad_.certify) {
      const auto t1 = std::chrono::steady_clock::now();
      interpolant_cert = certify_map(extraction, num_cells, map.control_points(), ad_.certification);
      if (interpolant_cert.certified_valid()) interpolant = map;
      t_certify_ += seconds_since(t1);
    }
    // The interpolant's figures: kept as it is where they meet keep_interpolant,
    // else compared with the optimized map's below.
    std::optional<MapQualityStats> iq;
    std::vector<CellMapQuality> icells;
    if (interpolant && ad_.keep_interpolant) {
      const auto t1 = std::chrono::steady_clock::now();
      iq = map_quality(map, extraction, ad_.gauss, &icells);
      const DenseMapQuality dense = whole_map_quality(map, icells, &extraction);
      t_check_ += seconds_since(t1);
      if (ad_.keep_interpolant->met_by(dense)) {
        std::ostringstream s;
        s << "kept the interpolating map without optimizing it: certified, and its whole-map scaled Jacobian "
          << dense.min_scaled << " and J_r " << dense.min_mean_ratio << " reach " << ad_.keep_interpolant->scaled_jacobian
          << " and " << ad_.keep_interpolant->mean_ratio;
        log("map", s.str());
        cert = std::move(interpolant_cert);
        cells = std::move(icells);
        rec.control_points_optimized = false;
        rec.dense_quality = dense;
        return *iq;
      }
    }
    if (ad_.optimize_control_points) {
      const auto t1 = std::chrono::steady_clock::now();
      const MapUntanglingReport u = untangle_map(map, untangling_options(), ad_.certification, &extraction);
      cert = u.certification;
      rec.untangling = u;
      rec.untangling.certification.failures.clear();
      rec.untangling.certification.cell_certified.clear();
      rec.control_points_optimized = u.free_points > 0;
      std::ostringstream s;
      s << "untangling: " << u.free_points << " free control points, " << u.elements << " elements, " << u.stages
        << " stages, " << u.iterations << " optimizer iterations, samples with det J <= 0 " << u.before.nonpositive
        << " -> " << u.after.nonpositive;
      if (u.newton_from_stage >= 0) s << ", Newton from stage " << u.newton_from_stage << " (L-BFGS stalled)";
      if (u.local_repairs > 0)
        s << ", " << u.local_repairs << " local repairs of folds between samples (" << u.local_repairs_certified
          << " certified the map)";
      s << ", " << (u.certified ? "certified" : "not certified") << ", " << u.seconds << " s";
      log("untangling", s.str());
      t_untangle_ += seconds_since(t1);
    } else if (ad_.certify) {
      const auto t1 = std::chrono::steady_clock::now();
      cert = certify_map(extraction, num_cells, map.control_points(), ad_.certification);
      t_certify_ += seconds_since(t1);
    }
    const auto t2 = std::chrono::steady_clock::now();
    MapQualityStats quality = map_quality(map, extraction, ad_.gauss, &cells);
    if (interpolant) {
      if (!iq) iq = map_quality(*interpolant, extraction, ad_.gauss, &icells);
      if (!cert.certified_valid() || iq->min_mean_ratio > quality.min_mean_ratio) {
        log("map", "kept the interpolating map: certified, and its min J_r at Gauss points " +
                       std::to_string(iq->min_mean_ratio) + " is higher than the untangled map's " +
                       std::to_string(quality.min_mean_ratio));
        map = std::move(*interpolant);
        cert = std::move(interpolant_cert);
        quality = *iq;
        cells = std::move(icells);
        rec.control_points_optimized = false;
      }
    }
    rec.dense_quality = whole_map_quality(map, cells, &extraction);
    t_check_ += seconds_since(t2);
    return quality;
  }

  // The whole-map minimum is over every point looked at: the dense sample, and
  // where a Gauss point is worse, that (at its cell's centre).
  DenseMapQuality whole_map_quality(const TSplineMap& map, const std::vector<CellMapQuality>& cells,
                                    const BezierExtraction* extraction = nullptr) const {
    DenseMapQuality q = extraction ? dense_map_quality(*extraction, map.control_points(), ad_.dense_samples)
                                   : dense_map_quality(map, ad_.dense_samples);
    for (int c = 0; c < static_cast<int>(cells.size()); ++c) {
      if (cells[c].min_mean_ratio < q.min_mean_ratio) {
        q.min_mean_ratio = cells[c].min_mean_ratio;
        q.worst_at = 0.5 * (f_.mesh.cell_min(c) + f_.mesh.cell_max(c));
      }
      q.min_scaled = std::min(q.min_scaled, cells[c].min_scaled);
    }
    return q;
  }

  // More quality stages for the map kept where it is certified but poor
  // (AdaptiveOptions::polish_below); kept only if its whole-map J_r rises.
  void polish() {
    Snapshot& b = *best_;
    if (!ad_.optimize_control_points || ad_.polish_stages <= 0 || b.dense.min_mean_ratio >= ad_.polish_below) return;
    // A warm start's optimization already ran at the polish power (untangling_options).
    if (warm_ && warm_->reference_mean_ratio < ad_.polish_below) return;
    if (ad_.certify && !b.certification.certified_valid()) return;
    if (!ad_.polish_skip.met_by(b.dense)) {
      std::ostringstream s;
      s << "polish: skipped, whole-map scaled Jacobian " << b.dense.min_scaled << " and J_r " << b.dense.min_mean_ratio
        << " (below " << ad_.polish_skip.scaled_jacobian << " or " << ad_.polish_skip.mean_ratio << ")";
      log("polish", s.str());
      return;
    }
    const auto t1 = std::chrono::steady_clock::now();
    MapUntanglingOptions uo = untangling_options();
    uo.max_quality_stages = ad_.polish_stages;
    uo.quality_power = ad_.polish_power;
    TSplineMap map = b.map;
    const BezierExtraction extraction(map.basis());  // for the untangling and the checks
    const MapUntanglingReport u = untangle_map(map, uo, ad_.certification, &extraction);
    t_untangle_ += seconds_since(t1);
    if (ad_.certify && !u.certified) return;
    const auto t2 = std::chrono::steady_clock::now();
    std::vector<CellMapQuality> cells;
    const MapQualityStats quality = map_quality(map, extraction, ad_.gauss, &cells);
    const DenseMapQuality dense = whole_map_quality(map, cells, &extraction);
    t_check_ += seconds_since(t2);
    std::ostringstream s;
    s << "polish: " << u.stages << " more quality stages, whole-map J_r " << b.dense.min_mean_ratio << " -> "
      << dense.min_mean_ratio << ", scaled Jacobian " << b.dense.min_scaled << " -> " << dense.min_scaled;
    if (!(dense.min_mean_ratio > b.dense.min_mean_ratio && quality.nonpositive_det == 0)) {
      log("polish", s.str() + ": not kept");
      return;
    }
    log("polish", s.str());
    b.map = std::move(map);
    b.quality = quality;
    b.dense = dense;
    b.cells = std::move(cells);
    if (ad_.certify) b.certification = u.certification;
    b.optimized = true;
  }

  MapUntanglingOptions untangling_options() const {
    MapUntanglingOptions uo = ad_.untangling;
    // A warm start from a polished map (whole-map J_r below polish_below) is
    // near the minimum of the polish energy: optimize that energy, not the
    // default one (whose minimum has the lower min J_r) followed by the polish.
    if (warm_ && warm_->reference_mean_ratio < ad_.polish_below) uo.quality_power = ad_.polish_power;
    if (warm_) uo.max_quality_stages = std::min(uo.max_quality_stages, warm_->quality_stages);
    if (!uo.progress && opt_.progress)
      uo.progress = [this](const UntanglingProgress& p) {
        ProgressEvent e;
        e.kind = ProgressEvent::Kind::Untangling;
        e.stage = "untangling";
        e.iteration = round_;
        e.count = p.stage;
        e.value = p.eps;
        e.defects = p.samples.nonpositive;
        std::ostringstream s;
        s << "untangling stage " << p.stage + 1 << ": eps " << p.eps << ", samples with det J <= 0 "
          << p.samples.nonpositive << ", " << p.iterations << " optimizer iterations"
          << (p.certified ? ", certified" : "");
        e.text = s.str();
        opt_.progress(e);
      };
    return uo;
  }

  // Ranks this round against the best so far, then the stop rules; returns the
  // cells to refine (none: stop, with r_.stop_reason set).
  std::vector<int> decide(int it, const TSplineMap& map, AdaptIteration& rec, const MapQualityStats& quality,
                          const MapCertification& cert, const std::vector<CellMapQuality>& cells) {
    const bool certified = !ad_.certify || cert.certified_valid();
    const bool good = quality.nonpositive_det == 0 && quality.min_mean_ratio >= ad_.min_jacobian;
    const Score score{certified, quality.nonpositive_det, good, rec.dense_quality.min_mean_ratio};
    // A round that certifies, validates or makes good counts as a gain, and so
    // does one that raises the whole-map min J_r by min_quality_gain.
    if (!best_ || score.certified != best_->score.certified || score.good != best_->score.good ||
        score.nonpositive < best_->score.nonpositive ||
        score.min_mean_ratio > best_->score.min_mean_ratio + ad_.min_quality_gain * std::abs(best_->score.min_mean_ratio))
      last_gain_it_ = it;
    if (!best_ || score.better_than(best_->score)) {
      best_ = Snapshot{f_.mesh, map, rec.control_points_optimized, rec.fit, quality, rec.dense_quality, cells, cert,
                       score};
      best_it_ = it;
    }
    std::vector<int> marked;
    std::string& why = r_.stop_reason;
    if (good && certified) {
      why = "det J > 0 and J_r >= " + std::to_string(ad_.min_jacobian) + " at every quadrature point" +
            (ad_.certify ? ", and det J > 0 is certified on every element" : "");
    } else if (!r_.boundary_problem.empty()) {
      why = r_.boundary_problem;
    } else if (warm_ && it == 0 && certified &&
               rec.dense_quality.min_mean_ratio >= warm_->keep_fraction * warm_->reference_mean_ratio) {
      why = "warm start: certified, whole-map J_r " + std::to_string(rec.dense_quality.min_mean_ratio) +
            " against the previous map's " + std::to_string(warm_->reference_mean_ratio);
    } else if (it >= ad_.max_adapt) {
      why = "reached `max_adapt` " + std::to_string(ad_.max_adapt);
    } else if (certified && best_->score.certified && ad_.min_quality_gain > 0.0 && it > last_gain_it_) {
      why = "certified; refining the cells with J_r < " + std::to_string(ad_.min_jacobian) +
            " raised the whole-map min J_r by less than " +
            std::to_string(static_cast<int>(100 * ad_.min_quality_gain)) +
            "% (the rest is set by the boundary and the corners)";
    } else if (it - best_it_ >= ad_.stall_rounds) {
      why = "no improvement in the last " + std::to_string(ad_.stall_rounds) +
            " rounds (the remaining distortion is not one refinement can remove)";
    } else {
      marked = cells_to_refine(f_.mesh, cells, cert, ad_, opt_.max_level, &rec.certification_marked_cells);
      if (marked.empty()) {
        why = "the cells to refine are at `max_level`";
      } else if (certified && static_cast<double>(marked.size()) > ad_.max_quality_fraction * f_.mesh.num_cells()) {
        // J_r < delta on a large part of a certified map: anisotropy that the
        // shape and the corner choice impose, which refinement only multiplies.
        why = "certified; J_r < " + std::to_string(ad_.min_jacobian) + " in " + std::to_string(marked.size()) +
              " of " + std::to_string(f_.mesh.num_cells()) +
              " cells, a distortion that the shape and the corners impose (refinement does not remove it)";
        marked.clear();
      } else if (f_.mesh.num_cells() + 3 * marked.size() > opt_.max_cells) {
        why = "refining " + std::to_string(marked.size()) + " more cells would exceed the budget of " +
              std::to_string(opt_.max_cells) + " cells (`max_cells`)";
        marked.clear();
      }
    }
    rec.refined_cells = marked.size();
    if (!marked.empty() && good) ++r_.certification_rounds;
    return marked;
  }

  // Step 5: refine and re-balance; the next round carries this map over.
  void refine(int it, const std::vector<int>& marked, TSplineMap map) {
    const auto t3 = std::chrono::steady_clock::now();
    f_.mesh = refine_cells(f_.mesh, marked);
    previous_ = std::move(map);
    log("refinement", "adaptive refinement " + std::to_string(it + 1) + ": refined " + std::to_string(marked.size()) +
                          " cells (J_r < " + std::to_string(ad_.min_jacobian) +
                          " or not certified, with a ring of neighbours), now " + std::to_string(f_.mesh.num_cells()) +
                          " cells");
    t_refine_ += seconds_since(t3);
  }

  // The kept iteration; its physical T-mesh is the image of the T-mesh under the map.
  void keep_best() {
    polish();
    r_.kept_iteration = best_it_;
    f_.mesh = std::move(best_->mesh);
    r_.map.emplace(std::move(best_->map));
    r_.fit = best_->fit;
    r_.quality = best_->quality;
    r_.dense_quality = best_->dense;
    r_.cell_quality = std::move(best_->cells);
    r_.certification = std::move(best_->certification);
    r_.control_points_optimized = best_->optimized;
    f_.optimized.assign(f_.mesh.num_vertices(), Eigen::Vector2d::Zero());
    for (int v = 0; v < static_cast<int>(f_.mesh.num_vertices()); ++v)
      f_.optimized[v] = r_.map->point(f_.mesh.vertex_param(v));
    f_.quality_optimized = mesh_quality(f_.mesh, f_.optimized);
    round_ = -1;
    log("stop", "adaptive refinement stopped: " + r_.stop_reason + "; kept iteration " + std::to_string(best_it_));
    f_.times.push_back({"boundary_curve_check", t_boundary_});
    f_.times.push_back({"tspline_fit", t_fit_});
    f_.times.push_back({"map_untangling", t_untangle_});
    f_.times.push_back({"jacobian_check", t_check_});
    f_.times.push_back({"adaptive_refinement", t_refine_});
    f_.times.push_back({"certification", t_certify_});
  }

  ParameterizationResult& r_;
  FrontResult& f_;
  const ParameterizationOptions& opt_;
  const AdaptiveOptions& ad_;
  const IterationCallback& on_iteration_;
  int round_ = -1;  // the adaptive round that progress events belong to
  std::optional<Snapshot> best_;
  int best_it_ = 0;
  int last_gain_it_ = 0;
  std::optional<TSplineMap> previous_;
  std::optional<WarmStart> warm_;
  // The Bezier extraction of the map freeze_boundary checked last, until
  // untangle_and_assess takes it (the first round's map, unchanged in between).
  std::optional<BezierExtraction> frozen_extraction_;
  bool warm_kept_ = false;  // the warm start was kept as moved (no optimization)
  double t_boundary_ = 0.0, t_fit_ = 0.0, t_untangle_ = 0.0, t_check_ = 0.0, t_certify_ = 0.0, t_refine_ = 0.0;
};

}  // namespace

ParameterizationResult run_parameterization(const Polygon& polygon, const ParameterizationOptions& opt,
                                            const AdaptiveOptions& ad, const IterationCallback& on_iteration) {
  validate_options(ad);  // before the front half, which validates its own options
  ParameterizationResult r(run_front(polygon, opt));  // step 1
  r.options = opt;
  r.options.progress = nullptr;
  r.options.smoothing.progress = nullptr;
  r.adaptive = ad;
  r.adaptive.untangling.progress = nullptr;
  AdaptiveRun(r, opt, ad, on_iteration).run();  // steps 2-5
  return r;
}

ParameterizationResult run_parameterization_from(FrontResult front, WarmStart warm,
                                                 const ParameterizationOptions& opt, const AdaptiveOptions& ad,
                                                 const IterationCallback& on_iteration) {
  validate_options(ad);
  ParameterizationResult r(std::move(front));
  r.options = opt;
  r.options.progress = nullptr;
  r.options.smoothing.progress = nullptr;
  r.adaptive = ad;
  r.adaptive.untangling.progress = nullptr;
  AdaptiveRun(r, opt, ad, on_iteration, std::move(warm)).run();
  return r;
}

}  // namespace tspline

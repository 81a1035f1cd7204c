// `tspline check`: certify det J > 0 on every Bezier element of the map of a
// T-spline file (map_certification.h). Prints a summary and the elements that
// are not certified; exit 0 if certified valid, 3 if not.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "commands.h"
#include "tspline/errors.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/param_output.h"
#include "tspline/io/tspline_file.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/corner_quality.h"
#include "tspline/validity/map_quality.h"
#include "tspline/validity/map_quality_bounds.h"

namespace tspline_app {

namespace {

struct CheckArgs {
  std::string file;
  int depth = tspline::CertificationOptions{}.max_depth;
  std::size_t max_listed = 20;
};

// Prints the certification of one map; true if certified valid.
bool check_map(const tspline::io::LoadedTSpline& t, const CheckArgs& args) {
  tspline::CertificationOptions opt;
  opt.max_depth = args.depth;
  const tspline::MapCertification c = tspline::certify_map(t.map, opt);
  const std::size_t failed_cells =
      static_cast<std::size_t>(std::count(c.cell_certified.begin(), c.cell_certified.end(), 0));
  std::printf("cells: %zu\n", t.map.mesh().num_cells());
  std::printf("bezier elements: %zu\n", c.elements);
  std::printf(
      "certified: %zu of %zu elements (det J > 0 on the whole element; subdivision depth limit %d, used "
      "%d)\n",
      c.certified, c.elements, args.depth, c.max_depth_used);
  std::printf("det J > 0 proven false: %zu elements\n", c.invalid);
  std::printf("undecided at the depth limit: %zu elements\n", c.undecided);
  if (std::isfinite(c.min_relative_lower_bound))
    std::printf("certified lower bound of det J / element mean: %.6g\n", c.min_relative_lower_bound);
  else
    std::printf("certified lower bound of det J / element mean: none (an element has mean det J <= 0)\n");
  std::printf("certified lower bound of det J: %.6g\n", c.min_det_lower_bound);
  const tspline::DenseMapQuality dq = tspline::dense_map_quality(t.map);
  const tspline::MapQualityStats gq = tspline::map_quality(t.map, 4);
  const tspline::QualityBoundOptions qo = tspline::io::report_quality_bound_options();
  const tspline::MapQualityBounds qb = tspline::certified_map_quality(t.map, qo);
  std::printf("J_r >= %.6g on the whole map (certified lower bound; J_r %.6g attained at (u, v) = (%.6g, %.6g))\n",
              qb.mean_ratio.lower_bound, qb.mean_ratio.attained, qb.mean_ratio.attained_at.x(),
              qb.mean_ratio.attained_at.y());
  std::printf("scaled Jacobian >= %.6g on the whole map (certified lower bound; min %.6g in a dense sample of %d x %d "
              "points per element)\n",
              qb.scaled.lower_bound, qb.scaled.sampled, qo.samples_per_edge + 1, qo.samples_per_edge + 1);
  if (const auto corner = tspline::worst_boundary_corner(t.map))
    std::printf("scaled Jacobian at the worst corner of the square, which the boundary fixes: %.6g (J_r %.6g; "
                "interior angle %.1f degrees at (x, y) = (%.6g, %.6g)): no whole-map minimum can exceed it\n",
                corner->scaled_jacobian, corner->mean_ratio, corner->angle_degrees, corner->at.x(), corner->at.y());
  std::printf("J_r min over a dense sample of %d x %d points per element: %.6g\n", qo.samples_per_edge + 1,
              qo.samples_per_edge + 1, qb.mean_ratio.sampled);
  std::printf("J_r min over the samples below: %.6g (the smaller of the two)\n",
              std::min(dq.min_mean_ratio, gq.min_mean_ratio));
  std::printf("J_r min over a dense sample: %.6g (%d x %d points per element, corners included; at (u, v) = (%.6g, "
              "%.6g))\n",
              dq.min_mean_ratio, dq.samples_per_edge + 1, dq.samples_per_edge + 1, dq.worst_at.x(), dq.worst_at.y());
  std::printf("J_r min at 4 x 4 Gauss points per cell: %.6g\n", gq.min_mean_ratio);
  std::printf("seconds: %.3f\n", c.seconds);
  if (c.certified_valid()) {
    std::printf("result: certified valid (det J > 0 everywhere)\n");
    return true;
  }
  std::printf("result: NOT certified valid (%zu cells affected)\n", failed_cells);
  std::size_t listed = 0;
  for (const tspline::CertificationFailure& f : c.failures) {
    if (listed++ == args.max_listed) {
      std::printf("... and %zu more elements not certified\n", c.failures.size() - args.max_listed);
      break;
    }
    std::printf("cell %d element [%.17g, %.17g] x [%.17g, %.17g]: ", f.cell, f.lo.x(), f.hi.x(), f.lo.y(),
                f.hi.y());
    if (f.certificate.status == tspline::ElementStatus::Invalid)
      std::printf("det J = %.6g < 0 at (u, v) = (%.17g, %.17g)\n", f.certificate.negative_det,
                  f.certificate.negative_at.x(), f.certificate.negative_at.y());
    else
      std::printf("undecided at depth %d (det J >= %.6g proven, no negative value found)\n",
                  f.certificate.depth, f.certificate.det_lower_bound);
  }
  std::fflush(stdout);
  std::cerr << "tspline: error: the map is not certified valid: " << c.elements - c.certified << " of "
            << c.elements << " elements not certified (" << c.invalid << " with det J < 0 proven, "
            << c.undecided << " undecided)" << std::endl;
  return false;
}

int run_check(const CheckArgs& args) {
  const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(args.file);
  if (maps.version == 1) return check_map(maps.patches.front(), args) ? 0 : 3;
  // Multi-patch: every patch, then the interfaces (the two images of each cut).
  bool all = true;
  for (std::size_t p = 0; p < maps.patches.size(); ++p) {
    std::printf("patch %zu:\n", p);
    all = check_map(maps.patches[p], args) && all;
  }
  double gap = 0.0;
  for (const tspline::Interface& f : maps.interfaces)
    gap = std::max(gap, tspline::interface_gap(maps.patches[f.patch_a].map, f.side_a, maps.patches[f.patch_b].map,
                                               f.side_b));
  std::printf("interfaces: %zu, largest gap between the two images of a cut: %.6g\n", maps.interfaces.size(), gap);
  std::printf("result: %s\n", all ? "every patch certified valid" : "NOT every patch certified valid");
  return all ? 0 : 3;
}

}  // namespace

void add_check_command(CLI::App& app, CommandAction& action) {
  const Subcommand<CheckArgs> check_sub = add_subcommand<CheckArgs>(
      app, "check",
      "Certify that det J > 0 on the whole domain of a T-spline file, not only at sample points: on every "
      "Bezier "
      "element (T-mesh cell split by the knot lines of its functions) the numerator of det J is written as a "
      "polynomial of bidegree (8,8) in the Bernstein basis and proved positive by its coefficients, with de "
      "Casteljau subdivision where needed. Exit 0 if certified valid, 3 if not (the elements and parametric "
      "points where det J < 0 are listed)");
  CLI::App* const check = check_sub.cmd;
  const std::shared_ptr<CheckArgs> args = check_sub.args;
  add_tspline_file_argument(*check, args->file);
  check
      ->add_option("--depth", args->depth,
                   "Subdivision levels at most per element (each halves both directions); an element neither "
                   "proved positive nor found negative there is 'undecided' (not certified)")
      ->check(CLI::Range(0, 20))
      ->capture_default_str();
  check
      ->add_option("--max-listed", args->max_listed, "List at most this many elements that are not certified")
      ->capture_default_str();
  run_when_parsed(check, args, action, run_check);
}

}  // namespace tspline_app

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
#include "tspline/multipatch/map_check.h"
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
  bool per_patch = false;
  int worst = 5;
};

// The elements of one patch that are not certified, at most `max_listed`.
void print_failures(const tspline::MapCertification& c, std::size_t max_listed) {
  std::size_t listed = 0;
  for (const tspline::CertificationFailure& f : c.failures) {
    if (listed++ == max_listed) {
      std::printf("... and %zu more elements not certified\n", c.failures.size() - max_listed);
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
}

// The figures of one patch (the map of a single-patch file), as they always were.
void print_patch(const tspline::PatchCheck& p, const tspline::MapCheckOptions& o, std::size_t max_listed) {
  const tspline::MapCertification& c = p.certification;
  std::printf("cells: %zu\n", p.cells);
  std::printf("bezier elements: %zu\n", c.elements);
  std::printf(
      "certified: %zu of %zu elements (det J > 0 on the whole element; subdivision depth limit %d, used "
      "%d)\n",
      c.certified, c.elements, o.certification.max_depth, c.max_depth_used);
  std::printf("det J > 0 proven false: %zu elements\n", c.invalid);
  std::printf("undecided at the depth limit: %zu elements\n", c.undecided);
  if (std::isfinite(c.min_relative_lower_bound))
    std::printf("certified lower bound of det J / element mean: %.6g\n", c.min_relative_lower_bound);
  else
    std::printf("certified lower bound of det J / element mean: none (an element has mean det J <= 0)\n");
  std::printf("certified lower bound of det J: %.6g\n", c.min_det_lower_bound);
  const tspline::MapQualityBounds& qb = p.quality;
  const int k = o.quality.samples_per_edge + 1;
  std::printf("J_r >= %.6g on the whole map (certified lower bound; J_r %.6g attained at (u, v) = (%.6g, %.6g))\n",
              qb.mean_ratio.lower_bound, qb.mean_ratio.attained, qb.mean_ratio.attained_at.x(),
              qb.mean_ratio.attained_at.y());
  std::printf("scaled Jacobian >= %.6g on the whole map (certified lower bound; min %.6g in a dense sample of %d x %d "
              "points per element)\n",
              qb.scaled.lower_bound, qb.scaled.sampled, k, k);
  if (p.corner)
    std::printf("scaled Jacobian at the worst corner of the square, which the boundary fixes: %.6g (J_r %.6g; "
                "interior angle %.1f degrees at (x, y) = (%.6g, %.6g)): no whole-map minimum can exceed it\n",
                p.corner->scaled_jacobian, p.corner->mean_ratio, p.corner->angle_degrees, p.corner->at.x(),
                p.corner->at.y());
  std::printf("J_r min over a dense sample of %d x %d points per element: %.6g\n", k, k, qb.mean_ratio.sampled);
  std::printf("J_r min over the samples below: %.6g (the smaller of the two)\n",
              std::min(p.dense.min_mean_ratio, p.gauss.min_mean_ratio));
  std::printf("J_r min over a dense sample: %.6g (%d x %d points per element, corners included; at (u, v) = (%.6g, "
              "%.6g))\n",
              p.dense.min_mean_ratio, p.dense.samples_per_edge + 1, p.dense.samples_per_edge + 1,
              p.dense.worst_at.x(), p.dense.worst_at.y());
  std::printf("J_r min at %d x %d Gauss points per cell: %.6g\n", o.gauss, o.gauss, p.gauss.min_mean_ratio);
  std::printf("seconds: %.3f\n", c.seconds);
  if (c.certified_valid()) {
    std::printf("result: certified valid (det J > 0 everywhere)\n");
    return;
  }
  std::size_t failed_cells = 0;
  for (const char ok : c.cell_certified) failed_cells += ok ? 0 : 1;
  std::printf("result: NOT certified valid (%zu cells affected)\n", failed_cells);
  print_failures(c, max_listed);
}

// A map of several patches: the whole map first (the minima over every
// patch), the worst patches, the patches not certified with their elements;
// every patch's own figures with --per-patch.
void print_whole_map(const tspline::MapCheck& m, const tspline::MapCheckOptions& o, const CheckArgs& args) {
  const tspline::MapQualityBounds& qb = m.quality;
  const int k = o.quality.samples_per_edge + 1;
  std::printf("patches: %zu\n", m.patches.size());
  std::printf("cells: %zu\n", m.cells);
  std::printf("bezier elements: %zu\n", m.elements);
  std::printf("certified: %zu of %zu elements, %zu of %zu patches (det J > 0 on the whole element; subdivision "
              "depth limit %d, used %d)\n",
              m.certified, m.elements, m.certified_patches, m.patches.size(), o.certification.max_depth,
              m.max_depth_used);
  std::printf("det J > 0 proven false: %zu elements\n", m.invalid);
  std::printf("undecided at the depth limit: %zu elements\n", m.undecided);
  if (std::isfinite(m.min_relative_det_lower_bound))
    std::printf("certified lower bound of det J / element mean: %.6g (over every patch)\n",
                m.min_relative_det_lower_bound);
  else
    std::printf("certified lower bound of det J / element mean: none (an element has mean det J <= 0)\n");
  // Element indices count through the patches: the patch holding one.
  auto patch_of = [&](std::size_t element) {
    std::size_t p = 0;
    for (std::size_t first = 0; p < m.patches.size(); ++p) {
      first += m.patches[p].certification.elements;
      if (element < first) break;
    }
    return p;
  };
  std::printf("whole map: J_r >= %.6g (certified lower bound over every patch; J_r %.6g attained in patch %zu at "
              "(u, v) = (%.6g, %.6g))\n",
              qb.mean_ratio.lower_bound, qb.mean_ratio.attained, patch_of(qb.mean_ratio.attained_element),
              qb.mean_ratio.attained_at.x(), qb.mean_ratio.attained_at.y());
  std::printf("whole map: scaled Jacobian >= %.6g (certified lower bound; min %.6g in a dense sample of %d x %d "
              "points per element, patch %zu)\n",
              qb.scaled.lower_bound, qb.scaled.sampled, k, k, patch_of(qb.scaled.sampled_element));
  std::printf("whole map: J_r min over a dense sample of %d x %d points per element: %.6g\n", k, k,
              qb.mean_ratio.sampled);
  if (m.corner)
    std::printf("scaled Jacobian at the worst patch corner, which the layout fixes: %.6g (J_r %.6g; interior angle "
                "%.1f degrees in patch %zu at (x, y) = (%.6g, %.6g)): no whole-map minimum can exceed it\n",
                m.corner->scaled_jacobian, m.corner->mean_ratio, m.corner->angle_degrees, m.corner_patch,
                m.corner->at.x(), m.corner->at.y());
  std::printf("J_r min over a dense sample: %.6g (%d x %d points per element); at %d x %d Gauss points per cell: "
              "%.6g\n",
              m.min_dense_mean_ratio, o.dense_samples + 1, o.dense_samples + 1, o.gauss, o.gauss,
              m.min_gauss_mean_ratio);
  // The worst patches by their certified J_r bound.
  std::vector<std::size_t> order(m.patches.size());
  for (std::size_t p = 0; p < order.size(); ++p) order[p] = p;
  const std::size_t shown = std::min(static_cast<std::size_t>(args.worst), order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown), order.end(),
                    [&](std::size_t a, std::size_t b) {
                      const double fa = m.patches[a].quality.mean_ratio.lower_bound;
                      const double fb = m.patches[b].quality.mean_ratio.lower_bound;
                      return fa < fb || (fa == fb && a < b);
                    });
  if (shown > 0) std::printf("worst patches (by the certified J_r bound):\n");
  for (std::size_t i = 0; i < shown; ++i) {
    const tspline::PatchCheck& p = m.patches[order[i]];
    std::printf("  patch %zu: %zu cells, J_r >= %.6g, scaled Jacobian >= %.6g, det J >= %.6g x element mean%s\n",
                order[i], p.cells, p.quality.mean_ratio.lower_bound, p.quality.scaled.lower_bound,
                p.certification.min_relative_lower_bound, p.certification.certified_valid() ? "" : ", NOT certified");
  }
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    const tspline::MapCertification& c = m.patches[p].certification;
    if (c.certified_valid()) continue;
    std::printf("patch %zu: NOT certified valid (%zu of %zu elements certified)\n", p, c.certified, c.elements);
    print_failures(c, args.max_listed);
  }
}

int run_check(const CheckArgs& args) {
  const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(args.file);
  std::vector<const tspline::TSplineMap*> patches;
  for (const tspline::io::LoadedTSpline& p : maps.patches) patches.push_back(&p.map);
  tspline::MapCheckOptions o;
  o.certification.max_depth = args.depth;
  o.quality = tspline::io::report_quality_bound_options();
  const tspline::MapCheck m = tspline::check_map(patches, maps.interfaces, o);
  if (maps.version == 1 || args.per_patch) {
    for (std::size_t p = 0; p < m.patches.size(); ++p) {
      if (maps.version != 1) std::printf("patch %zu:\n", p);
      print_patch(m.patches[p], o, args.max_listed);
    }
  }
  if (maps.version != 1) {
    if (args.per_patch) std::printf("whole map:\n");
    print_whole_map(m, o, args);
    std::printf("interfaces: %zu, largest gap between the two images of a cut: %.6g\n", maps.interfaces.size(),
                m.max_interface_gap);
    std::printf("result: %s\n", m.certified_valid() ? "every patch certified valid" : "NOT every patch certified valid");
  }
  std::fflush(stdout);
  if (m.certified_valid()) return 0;
  std::cerr << "tspline: error: the map is not certified valid: " << m.elements - m.certified << " of " << m.elements
            << " elements not certified (" << m.invalid << " with det J < 0 proven, " << m.undecided << " undecided)"
            << std::endl;
  return 3;
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
      ->add_option("--max-listed", args->max_listed,
                   "List at most this many elements that are not certified (per patch)")
      ->capture_default_str();
  check->add_flag("--per-patch", args->per_patch,
                  "A map of several patches: every patch's own figures too (by default the whole map's, the worst "
                  "patches and the patches not certified)");
  check->add_option("--worst", args->worst, "A map of several patches: list this many worst patches (by J_r)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  run_when_parsed(check, args, action, run_check);
}

}  // namespace tspline_app

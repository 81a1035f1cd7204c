// IGA Poisson on the multi-patch map of the plate with a hole: C0 coupling
// across the cuts, optimal rates on uniform refinement.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "tspline/boundary/border_knots.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/analysis/multipatch_poisson.h"

namespace {

tspline::MultiPatchResult plate_map() {
  const tspline::io::DomainInput in =
      tspline::io::read_domain(std::string(TSPLINE_TEST_DATA_DIR) + "/holes/plate_with_hole.txt");
  return tspline::run_multipatch_parameterization(tspline::Domain{in.outer, in.holes}, std::nullopt, {}, {});
}

// u = sin(0.7 x + 0.3) cos(0.5 y): -Laplace u = (0.49 + 0.25) u.
tspline::PoissonProblem smooth_problem() {
  tspline::PoissonProblem pb;
  pb.exact = [](double x, double y) { return std::sin(0.7 * x + 0.3) * std::cos(0.5 * y); };
  pb.exact_gradient = [](double x, double y) {
    return Eigen::Vector2d(0.7 * std::cos(0.7 * x + 0.3) * std::cos(0.5 * y),
                           -0.5 * std::sin(0.7 * x + 0.3) * std::sin(0.5 * y));
  };
  pb.f = [](double x, double y) { return 0.74 * std::sin(0.7 * x + 0.3) * std::cos(0.5 * y); };
  pb.g = pb.exact;
  return pb;
}

std::vector<tspline::TMesh> refined(const std::vector<tspline::TMesh>& meshes) {
  std::vector<tspline::TMesh> out;
  for (const tspline::TMesh& m : meshes) {
    std::vector<int> all(m.num_cells());
    for (int c = 0; c < static_cast<int>(all.size()); ++c) all[c] = c;
    out.push_back(tspline::refine_cells(m, all));
  }
  return out;
}

}  // namespace

TEST_SUITE("holes_poisson") {
  TEST_CASE("plate with a hole, uniform refinement: C0 across the cuts, rates 4 (L2) and 3 (H1)") {
    const tspline::MultiPatchResult R = plate_map();
    std::vector<const tspline::TSplineMap*> maps;
    std::vector<tspline::TMesh> meshes;
    for (const auto& r : R.patches) maps.push_back(&*r.map), meshes.push_back(r.map->mesh());
    const tspline::PoissonProblem pb = smooth_problem();
    std::vector<double> l2, h1;
    for (int step = 0; step < 4; ++step) {
      const tspline::MultiPatchSolution S = tspline::solve_multipatch_poisson(maps, R.layout.interfaces, meshes, pb);
      // One unknown per glued pair: fewer unknowns than functions.
      std::size_t functions = 0;
      for (const auto& sp : S.spaces) functions += sp->num_dofs();
      CHECK(S.unknowns < functions);
      CHECK(S.glued_pairs > 0);
      CHECK(tspline::multipatch_interface_jump(R.layout.interfaces, S) < 1e-12);
      const tspline::PoissonErrors e = tspline::multipatch_errors(maps, S, pb);
      MESSAGE("step " << step << ": unknowns " << S.unknowns << ", L2 " << e.l2 << ", H1 " << e.h1);
      l2.push_back(e.l2), h1.push_back(e.h1);
      if (step < 3) meshes = refined(meshes);
    }
    const double rate_l2 = std::log2(l2[2] / l2[3]), rate_h1 = std::log2(h1[2] / h1[3]);
    MESSAGE("rates: L2 " << rate_l2 << ", H1 " << rate_h1);
    CHECK(std::abs(rate_l2 - 4) <= 0.3);
    CHECK(std::abs(rate_h1 - 3) <= 0.3);
  }

  TEST_CASE("an analysis space refined on one side of a cut only is not conforming: refused") {
    const tspline::MultiPatchResult R = plate_map();
    std::vector<const tspline::TSplineMap*> maps;
    std::vector<tspline::TMesh> meshes;
    for (const auto& r : R.patches) maps.push_back(&*r.map), meshes.push_back(r.map->mesh());
    meshes[0] = refined({meshes[0]}).front();
    CHECK_THROWS_AS(tspline::solve_multipatch_poisson(maps, R.layout.interfaces, meshes, smooth_problem()),
                    tspline::NumericalError);
  }

  TEST_CASE("adaptive refinement across a cut stays conforming and lowers the H1 error") {
    const tspline::MultiPatchResult R = plate_map();
    std::vector<const tspline::TSplineMap*> maps;
    std::vector<tspline::TMesh> meshes;
    for (const auto& r : R.patches) maps.push_back(&*r.map), meshes.push_back(r.map->mesh());
    // A Gaussian bump on the cut of interface 0, so that the marked region crosses it.
    const tspline::Interface& f = R.layout.interfaces[0];
    const Eigen::Vector2d c = maps[f.patch_a]->point(tspline::side_point_uv(f.side_a, 0.5));
    tspline::PoissonProblem pb;
    const double s2 = 0.25;
    pb.exact = [c, s2](double x, double y) { return std::exp(-((x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y())) / s2); };
    pb.f = [c, s2](double x, double y) {
      const double r2 = (x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y());
      return -(4 * r2 / (s2 * s2) - 4 / s2) * std::exp(-r2 / s2);  // -Laplace u
    };
    pb.g = pb.exact;
    double h1_first = 0, h1_last = 0;
    std::size_t border_splits = 0;
    for (int step = 0; step < 3; ++step) {
      const tspline::MultiPatchSolution S = tspline::solve_multipatch_poisson(maps, R.layout.interfaces, meshes, pb);
      CHECK(tspline::multipatch_interface_jump(R.layout.interfaces, S) < 1e-12);
      const double h1 = tspline::multipatch_errors(maps, S, pb).h1;
      (step == 0 ? h1_first : h1_last) = h1;
      const auto eta = tspline::multipatch_estimate(maps, S, pb);
      double max_eta = 0;
      for (const auto& e : eta) max_eta = std::max(max_eta, *std::max_element(e.begin(), e.end()));
      std::vector<std::vector<int>> marked(maps.size());
      for (std::size_t p = 0; p < maps.size(); ++p)  // eta_e > 0.5 max eta over all patches
        for (int c = 0; c < static_cast<int>(eta[p].size()); ++c)
          if (eta[p][c] > 0.5 * max_eta) marked[p].push_back(c);
      // Both patches of the cut are refined.
      if (step == 0) CHECK((!marked[f.patch_a].empty() && !marked[f.patch_b].empty()));
      const auto before = tspline::border_params(meshes[f.patch_a], static_cast<tspline::Side>(f.side_a)).size();
      meshes = tspline::refine_multipatch(meshes, R.layout.interfaces, marked);
      border_splits += tspline::border_params(meshes[f.patch_a], static_cast<tspline::Side>(f.side_a)).size() - before;
    }
    CHECK(border_splits > 0);  // the refined region reached the cut
    CHECK(h1_last < 0.5 * h1_first);
  }
}

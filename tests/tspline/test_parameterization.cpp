// The front half on every bundled test domain, with default options and
// automatic corners: the optimized T-mesh must have no inverted cell.
#include <doctest/doctest.h>

#include <iostream>

#include "test_support.h"

using test_support::contains;

#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/parameterization.h"

TEST_SUITE("parameterization") {
  TEST_CASE("every test domain ends with zero inverted cells (default options, automatic corners)") {
    for (const std::string name : {"square.txt", "lshape_cw.txt", "disk.txt", "flower.txt", "cshape.txt", "gear.txt",
                             "blob_bay.txt", "fjords.txt"}) {
      CAPTURE(name);
      const auto poly = tspline::io::read_polygon(test_support::polygon_file(name));
      const tspline::FrontResult r = tspline::run_front(poly, {});
      MESSAGE(name << ": " << r.mesh.num_cells() << " cells, inverted after Coons "
                   << r.quality_coons.inverted_cells << ", after optimization " << r.quality_optimized.inverted_cells
                   << ", min/mean quality " << r.quality_optimized.min_mean_ratio << "/"
                   << r.quality_optimized.mean_mean_ratio << ", sweeps " << r.total_sweeps << ", repair rounds " << r.repair_refined_cells.size());
      CHECK(r.quality_optimized.inverted_cells == 0);
      CHECK(r.refinement.edges_over_tolerance == 0);
      CHECK(r.mesh.check_invariants() == "");
      CHECK(r.quality_optimized.min_mean_ratio > 0.0);
      // Boundary vertices stay exactly where the chord-length map puts them.
      for (int v = 0; v < static_cast<int>(r.mesh.num_vertices()); ++v)
        if (r.mesh.vertex_on_boundary(v))
          CHECK((r.optimized[v] - r.boundary.point_at(r.mesh.vertex_param(v))).norm() == 0.0);
    }
  }
}

TEST_SUITE("parameterization") {
  TEST_CASE("nested optimization ends on the same T-mesh as the direct one, and as good") {
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("flower.txt"));
    tspline::ParameterizationOptions opt;
    opt.initial_level = 5;
    opt.corner_trials = 1;  // the same corners for both runs
    opt.smoothing.relative_displacement_tolerance = 1e-5;
    opt.smoothing.max_sweeps = 5000;
    const tspline::FrontResult nested = tspline::run_front(poly, opt);
    opt.nested_optimization = false;
    const tspline::FrontResult direct = tspline::run_front(poly, opt);
    REQUIRE(nested.mesh.num_cells() == direct.mesh.num_cells());
    REQUIRE(nested.mesh.num_vertices() == direct.mesh.num_vertices());
    // Same vertex set (exact integer coordinates), hence the same optimization problem.
    for (int v = 0; v < static_cast<int>(direct.mesh.num_vertices()); ++v)
      CHECK(nested.mesh.find_vertex(direct.mesh.vertex_ipos(v)) >= 0);
    CHECK(nested.quality_optimized.inverted_cells == 0);
    CHECK(direct.quality_optimized.inverted_cells == 0);
    // Both converge to the same optimum: node positions agree to a small
    // fraction of the smallest cell's physical size (~1e-2 here).
    double worst = 0.0;
    for (int v = 0; v < static_cast<int>(direct.mesh.num_vertices()); ++v) {
      const int w = nested.mesh.find_vertex(direct.mesh.vertex_ipos(v));
      worst = std::max(worst, (nested.optimized[w] - direct.optimized[v]).norm());
    }
    MESSAGE("largest node distance nested vs direct: " << worst);
    CHECK(worst < 1e-3);
    CHECK(nested.quality_optimized.mean_mean_ratio == doctest::Approx(direct.quality_optimized.mean_mean_ratio).epsilon(1e-4));
  }
}

TEST_SUITE("parameterization") {
  TEST_CASE("corner trials keep the best automatic choice by the documented criterion") {
    const auto poly = tspline::io::read_polygon(test_support::polygon_file("lshape_cw.txt"));
    tspline::ParameterizationOptions opt;
    opt.corner_trials = 4;
    const tspline::FrontResult r = tspline::run_front(poly, opt);
    REQUIRE(r.corner_trials.size() == 4);
    // The rule itself is tested on literal values (best_corner_trial, test_hardening.cpp);
    // here: the run keeps the trial it names, and that trial is no worse than any other.
    const std::size_t best = tspline::best_corner_trial(r.corner_trials);
    CHECK(r.boundary.corners().index == r.corner_trials[best].corners);
    for (const auto& t : r.corner_trials) {
      CHECK(r.corner_trials[best].inverted_cells <= t.inverted_cells);
      if (t.inverted_cells == r.corner_trials[best].inverted_cells)
        CHECK(r.corner_trials[best].min_mean_ratio + r.corner_trials[best].mean_mean_ratio >=
              t.min_mean_ratio + t.mean_mean_ratio);
    }
    CHECK(contains(r.boundary.corners().explanation, "(choice " + std::to_string(best + 1) + ")"));
    // With the default initial level the trial is the final run: identical numbers.
    CHECK(r.quality_optimized.min_mean_ratio == r.corner_trials[best].min_mean_ratio);
    CHECK(r.quality_optimized.mean_mean_ratio == r.corner_trials[best].mean_mean_ratio);
    // The four choices are distinct.
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = i + 1; j < 4; ++j) CHECK(r.corner_trials[i].corners != r.corner_trials[j].corners);
    opt.corner_trials = 1;
    const tspline::FrontResult single = tspline::run_front(poly, opt);
    CHECK(single.corner_trials.empty());
    CHECK(single.boundary.corners().index == r.corner_trials[0].corners);
  }
}

TEST_SUITE("parameterization") {
  TEST_CASE("stop_when_tangled stops a front whose every trial is tangled, and changes no other run") {
    // The fjords with default options: a corner trial's T-mesh keeps inverted
    // cells after its nested stages, another's does not. With the option the
    // tangled trials wait before their repair rounds and then go on: the same
    // front, bit for bit, as without it (the kept one had a repair round).
    const auto fjords = tspline::io::read_polygon(test_support::polygon_file("fjords.txt"));
    tspline::ParameterizationOptions opt;
    const tspline::FrontResult full = tspline::run_front(fjords, opt);
    REQUIRE_FALSE(full.repair_refined_cells.empty());
    CHECK(full.quality_optimized.inverted_cells == 0);
    opt.stop_when_tangled = true;
    const tspline::FrontResult waited = tspline::run_front(fjords, opt);
    CHECK(waited.boundary.corners().index == full.boundary.corners().index);
    CHECK(waited.repair_refined_cells == full.repair_refined_cells);
    CHECK(waited.optimized == full.optimized);
    REQUIRE(waited.corner_trials.size() == full.corner_trials.size());
    for (std::size_t k = 0; k < full.corner_trials.size(); ++k) {
      CHECK(waited.corner_trials[k].inverted_cells == full.corner_trials[k].inverted_cells);
      CHECK(waited.corner_trials[k].min_mean_ratio == full.corner_trials[k].min_mean_ratio);
    }
    // At 20 sweeps a stage every trial's T-mesh is tangled after its stages:
    // the run stops, naming each trial's inverted cells (without the option,
    // repair rounds go on).
    opt.smoothing.max_sweeps = 20;
    const std::string why =
        test_support::message_of<tspline::FrontTangled>([&] { (void)tspline::run_front(fjords, opt); });
    CHECK(contains(why,
                   "every corner trial's T-mesh is tangled after its nested stages, at most 100 sweeps into "
                   "the final one (inverted cells: "));
    opt.stop_when_tangled = false;
    CHECK_FALSE(tspline::run_front(fjords, opt).repair_refined_cells.empty());
    // One choice of corners (no trials): the run's own T-mesh.
    opt.stop_when_tangled = true;
    opt.corners.emplace();
    for (int k = 0; k < 4; ++k)
      (*opt.corners)[k] =
          static_cast<long long>(full.boundary.polygon().file_index[full.boundary.corners().index[k]]);
    const std::string own =
        test_support::message_of<tspline::FrontTangled>([&] { (void)tspline::run_front(fjords, opt); });
    CHECK(contains(own, "the optimized T-mesh is tangled after its nested stages ("));
    CHECK(contains(own, " inverted cells of "));
    // The gear needs no repair round; one of the C-shape's trials ends its
    // final stage with 18 % of its cells inverted (it pauses 100 sweeps in,
    // and goes on once another trial is untangled): the same fronts, bit for bit.
    tspline::ParameterizationOptions quick_options;
    quick_options.stop_when_tangled = true;
    for (const char* name : {"gear.txt", "cshape.txt"}) {
      CAPTURE(name);
      const auto poly = tspline::io::read_polygon(test_support::polygon_file(name));
      const tspline::FrontResult plain = tspline::run_front(poly, {});
      const tspline::FrontResult quick = tspline::run_front(poly, quick_options);
      CHECK(quick.boundary.corners().index == plain.boundary.corners().index);
      CHECK(quick.optimized == plain.optimized);
      CHECK(quick.total_sweeps == plain.total_sweeps);
      REQUIRE(quick.corner_trials.size() == plain.corner_trials.size());
      for (std::size_t k = 0; k < plain.corner_trials.size(); ++k)
        CHECK(quick.corner_trials[k].inverted_cells == plain.corner_trials[k].inverted_cells);
    }
  }
}

TEST_SUITE("parameterization") {
  TEST_CASE("best_corner_trial: fewest inverted cells first, then the highest min + mean quality") {
    using tspline::CornerTrial;
    using tspline::best_corner_trial;
    const std::array<std::size_t, 4> c{0, 1, 2, 3};
    CHECK(best_corner_trial({}) == 0);
    // Fewer inverted cells beat any quality.
    CHECK(best_corner_trial({{c, 2, 0.9, 0.9}, {c, 1, -0.5, 0.1}, {c, 3, 0.9, 0.9}}) == 1);
    // Equal inverted cells: the sum min + mean decides (0.2 + 0.6 > 0.5 + 0.2).
    CHECK(best_corner_trial({{c, 0, 0.5, 0.2}, {c, 0, 0.2, 0.6}, {c, 1, 0.9, 0.9}}) == 1);
    // A tie keeps the first.
    CHECK(best_corner_trial({{c, 0, 0.3, 0.5}, {c, 0, 0.5, 0.3}}) == 0);
    // A trial over the cell budget (ranked with the most inverted cells) loses.
    constexpr double kWorst = -std::numeric_limits<double>::infinity();
    CHECK(best_corner_trial({{c, std::numeric_limits<std::size_t>::max(), kWorst, kWorst}, {c, 40, 0.0, 0.1}}) == 1);
  }
}

TEST_SUITE("parameterization") {
  TEST_CASE(
      "each nested stage starts from the carried-over positions or Coons, whichever has fewer inverted "
      "cells") {
    // Hokkaido at level 6 with a fine tolerance: stages end at their sweep
    // cap with a few inverted cells, and the Coons start of the next has
    // several times more. Restarting each such stage from Coons left 430
    // inverted cells after the repair rounds; the better start leaves none.
    const auto poly =
        tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/hokkaido.txt");
    tspline::ParameterizationOptions opt;
    opt.initial_level = 6;
    opt.tolerance_relative = 1e-7;
    const tspline::FrontResult r = tspline::run_front(poly, opt);
    REQUIRE(r.stages.size() >= 3);
    CHECK_FALSE(r.stages.front().carried);
    CHECK_FALSE(r.stages.front().other_start_inverted.has_value());
    bool carried_with_folds = false;  // a stage that ended with inverted cells, carried over all the same
    for (std::size_t k = 1; k < r.stages.size(); ++k) {
      const tspline::FrontStage& s = r.stages[k];
      const tspline::FrontStage& prev = r.stages[k - 1];
      CAPTURE(k);
      MESSAGE("stage " << k + 1 << ": " << s.cells << " cells, from "
                       << std::string(s.carried ? "carried" : "Coons") << " with " << s.start_inverted
                       << " inverted (the other "
                       << (s.other_start_inverted ? std::to_string(*s.other_start_inverted) : "-") << "), "
                       << s.end_inverted << " at the end, " << s.sweeps << " sweeps");
      CHECK(s.cells >= prev.cells);
      if (prev.end_inverted == 0) {
        // An untangled stage is carried over without counting Coons' folds.
        CHECK(s.carried);
        CHECK_FALSE(s.other_start_inverted.has_value());
      } else {
        REQUIRE(s.other_start_inverted.has_value());
        CHECK(s.start_inverted <= *s.other_start_inverted);
        if (s.carried && s.start_inverted > 0) carried_with_folds = true;
      }
    }
    CHECK(carried_with_folds);
    // After the repair rounds (the last stage may end with a few).
    CHECK(r.quality_optimized.inverted_cells == 0);
  }
}

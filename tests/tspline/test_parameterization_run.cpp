// run_front / run_parameterization as a library user sees them: the progress
// events (typed, per stage), the options kept in the result, the options
// validated before any work with the option named, and the corner trials,
// whose kept trial is the run itself.
#include <doctest/doctest.h>

#include <atomic>
#include <cmath>

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "test_support.h"
#include "toolkit/errors.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/errors.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/pipeline/parameterization.h"

using tspline::ProgressEvent;

TEST_SUITE("parameterization_run") {
  TEST_CASE("progress arrives as typed events: steps per stage, every sweep in order, untangling stages") {
    const tspline::Polygon poly = tspline::io::read_polygon(test_support::polygon_file("lshape_cw.txt"));
    std::vector<ProgressEvent> events;
    tspline::ParameterizationOptions opt;
    opt.corner_trials = 1;  // concurrent trials report when each is done, not their sweeps
    opt.progress = [&](const ProgressEvent& e) { events.push_back(e); };
    tspline::AdaptiveOptions ad;
    ad.max_adapt = 1;
    const tspline::ParameterizationResult r = tspline::run_parameterization(poly, opt, ad);
    std::set<std::string> step_stages;
    int last_sweep = -1, sweeps = 0, untangling_stages = 0;
    for (const ProgressEvent& e : events) {
      CHECK_FALSE(e.text.empty());
      CHECK_FALSE(e.stage.empty());
      switch (e.kind) {
        case ProgressEvent::Kind::Step: step_stages.insert(e.stage); break;
        case ProgressEvent::Kind::Note: break;
        case ProgressEvent::Kind::Sweep:
          // Each optimization run counts its sweeps from 0, one event per sweep.
          CHECK(e.stage == "optimization");
          CHECK((e.count == 0 || e.count == last_sweep + 1));
          CHECK(e.value >= 0.0);
          last_sweep = e.count;
          ++sweeps;
          break;
        case ProgressEvent::Kind::Untangling:
          CHECK(e.stage == "untangling");
          CHECK(e.iteration >= 0);
          CHECK(e.count >= 0);
          CHECK(e.value > 0.0);  // eps
          ++untangling_stages;
          break;
        case ProgressEvent::Kind::Heartbeat: FAIL("a heartbeat without concurrent corner trials"); break;
      }
    }
    for (const char* s : {"boundary", "tmesh", "coons", "optimization", "boundary_curve", "untangling", "map", "stop"}) {
      CAPTURE(s);
      CHECK(step_stages.count(s) == 1);
    }
    // Every sweep of every optimization run was reported.
    CHECK(sweeps == r.front.total_sweeps);
    int stages = 0;
    for (const tspline::AdaptIteration& it : r.iterations) stages += it.untangling.stages;
    CHECK(untangling_stages == stages);
    // The last event says why the loop stopped.
    CHECK(events.back().stage == "stop");
    CHECK(test_support::contains(events.back().text, r.stop_reason));
  }

  TEST_CASE("the result keeps the options it was computed with, without the callbacks") {
    const tspline::Polygon poly = tspline::io::read_polygon(test_support::polygon_file("square.txt"));
    tspline::ParameterizationOptions opt;
    opt.initial_level = 2;
    opt.progress = [](const ProgressEvent&) {};
    tspline::AdaptiveOptions ad;
    ad.min_jacobian = 0.35;
    ad.max_adapt = 1;
    const tspline::ParameterizationResult r = tspline::run_parameterization(poly, opt, ad);
    CHECK(r.options.initial_level == 2);
    CHECK_FALSE(r.options.progress);
    CHECK(r.adaptive.min_jacobian == 0.35);
    CHECK(r.adaptive.max_adapt == 1);
    CHECK(r.good() == (r.valid() && r.quality.min_mean_ratio >= 0.35));
  }

  TEST_CASE("the polish: run where the map is certified and below polish_below, skipped below polish_skip_*") {
    // The L-shape's map (J_r 0.47) is polished once polish_below is above it;
    // with the skip thresholds above its figures the polish is skipped and the
    // map is the one without any polish, control point for control point.
    const tspline::Polygon poly = tspline::io::read_polygon(test_support::polygon_file("lshape_cw.txt"));
    auto run = [&](double skip_scaled, double skip_mean_ratio, int stages, std::string* polish_line) {
      tspline::ParameterizationOptions opt;
      opt.corner_trials = 1;
      opt.progress = [&](const ProgressEvent& e) {
        if (polish_line && e.stage == "polish") *polish_line = e.text;
      };
      tspline::AdaptiveOptions ad;
      ad.max_adapt = 1;
      ad.polish_below = 1.1;
      ad.polish_stages = stages;
      ad.polish_skip = {skip_scaled, skip_mean_ratio};
      return tspline::run_parameterization(poly, opt, ad);
    };
    std::string ran, skipped_sj, skipped_jr;
    const tspline::ParameterizationResult polished = run(0.0, 0.0, 12, &ran);
    CHECK(test_support::contains(ran, "more quality stages"));
    const tspline::ParameterizationResult none = run(0.0, 0.0, 0, nullptr);
    REQUIRE(none.map);
    REQUIRE(none.dense_quality.min_scaled < 0.99);
    REQUIRE(none.dense_quality.min_mean_ratio < 0.99);
    const tspline::ParameterizationResult by_sj = run(0.99, 0.0, 12, &skipped_sj);
    const tspline::ParameterizationResult by_jr = run(0.0, 0.99, 12, &skipped_jr);
    CHECK(test_support::contains(skipped_sj, "polish: skipped"));
    CHECK(test_support::contains(skipped_jr, "polish: skipped"));
    CHECK(by_sj.map->control_points() == none.map->control_points());
    CHECK(by_jr.map->control_points() == none.map->control_points());
    // Where it ran and was kept, the map moved.
    if (!test_support::contains(ran, "not kept")) CHECK(polished.map->control_points() != none.map->control_points());
  }

  TEST_CASE("keep_interpolant: a certified interpolant whose whole map meets the floor is kept without optimization") {
    // A trapezoid's interpolating map is nearly bilinear (whole-map J_r and
    // scaled Jacobian far above the default floor): kept as it is by default, control point
    // for control point the map of a run without optimization; unset, or with
    // a floor it does not meet, the optimizer runs on it.
    tspline::Polygon poly;
    poly.vertices = {Eigen::Vector2d(0, 0), Eigen::Vector2d(4, 0), Eigen::Vector2d(3, 2), Eigen::Vector2d(1, 2)};
    poly.file_index = {0, 1, 2, 3};
    tspline::ParameterizationOptions opt;
    opt.corners = std::array<long long, 4>{0, 1, 2, 3};
    std::string kept_line;
    auto run = [&](std::optional<tspline::QualityFloor> keep, bool optimize, std::string* line) {
      tspline::ParameterizationOptions o = opt;
      o.progress = [line](const ProgressEvent& e) {
        if (line && e.stage == "map" && test_support::contains(e.text, "without optimizing")) *line = e.text;
      };
      tspline::AdaptiveOptions ad;
      ad.max_adapt = 0;
      ad.keep_interpolant = keep;
      ad.optimize_control_points = optimize;
      return tspline::run_parameterization(poly, o, ad);
    };
    const tspline::ParameterizationResult kept = run(tspline::AdaptiveOptions{}.keep_interpolant, true, &kept_line);
    const tspline::ParameterizationResult plain = run(std::nullopt, false, nullptr);
    const tspline::ParameterizationResult optimized = run(std::nullopt, true, nullptr);
    const tspline::ParameterizationResult unmet = run(tspline::QualityFloor{0.6, 1.01}, true, nullptr);
    REQUIRE(kept.map);
    REQUIRE(kept.certified_valid());
    const tspline::QualityFloor floor = *tspline::AdaptiveOptions{}.keep_interpolant;
    CHECK(kept.dense_quality.min_mean_ratio >= floor.mean_ratio);
    CHECK(kept.dense_quality.min_scaled >= floor.scaled_jacobian);
    CHECK(test_support::contains(kept_line, "kept the interpolating map without optimizing it"));
    REQUIRE(kept.iterations.size() == 1);
    CHECK_FALSE(kept.iterations[0].control_points_optimized);
    CHECK(kept.iterations[0].untangling.free_points == 0);  // the optimizer never ran
    CHECK(kept.map->control_points() == plain.map->control_points());
    for (const tspline::ParameterizationResult* r : {&optimized, &unmet}) {
      REQUIRE(r->iterations.size() == 1);
      CHECK(r->iterations[0].untangling.free_points > 0);
      CHECK(r->certified_valid());
    }
  }

  TEST_CASE("options out of range are input errors that name the option's field, before any work") {
    const tspline::Polygon poly = tspline::io::read_polygon(test_support::polygon_file("square.txt"));
    auto message = [&](const tspline::ParameterizationOptions& o, const tspline::AdaptiveOptions& a) -> std::string {
      try {
        tspline::run_parameterization(poly, o, a);
      } catch (const tspline::InputError& e) {
        return e.what();
      }
      return "";
    };
    const std::map<std::string, std::function<void(tspline::ParameterizationOptions&, tspline::AdaptiveOptions&)>>
        cases{{"`smoothing.over_relaxation`", [](auto& o, auto&) { o.smoothing.over_relaxation = 2.5; }},
              {"`smoothing.max_sweeps`", [](auto& o, auto&) { o.smoothing.max_sweeps = -1; }},
              {"`smoothing.relative_displacement_tolerance`", [](auto& o, auto&) { o.smoothing.relative_displacement_tolerance = -1.0; }},
              {"`initial_level`", [](auto& o, auto&) { o.initial_level = 11; }},
              {"`min_jacobian`", [](auto&, auto& a) { a.min_jacobian = 0.0; }},
              {"`certification.max_depth`", [](auto&, auto& a) { a.certification.max_depth = 21; }},
              {"`untangling.quality_power`", [](auto&, auto& a) { a.untangling.quality_power = 0.5; }},
              {"`polish_skip.scaled_jacobian`", [](auto&, auto& a) { a.polish_skip.scaled_jacobian = std::nan(""); }},
              {"`keep_interpolant.mean_ratio`", [](auto&, auto& a) { a.keep_interpolant = tspline::QualityFloor{0.6, INFINITY}; }}};
    for (const auto& name_spoil : cases) {
      const std::string& name = name_spoil.first;
      const auto& spoil = name_spoil.second;
      CAPTURE(name);
      tspline::ParameterizationOptions o;
      tspline::AdaptiveOptions a;
      spoil(o, a);
      CHECK(test_support::contains(message(o, a), name));
    }
  }

  TEST_CASE("initial level 0: a map where the boundary refines the cell, an input error naming initial_level where not") {
    // A single cell gives the four corner-extra functions one interpolation
    // point (the cell's centre): Eq. 8 would be singular. The square needs no
    // boundary refinement, so level 0 leaves it one cell; the L-shape's
    // reflex corner refines it, and level 0 maps it.
    tspline::ParameterizationOptions o;
    o.initial_level = 0;
    tspline::AdaptiveOptions a;
    a.max_adapt = 0;
    const tspline::Polygon square = tspline::io::read_polygon(test_support::polygon_file("square.txt"));
    std::string message;
    try {
      tspline::run_parameterization(square, o, a);
    } catch (const tspline::InputError& e) {
      message = e.what();
    }
    CHECK(test_support::contains(message, "initial_level"));
    CHECK(test_support::contains(message, "single cell"));
    const tspline::Polygon lshape = tspline::io::read_polygon(test_support::polygon_file("lshape_cw.txt"));
    const tspline::ParameterizationResult r = tspline::run_parameterization(lshape, o, a);
    CHECK(r.map->mesh().num_cells() >= 4);
    CHECK(r.certified_valid());
  }

  TEST_CASE("a tolerance that needs more than max_cells: an input error naming the tolerance given, no stage optimized") {
    // The last stage's T-mesh is built before the nested stages: the error
    // names the tolerance asked for (not a coarser stage's), and no sweep ran.
    const tspline::Polygon poly = tspline::io::read_polygon(test_support::polygon_file("fjords.txt"));
    tspline::ParameterizationOptions o;
    o.tolerance_absolute = 1e-12;
    o.max_cells = 30000;
    o.corner_trials = 1;
    int sweeps = 0;
    o.progress = [&](const ProgressEvent& e) { sweeps += e.kind == ProgressEvent::Kind::Sweep; };
    std::string message;
    try {
      tspline::run_parameterization(poly, o, tspline::AdaptiveOptions{});
    } catch (const tspline::InputError& e) {
      message = e.what();
    }
    CHECK(test_support::contains(message, "more than 30000 cells"));
    CHECK(test_support::contains(message, "tolerance 1e-12"));
    CHECK(sweeps == 0);
  }

  TEST_CASE("a callback that throws during the concurrent corner trials stops them (Ctrl-C in the program)") {
    const tspline::Polygon poly = tspline::io::read_polygon(test_support::polygon_file("flower.txt"));
    tspline::ParameterizationOptions opt;
    REQUIRE(opt.corner_trials > 1);
    std::atomic<int> beats{0};
    opt.progress = [&](const ProgressEvent& e) {
      if (e.kind != ProgressEvent::Kind::Heartbeat) return;
      CHECK(e.stage == "corners");
      if (++beats >= 3) throw toolkit::Interrupted("interrupted");  // and at every later one, like the program
    };
    CHECK_THROWS_AS(tspline::run_front(poly, opt), toolkit::Interrupted);
    // Stopped at the third heartbeat: each trial sends one per sweep, and
    // every trial of the flower runs tens of sweeps.
    CHECK(beats >= 3);
  }

  TEST_CASE("the kept corner trial is the run: the same T-mesh and nodes as a run with those corners given") {
    const tspline::Polygon poly = tspline::io::read_polygon(test_support::polygon_file("flower.txt"));
    tspline::ParameterizationOptions opt;
    int trial_reports = 0;  // one "trial k of n done" per trial, as each finishes
    opt.progress = [&](const ProgressEvent& e) { trial_reports += e.kind == ProgressEvent::Kind::Step && e.stage == "corners" && test_support::contains(e.text, "trial"); };
    const tspline::FrontResult automatic = tspline::run_front(poly, opt);
    CHECK(trial_reports == opt.corner_trials);
    REQUIRE(automatic.corner_trials.size() == static_cast<std::size_t>(opt.corner_trials));
    std::array<long long, 4> given{};
    for (int k = 0; k < 4; ++k)
      given[k] = static_cast<long long>(automatic.boundary.polygon().file_index[automatic.boundary.corners().index[k]]);
    opt.corners = given;
    trial_reports = 0;
    opt.progress = [&](const ProgressEvent& e) { trial_reports += e.kind == ProgressEvent::Kind::Step && e.stage == "corners" && test_support::contains(e.text, "trial"); };
    const tspline::FrontResult explicit_corners = tspline::run_front(poly, opt);
    CHECK(trial_reports == 0);  // corners given: no trials
    REQUIRE(explicit_corners.mesh.num_cells() == automatic.mesh.num_cells());
    REQUIRE(explicit_corners.optimized.size() == automatic.optimized.size());
    for (std::size_t v = 0; v < automatic.optimized.size(); ++v) CHECK(explicit_corners.optimized[v] == automatic.optimized[v]);
    CHECK(explicit_corners.total_sweeps == automatic.total_sweeps);
    // The stage times of the kept trial are reported as the run's.
    bool has_optimization = false;
    for (const tspline::StageTime& t : automatic.times) has_optimization = has_optimization || t.stage == "optimization";
    CHECK(has_optimization);
  }
}

// check_map (multipatch/map_check.h): the figures of every patch are those of
// the functions it gathers, computed on their own; the whole map's are their
// minima and sums; interfaces naming a patch that is not there are input errors.
#include <doctest/doctest.h>

#include <algorithm>

#include "test_support.h"
#include "tspline/errors.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/multipatch/map_check.h"
#include "tspline/pipeline/adaptive_parameterization.h"

TEST_SUITE("map_check") {
  TEST_CASE("check_map: per patch the certificate and bounds as computed alone, over the map their minima") {
    tspline::AdaptiveOptions ad;
    ad.max_adapt = 0;
    tspline::ParameterizationOptions opt;
    opt.initial_level = 2;
    std::vector<tspline::ParameterizationResult> runs;
    for (const char* f : {"lshape_cw.txt", "disk.txt", "square.txt"})
      runs.push_back(tspline::run_parameterization(tspline::io::read_polygon(test_support::polygon_file(f)), opt, ad));
    std::vector<const tspline::TSplineMap*> maps;
    for (const auto& r : runs) maps.push_back(&*r.map);
    tspline::MapCheckOptions o;
    o.quality.samples_per_edge = 5;
    const tspline::MapCheck m = tspline::check_map(maps, {}, o);
    REQUIRE(m.patches.size() == 3);
    std::size_t elements = 0;
    double jr = 2.0, sj = 2.0, rel = 2.0;
    for (std::size_t p = 0; p < maps.size(); ++p) {
      CAPTURE(p);
      const tspline::MapCertification c = tspline::certify_map(*maps[p], o.certification);
      const tspline::MapQualityBounds q = tspline::certified_map_quality(*maps[p], o.quality);
      const tspline::PatchCheck& pc = m.patches[p];
      CHECK(pc.certification.elements == c.elements);
      CHECK(pc.certification.certified == c.certified);
      CHECK(pc.certification.min_relative_lower_bound == c.min_relative_lower_bound);
      CHECK(pc.quality.mean_ratio.lower_bound == q.mean_ratio.lower_bound);
      CHECK(pc.quality.scaled.lower_bound == q.scaled.lower_bound);
      CHECK(pc.quality.scaled.sampled == q.scaled.sampled);
      CHECK(pc.dense.min_mean_ratio == tspline::dense_map_quality(*maps[p], o.dense_samples).min_mean_ratio);
      CHECK(pc.gauss.min_mean_ratio == tspline::map_quality(*maps[p], o.gauss).min_mean_ratio);
      elements += c.elements;
      jr = std::min(jr, q.mean_ratio.lower_bound);
      sj = std::min(sj, q.scaled.lower_bound);
      rel = std::min(rel, c.min_relative_lower_bound);
    }
    CHECK(m.elements == elements);
    CHECK(m.certified == elements);
    CHECK(m.certified_patches == 3);
    CHECK(m.certified_valid());
    CHECK(m.quality.mean_ratio.lower_bound == jr);
    CHECK(m.quality.scaled.lower_bound == sj);
    CHECK(m.min_relative_det_lower_bound == rel);
    CHECK(m.max_interface_gap == 0.0);
    // The square's map is the identity: every figure 1 there, so the minima are the others'.
    CHECK(m.patches[2].quality.mean_ratio.lower_bound == doctest::Approx(1.0));
    CHECK(jr < 1.0);
    // An interface naming a fourth patch.
    tspline::Interface bad;
    bad.patch_a = 0, bad.patch_b = 3;
    CHECK_THROWS_AS(tspline::check_map(maps, {bad}, o), tspline::InputError);
    o.dense_samples = 0;
    CHECK_THROWS_AS(tspline::check_map(maps, {}, o), tspline::InputError);
  }
}

// Automatic quad layouts (layout/): ring nodes, the size field, the layout of
// a domain with a narrow neck and of one with many holes, the conforming
// multi-patch map on a layout, and the layout choice of parameterize_domain.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <numbers>
#include <string>
#include <thread>

#include "test_support.h"
#include "tspline/boundary/domain.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/layout_output.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/layout/quad_layout.h"
#include "tspline/layout/quad_layout_memo.h"
#include "tspline/layout/quad_mesher.h"
#include "tspline/layout/ring_nodes.h"
#include "tspline/layout/size_field.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/pipeline/domain_parameterization.h"

namespace {

using test_support::contains;
using test_support::make_polygon;
using test_support::message_of;

tspline::Polygon rectangle(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}});
}

// Two 4 x 4 squares joined by a neck of width w and length 2 (counter-clockwise).
tspline::Polygon dumbbell(double w) {
  return make_polygon({{0, 0}, {4, 0}, {4, 2 - w / 2}, {6, 2 - w / 2}, {6, 0}, {10, 0}, {10, 4}, {6, 4},
                       {6, 2 + w / 2}, {4, 2 + w / 2}, {4, 4}, {0, 4}});
}

double polygon_area(const std::vector<Eigen::Vector2d>& v) {
  double a = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector2d &p = v[i], &q = v[(i + 1) % v.size()];
    a += p.x() * q.y() - p.y() * q.x();
  }
  return 0.5 * a;
}

// Inner angle (degrees) of a counter-clockwise polygon at vertex i.
double inner_angle(const std::vector<Eigen::Vector2d>& v, std::size_t i) {
  const std::size_t n = v.size();
  const Eigen::Vector2d a = v[(i + n - 1) % n] - v[i], b = v[(i + 1) % n] - v[i];
  double t = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
  if (t < 0) t += 2 * std::numbers::pi;
  return 360.0 - t * 180.0 / std::numbers::pi;
}

// Every patch: four corners, each of inner angle below 180 degrees; the patch
// polygons tile the domain (their areas add up to the domain's).
void check_layout_tiles(const tspline::Domain& d, const tspline::PatchLayout& L) {
  double area = 0.0;
  for (const tspline::Patch& p : L.patches) {
    const double a = polygon_area(p.polygon.vertices);
    CHECK(a > 0.0);
    area += a;
    for (int k = 0; k < 4; ++k) CHECK(inner_angle(p.polygon.vertices, p.corners[k]) < 180.0);
  }
  CHECK(area == doctest::Approx(tspline::domain_area(d)).epsilon(1e-12));
  // Every cut is the side of exactly two patches.
  CHECK(L.interfaces.size() == L.cuts.size());
}

// The unit square, one patch at initial level 2, default adaptive options.
struct UnitSquareAtLevel2 {
  UnitSquareAtLevel2() { po.initial_level = 2; }
  const tspline::Domain square{rectangle(0, 0, 1, 1), {}};
  tspline::ParameterizationOptions po;
  const tspline::AdaptiveOptions ad;
};

// Two layouts the same to the last bit: patch polygons, corners and the
// optimization's counts and figures.
void check_same_layout(const tspline::QuadLayout& a, const tspline::QuadLayout& b) {
  REQUIRE(a.layout.patches.size() == b.layout.patches.size());
  for (std::size_t p = 0; p < a.layout.patches.size(); ++p) {
    CHECK(a.layout.patches[p].polygon.vertices == b.layout.patches[p].polygon.vertices);
    CHECK(a.layout.patches[p].corners == b.layout.patches[p].corners);
  }
  CHECK(a.ring_nodes == b.ring_nodes);
  CHECK(a.stats.rotations == b.stats.rotations);
  CHECK(a.stats.optimization_sweeps == b.stats.optimization_sweeps);
  CHECK(a.stats.repair_rounds == b.stats.repair_rounds);
  CHECK(a.stats.corner_mean_ratio == b.stats.corner_mean_ratio);
  CHECK(a.stats.corner_scaled_jacobian == b.stats.corner_scaled_jacobian);
}

}  // namespace

TEST_SUITE("quad_layout") {
  TEST_CASE("ring curve: arc length, points, the vertex farthest from a chord") {
    const tspline::RingCurve r(rectangle(0, 0, 4, 2).vertices);
    CHECK(r.length() == doctest::Approx(12.0));
    CHECK((r.point(5.0) - Eigen::Vector2d(4, 1)).norm() < 1e-14);
    CHECK((r.point(13.0) - Eigen::Vector2d(1, 0)).norm() < 1e-14);  // modulo the length
    // From (2, 0) to (4, 1): the vertex (4, 0) in between, at distance 2/sqrt(5) from the chord.
    const auto [dev, at] = r.farthest_from_chord(2.0, 5.0);
    CHECK(dev == doctest::Approx(2.0 / std::sqrt(5.0)));
    CHECK(at == doctest::Approx(4.0));
    // Wrapping past vertex 0: from (0, 1) (arc 11) to (1, 0) (arc 13): the vertex (0, 0) at arc 12.
    CHECK(r.farthest_from_chord(11.0, 13.0).second == doctest::Approx(12.0));
  }

  TEST_CASE("ring nodes: the corners of a rectangle, and long sides split by the size") {
    const tspline::RingCurve r(rectangle(0, 0, 4, 2).vertices);
    const std::vector<double> corners = tspline::ring_nodes(r, {});
    CHECK(corners == std::vector<double>{0.0, 4.0, 6.0, 10.0});
    // With size 1 every side is split into pieces of at most 1.2.
    const std::vector<double> fine = tspline::ring_nodes(r, {}, [](const Eigen::Vector2d&) { return 1.0; });
    CHECK(fine.size() == 12);
    for (std::size_t k = 0; k < fine.size(); ++k) {
      const double next = k + 1 < fine.size() ? fine[k + 1] : fine[0] + r.length();
      CHECK(next - fine[k] == doctest::Approx(1.0));
    }
    // A ring of three vertices still gets four nodes.
    const tspline::RingCurve tri(make_polygon({{0, 0}, {1, 0}, {0, 1}}).vertices);
    CHECK(tspline::ring_nodes(tri, {}).size() == 4);
  }

  TEST_CASE("ring nodes: a spike or crack shorter than a quarter piece is a node, sharp at its own edges") {
    // An 8 x 4 rectangle with, in its bottom side, a crack 0.1 deep and 0.04
    // wide (inner angle 337.4 degrees at its tip, a turn of 157.4) and, in its
    // top side, a spike 0.1 out (inner angle 22.6). With patch size 4 the
    // corner test looks a quarter piece (1) either side, where the ring turns
    // by only 12.7 degrees: the tips are nodes because they are sharp at the
    // vertex itself (RingNodeOptions::sharp_turn, 150 degrees).
    // (Off the sides' middles, where the split by size puts nodes anyway.)
    const tspline::Polygon p = make_polygon({{0, 0}, {2.98, 0}, {3, 0.1}, {3.02, 0}, {8, 0}, {8, 4}, {5.02, 4},
                                             {5, 4.1}, {4.98, 4}, {0, 4}});
    const tspline::RingCurve r(p.vertices);
    const double crack_tip = r.arc(2), spike_tip = r.arc(7);
    CHECK(std::abs(r.turn(2)) > 157.0 * std::numbers::pi / 180.0);
    CHECK(std::abs(r.turn(7)) > 157.0 * std::numbers::pi / 180.0);
    auto size = [](const Eigen::Vector2d&) { return 4.0; };
    auto has = [](const std::vector<double>& nodes, double s) {
      return std::any_of(nodes.begin(), nodes.end(), [s](double n) { return std::abs(n - s) < 1e-12; });
    };
    const std::vector<double> nodes = tspline::ring_nodes(r, {}, size);
    CHECK(has(nodes, crack_tip));
    CHECK(has(nodes, spike_tip));
    // The rectangle's own corners stay nodes.
    for (const std::size_t corner : {0u, 4u, 5u, 9u}) CHECK(has(nodes, r.arc(corner)));
    // Without the rule (no vertex is sharper than a half turn) neither tip is a node.
    tspline::RingNodeOptions blunt;
    blunt.sharp_turn = std::numbers::pi;
    const std::vector<double> old = tspline::ring_nodes(r, blunt, size);
    CHECK_FALSE(has(old, crack_tip));
    CHECK_FALSE(has(old, spike_tip));
  }

  TEST_CASE("size field: the local width in a neck, growing away from it at the grading rate") {
    const tspline::Domain d = tspline::validate_domain({dumbbell(0.5), {}});
    tspline::SizeFieldOptions o;
    o.factor = 0.5;
    o.grading = 0.35;
    const tspline::SizeField h(d, o);
    // Across the neck: factor x width 0.5 at the ring, plus the grading times the 0.25 to
    // the centre (up to the grid's resolution, 10 / 768, and the chamfer's 8 %).
    CHECK(h({5.0, 2.0}) == doctest::Approx(0.5 * 0.5 + 0.35 * 0.25).epsilon(0.1));
    CHECK(h.min_width() == doctest::Approx(0.5).epsilon(1e-6));
    // One unit from the neck's mouth into a bulb: at most factor x width + grading.
    CHECK(h({3.0, 2.0}) <= 0.5 * 0.5 + 0.35 * 1.0 + 0.05);
    // Far from any narrow place the size is capped by an eighth of the diagonal.
    CHECK(h({1.0, 1.0}) <= 0.125 * std::hypot(10.0, 4.0) + 1e-12);
  }

  TEST_CASE("quad corner scaled Jacobian: 1 for a square, sin 60 for a rhombus, negative when reflex") {
    using V = Eigen::Vector2d;
    CHECK(tspline::quad_corner_scaled_jacobian({V(0, 0), V(1, 0), V(1, 1), V(0, 1)}) == doctest::Approx(1.0));
    const double c = std::cos(std::numbers::pi / 3), s = std::sin(std::numbers::pi / 3);
    CHECK(tspline::quad_corner_scaled_jacobian({V(0, 0), V(1, 0), V(1 + c, s), V(c, s)}) == doctest::Approx(s));
    CHECK(tspline::quad_corner_scaled_jacobian({V(0, 0), V(2, 0), V(0.5, 0.5), V(0, 2)}) < 0.0);
  }

  TEST_CASE("a layout whose cancel flag is set stops with LayoutCancelled and nothing else") {
    if (!tspline::quad_mesher_available()) return;  // the no-mesher message is tested below
    const tspline::Domain d = tspline::validate_domain({dumbbell(0.5), {}});
    std::atomic<bool> cancel{true};
    tspline::QuadLayoutOptions o;
    o.cancel = &cancel;
    CHECK_THROWS_AS((void)tspline::build_quad_layout(d, o), tspline::LayoutCancelled);
    cancel = false;  // the same options, not cancelled: a layout
    CHECK(tspline::build_quad_layout(d, o).layout.patches.size() >= 3);
  }

  TEST_CASE("layout of a domain with a narrow neck: patches of their own in the neck, near square") {
    if (!tspline::quad_mesher_available()) {
      const std::string msg = message_of<tspline::InputError>(
          [] { (void)tspline::build_quad_layout(tspline::validate_domain({dumbbell(0.5), {}})); });
      CHECK(contains(msg, "Gmsh"));
      return;
    }
    const tspline::Domain d = tspline::validate_domain({dumbbell(0.5), {}});
    const tspline::QuadLayout L = tspline::build_quad_layout(d);
    check_layout_tiles(d, L.layout);
    // Patches whose centroid lies in the neck (4 < x < 6): shorter than four times
    // the neck's width along it, and with sides of ratio at most 4.
    int in_neck = 0;
    for (const tspline::Patch& p : L.layout.patches) {
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (std::size_t k = 0; k < 4; ++k) c += p.polygon.vertices[p.corners[k]] / 4.0;
      if (!(c.x() > 4.2 && c.x() < 5.8)) continue;
      ++in_neck;
      double lo = 1e300, hi = 0.0;
      for (int k = 0; k < 4; ++k) {
        const double l = (p.polygon.vertices[p.corners[(k + 1) % 4]] - p.polygon.vertices[p.corners[k]]).norm();
        lo = std::min(lo, l), hi = std::max(hi, l);
      }
      CHECK(hi <= 4.0 * lo);
      CHECK(hi <= 4.0 * 0.5);
    }
    CHECK(in_neck >= 2);  // the neck is 2 long and 0.5 wide: several patches along it
    CHECK(L.stats.straight_min_scaled_jacobian > 0.2);
    for (std::size_t v = 0; v <= 2; ++v) CHECK(L.stats.inner_valence[v] == 0);  // no inner node of valence 2 or less
  }

  TEST_CASE("layout of a square with 16 holes: every ring joined, patches tiling the domain") {
    if (!tspline::quad_mesher_available()) return;  // the no-Gmsh message is checked above
    tspline::Domain d{rectangle(0, 0, 8, 8), {}};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) d.holes.push_back(rectangle(1 + 2 * i, 1 + 2 * j, 1.6 + 2 * i, 1.5 + 2 * j));
    d = tspline::validate_domain(d);
    const tspline::QuadLayout L = tspline::build_quad_layout(d);
    check_layout_tiles(d, L.layout);
    CHECK(L.stats.patches == L.layout.patches.size());
    CHECK(L.stats.straight_min_scaled_jacobian > 0.2);
    // Every hole is a side of some patch.
    for (std::size_t h = 0; h < d.holes.size(); ++h) {
      const Eigen::Vector2d corner = d.holes[h].vertices[0];
      bool touched = false;
      for (const tspline::Patch& p : L.layout.patches)
        for (const Eigen::Vector2d& v : p.polygon.vertices)
          if ((v - corner).norm() < 1e-12) touched = true;
      CHECK(touched);
    }
  }

  TEST_CASE("a flat ring corner of Bali's layout: a sheet through it, or its ring pillowed; restarted from the ring nodes") {
    if (!tspline::quad_mesher_available()) return;
    tspline::DomainCleaningOptions how;
    how.blunt_tips_below_degrees = 17.5;  // as `tspline param` cleans it
    const tspline::Domain d = tspline::validate_domain(
        {tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/bali.txt"), {}}, how);
    const tspline::QuadLayout sheets = tspline::build_quad_layout(d);
    check_layout_tiles(d, sheets.layout);
    REQUIRE(sheets.stats.corner_sheets >= 1);
    CHECK(sheets.stats.pillowed_rings == 0);
    CHECK(contains(sheets.explanation(), "sheet(s) of quads through flat ring corners"));
    tspline::QuadLayoutOptions o;
    o.corner_sheets = false;
    const tspline::QuadLayout pillowed = tspline::build_quad_layout(d, o);
    check_layout_tiles(d, pillowed.layout);
    CHECK(pillowed.stats.pillowed_rings == 1);
    CHECK(pillowed.stats.corner_sheets == 0);
    // A sheet adds fewer patches than a layer along the whole coast.
    CHECK(sheets.stats.patches < pillowed.stats.patches);
    // The first layout's ring nodes (its repairs included) give the same layout, with no repair.
    REQUIRE(sheets.ring_nodes.size() == 1);
    o.corner_sheets = true;
    o.start_ring_nodes = sheets.ring_nodes;
    const tspline::QuadLayout again = tspline::build_quad_layout(d, o);
    CHECK(again.stats.repair_rounds == 0);
    CHECK(again.stats.patches == sheets.stats.patches);
    CHECK(again.ring_nodes == sheets.ring_nodes);
    o.start_ring_nodes.push_back({0.0});
    CHECK(contains(message_of<tspline::InputError>([&] { (void)tspline::build_quad_layout(d, o); }),
                   "start_ring_nodes has 2 list(s) for 1 ring(s)"));
    o.start_ring_nodes = {{1.0, 0.5}};
    CHECK(contains(message_of<tspline::InputError>([&] { (void)tspline::build_quad_layout(d, o); }),
                   "not ascending arc lengths"));
  }

  TEST_CASE("patch corners up to 135 degrees: a rejected mesh gets the guard, or has it from the start") {
    if (!tspline::quad_mesher_available()) return;
    tspline::DomainCleaningOptions how;
    how.blunt_tips_below_degrees = 17.5;
    const tspline::Domain d = tspline::validate_domain(
        {tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/isle_of_man.txt"), {}},
        how);
    // The Isle of Man's optimized mesh has a patch corner wider than 135
    // degrees: the same mesh is optimized again with node moves that keep
    // corners in range.
    tspline::QuadLayoutOptions o;
    o.max_patch_corner_degrees = 135.0;
    std::vector<std::string> notes;
    o.progress = [&notes](const std::string& text) { notes.push_back(text); };
    const tspline::QuadLayout rejected_once = tspline::build_quad_layout(d, o);
    CHECK(std::any_of(notes.begin(), notes.end(), [](const std::string& m) {
      return contains(m, "a patch corner outside 1-135 degrees near (") &&
             contains(m, "no node move allowed to put a patch corner out of range");
    }));
    // With the guard from the first mesh on, from the same ring nodes: no
    // rejection, and the same layout (the guarded mesh is the builder's own).
    o.progress = nullptr;
    o.guard_patch_corners = true;
    o.start_ring_nodes = rejected_once.ring_nodes;
    const tspline::QuadLayout guarded = tspline::build_quad_layout(d, o);
    CHECK(guarded.stats.repair_rounds == 0);
    REQUIRE(guarded.layout.patches.size() == rejected_once.layout.patches.size());
    for (std::size_t p = 0; p < guarded.layout.patches.size(); ++p) {
      CHECK(guarded.layout.patches[p].polygon.vertices == rejected_once.layout.patches[p].polygon.vertices);
      CHECK(guarded.layout.patches[p].corners == rejected_once.layout.patches[p].corners);
    }
    check_layout_tiles(d, guarded.layout);
    for (const tspline::Patch& p : guarded.layout.patches)
      for (int k = 0; k < 4; ++k) CHECK(inner_angle(p.polygon.vertices, p.corners[k]) <= 135.0 + 1e-9);
    // The widest corner is checked.
    o.max_patch_corner_degrees = 180.0;
    CHECK(contains(message_of<tspline::InputError>([&] { (void)tspline::build_quad_layout(d, o); }),
                   "between 90 and 180 degrees"));
  }

  TEST_CASE(
      "a memo shared by two layouts of one domain: the second takes the first's mesh and first pass, same "
      "result") {
    if (!tspline::quad_mesher_available()) return;
    tspline::DomainCleaningOptions how;
    how.blunt_tips_below_degrees = 17.5;
    const tspline::Domain d = tspline::validate_domain(
        {tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/bali.txt"), {}}, how);
    // The pillowed layout from the first layout's ring nodes, as parameterize_domain makes it, without a
    // memo.
    const tspline::QuadLayout sheets = tspline::build_quad_layout(d);
    REQUIRE(sheets.stats.corner_sheets >= 1);
    tspline::QuadLayoutOptions pillow;
    pillow.corner_sheets = false;
    pillow.start_ring_nodes = sheets.ring_nodes;
    const tspline::QuadLayout pillowed = tspline::build_quad_layout(d, pillow);
    // The same two with one memo.
    tspline::QuadLayoutOptions first;
    first.memo = tspline::make_quad_layout_memo();
    const tspline::QuadLayout sheets_memo = tspline::build_quad_layout(d, first);
    check_same_layout(sheets_memo, sheets);
    const std::size_t hits_first = first.memo->hits();
    pillow.memo = first.memo;
    const tspline::QuadLayout pillowed_memo = tspline::build_quad_layout(d, pillow);
    check_same_layout(pillowed_memo, pillowed);
    CHECK(pillowed_memo.stats.pillowed_rings == 1);
    // Its first mesh and that mesh's first pass came from the memo.
    CHECK(first.memo->hits() >= hits_first + 2);
    // Another domain is not served by this memo: the same layout as without it, no hit.
    const tspline::Domain neck = tspline::validate_domain({dumbbell(1.0), {}});
    tspline::QuadLayoutOptions other;
    other.memo = first.memo;
    const std::size_t hits_before = first.memo->hits();
    check_same_layout(tspline::build_quad_layout(neck, other), tspline::build_quad_layout(neck));
    CHECK(first.memo->hits() == hits_before);
  }

  TEST_CASE("quad layout of a domain whose holes have needles at vertex 0: cleaned, then laid out and mapped") {
    if (!tspline::quad_mesher_available()) return;
    const tspline::io::DomainInput in =
        tspline::io::read_domain(std::string(TSPLINE_TEST_DATA_DIR) + "/holes/needles.txt");
    std::vector<std::string> notes;
    tspline::DomainCleaningOptions how;
    how.notes = &notes;
    const tspline::Domain d = tspline::validate_domain({in.outer, in.holes}, how);
    CHECK(notes.size() == 3);  // the outer ring and both holes were cleaned
    // Areas (needles.txt): 100 - 0.75 - 2 once the needles are gone.
    CHECK(tspline::domain_area(d) == doctest::Approx(100.0 - 0.75 - 2.0).epsilon(1e-9));
    const tspline::QuadLayout L = tspline::build_quad_layout(d);
    check_layout_tiles(d, L.layout);
    tspline::ParameterizationOptions po;
    po.initial_level = 1;
    tspline::AdaptiveOptions ad;
    ad.max_adapt = 2;
    const tspline::MultiPatchResult R =
        tspline::run_multipatch_parameterization(d, L.layout, L.explanation(), po, ad);
    CHECK(R.certified_valid());
    CHECK(std::abs(R.map_area - R.domain_area) < 1e-3 * R.domain_area);
    CHECK(R.max_gap() <= 1e-12 * R.diameter);
  }

  TEST_CASE(
      "the options are checked before the layout: a bad one stops the run naming the option, not a patch") {
    if (!tspline::quad_mesher_available()) return;
    const tspline::Domain d{rectangle(0, 0, 4, 3), {rectangle(1, 1, 2, 2)}};
    tspline::DomainParameterizationOptions choice;
    choice.layout = tspline::LayoutMode::Quad;
    tspline::ParameterizationOptions po;
    po.smoothing.max_sweeps = 0;
    std::string m = message_of<tspline::InputError>([&] { tspline::parameterize_domain(d, po, {}, choice); });
    CHECK(contains(m, "`smoothing.max_sweeps` must be >= 1"));
    CHECK(!contains(m, "patch"));
    tspline::AdaptiveOptions ad;
    ad.min_jacobian = 0.0;
    m = message_of<tspline::InputError>([&] { tspline::parameterize_domain(d, {}, ad, choice); });
    CHECK(contains(m, "`min_jacobian` must be in (0, 1]"));
    CHECK(!contains(m, "patch"));
    // A maximum level below the default initial level is left to each patch:
    // a quad layout's patches start at level 2.
    po = {};
    po.max_level = 2;
    ad = {};
    ad.max_adapt = 1;
    const tspline::DomainParameterization P = tspline::parameterize_domain(d, po, ad, choice);
    REQUIRE(P.patches);
    CHECK(P.patches->certified_valid());
  }

  TEST_CASE(
      "an absolute tolerance as large as the domain's: each patch fitted at least as closely as alone") {
    if (!tspline::quad_mesher_available()) return;
    // The flange's default tolerance given as an area (--tol): its small
    // patches near the bolt holes once took it as their own, and their ring
    // cleaning removed patch corners ("patch 50 of the layout: corner 1: vertex
    // 1 was removed from the input"). Each patch takes the smaller of the area
    // and tolerance_relative times its own squared diagonal: here the latter
    // everywhere, so the map is the default one, bit for bit.
    const tspline::io::DomainInput in =
        tspline::io::read_domain(std::string(TSPLINE_TEST_DATA_DIR) + "/holes/flange.txt");
    const tspline::Domain d = tspline::validate_domain({in.outer, in.holes});
    const tspline::QuadLayout L = tspline::build_quad_layout(d);
    tspline::AdaptiveOptions ad;
    ad.max_adapt = 2;
    const tspline::MultiPatchResult R =
        tspline::run_multipatch_parameterization(d, L.layout, L.explanation(), {}, ad);
    tspline::ParameterizationOptions po;
    po.tolerance_absolute = po.tolerance_relative * R.diameter * R.diameter;
    const tspline::MultiPatchResult A =
        tspline::run_multipatch_parameterization(d, L.layout, L.explanation(), po, ad);
    CHECK(A.certified_valid());
    REQUIRE(A.patches.size() == R.patches.size());
    for (std::size_t p = 0; p < A.patches.size(); ++p) {
      const double diag = tspline::bounding_box_diagonal(L.layout.patches[p].polygon);
      CHECK(A.patches[p].front.tolerance_area == po.tolerance_relative * diag * diag);
      CHECK(A.patches[p].front.tolerance_area < *po.tolerance_absolute);
      CHECK(A.patches[p].map->control_points() == R.patches[p].map->control_points());
    }
  }

  TEST_CASE("a coarse relative tolerance: the domain cleaned with it, the patches' rings not cleaned again") {
    if (!tspline::quad_mesher_available()) return;
    // tolerance_relative 1e-2 (--tol-rel) once stopped the flange with "patch
    // 50 of the layout: corner 1: vertex 1 was removed from the input": at a
    // small patch's own needle width, an acute patch corner beside a short
    // edge looked like a needle's tip. The domain's rings are cleaned with the
    // run's tolerance; the patches' rings, cut from them, are not cleaned again.
    const tspline::io::DomainInput in =
        tspline::io::read_domain(std::string(TSPLINE_TEST_DATA_DIR) + "/holes/flange.txt");
    tspline::Domain d{in.outer, in.holes};
    tspline::ParameterizationOptions po;
    po.tolerance_relative = 1e-2;
    // A needle out of the outer ring's first edge, half as wide as the run's
    // needle width and twice as long: removed at that width, not at the default.
    const double w = tspline::needle_width_for_ring(d.outer, std::nullopt, po.tolerance_relative);
    {
      std::vector<Eigen::Vector2d> v = d.outer.vertices;
      double area2 = 0.0;
      for (std::size_t i = 0; i < v.size(); ++i)
        area2 += v[i].x() * v[(i + 1) % v.size()].y() - v[i].y() * v[(i + 1) % v.size()].x();
      const Eigen::Vector2d t = (v[1] - v[0]).normalized();
      const Eigen::Vector2d out =
          area2 > 0.0 ? Eigen::Vector2d(t.y(), -t.x()) : Eigen::Vector2d(-t.y(), t.x());
      const Eigen::Vector2d mid = 0.5 * (v[0] + v[1]);
      v.insert(v.begin() + 1, {mid, mid + 2.0 * w * out + 0.25 * w * t, mid + 0.5 * w * t});
      d.outer = make_polygon(v);
    }
    tspline::AdaptiveOptions ad;
    ad.max_adapt = 2;
    tspline::DomainParameterizationOptions choice;
    choice.layout = tspline::LayoutMode::Quad;
    const tspline::DomainParameterization P = tspline::parameterize_domain(d, po, ad, choice);
    REQUIRE(P.patches);
    const tspline::MultiPatchResult& R = *P.patches;
    CHECK(R.certified_valid());
    REQUIRE(R.patches.size() == R.layout.patches.size());
    for (std::size_t p = 0; p < R.patches.size(); ++p)
      CHECK(R.patches[p].front.boundary.polygon().vertices.size() ==
            R.layout.patches[p].polygon.vertices.size());
    // The rings the layout was made from: those of the run's needle width.
    tspline::DomainCleaningOptions how;
    how.needle_width = w;
    const tspline::Domain cleaned = tspline::validate_domain(d, how);
    CHECK(R.domain.outer.vertices == cleaned.outer.vertices);
    // (The needle's tip and one of its base vertices: kept at the default width.)
    CHECK(cleaned.outer.vertices.size() + 2 == tspline::validate_domain(d).outer.vertices.size());
  }

  TEST_CASE("multi-patch map on a quad layout: certified, conforming after adaptive refinement, area") {
    if (!tspline::quad_mesher_available()) return;
    // A rectangular and a round hole (a 48-gon: its patches refine to the boundary tolerance,
    // the cuts' other patches do not, so the knots must be carried across the interfaces).
    std::vector<Eigen::Vector2d> circle;
    for (int k = 0; k < 48; ++k)
      circle.push_back(Eigen::Vector2d(2.8, 1.6) + 0.45 * Eigen::Vector2d(std::cos(k * std::numbers::pi / 24),
                                                                          std::sin(k * std::numbers::pi / 24)));
    tspline::Domain d{rectangle(0, 0, 4, 3), {rectangle(1, 1, 1.8, 1.6), make_polygon(circle)}};
    d = tspline::validate_domain(d);
    const double circle_area = 0.5 * 48 * 0.45 * 0.45 * std::sin(std::numbers::pi / 24);
    tspline::DomainParameterizationOptions choice;
    choice.layout = tspline::LayoutMode::Quad;
    tspline::ParameterizationOptions po;
    po.tolerance_relative = 1e-7;  // the round hole's sides need more than the initial cells
    tspline::AdaptiveOptions ad;
    ad.max_adapt = 3;
    const tspline::DomainParameterization P = tspline::parameterize_domain(d, po, ad, choice);
    REQUIRE(P.patches);
    CHECK(P.layout == "quad");
    const tspline::MultiPatchResult& R = *P.patches;
    CHECK(R.certified_valid());
    CHECK(std::abs(R.map_area - R.domain_area) < 1e-3 * R.domain_area);
    CHECK(R.domain_area == doctest::Approx(12.0 - 0.48 - circle_area));
    CHECK(R.max_gap() <= 1e-12 * R.diameter);
    bool refined = false;
    for (const auto& r : R.patches) refined = refined || r.map->mesh().num_cells() > 16;
    CHECK(refined);
    for (const auto& i : R.interfaces) CHECK(i.same_knots);
  }

  TEST_CASE("the patches' run stops with MultiPatchCancelled once its cancel flag is set, before any patch") {
    const tspline::Domain d = tspline::validate_domain({rectangle(0, 0, 3, 3), {rectangle(1, 1, 2, 2)}});
    std::atomic<bool> cancel{true};
    tspline::MultiPatchOptions mo;
    mo.cancel = &cancel;
    std::atomic<int> started{0};
    const tspline::PatchCallback count = [&](std::size_t, int) { ++started; };
    CHECK_THROWS_AS(tspline::run_multipatch_parameterization(d, std::nullopt, {}, {}, mo, count),
                    tspline::MultiPatchCancelled);
    CHECK(started == 0);
    cancel = false;
    CHECK(tspline::run_multipatch_parameterization(d, std::nullopt, {}, {}, mo, count).certified_valid());
    CHECK(started >= 4);
  }

  TEST_CASE("auto: the patches run while one patch is tried are the patches run after it, reported once kept") {
    if (!tspline::quad_mesher_available()) return;
    // A 64-gon: one patch has corners of 174 degrees (poor); the layout's patches are run
    // as soon as the layout is built, maybe before one patch is judged.
    std::vector<Eigen::Vector2d> v;
    for (int k = 0; k < 64; ++k) v.emplace_back(std::cos(k * std::numbers::pi / 32), std::sin(k * std::numbers::pi / 32));
    const tspline::Domain disk{make_polygon(v), {}};
    std::mutex lock;
    std::vector<std::string> events;  // "stage: text", and "on_patch" for the patch callback
    tspline::ParameterizationOptions po;
    bool waited = false;
    po.progress = [&](const tspline::ProgressEvent& e) {
      {
        std::lock_guard<std::mutex> hold(lock);
        events.push_back(e.stage + ": " + e.text);
      }
      // The single patch's run ends only after a pause, long enough for the
      // layout (about 0.2 s here) to be built and its patches to start: what
      // they report must still come after the verdict.
      if (e.stage == "stop" && e.text.rfind("patch ", 0) != 0 && !waited) {
        waited = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(1500));
      }
    };
    const tspline::PatchCallback on_patch = [&](std::size_t, int) {
      std::lock_guard<std::mutex> hold(lock);
      events.push_back("on_patch");
    };
    const tspline::AdaptiveOptions ad;
    const tspline::DomainParameterization A = tspline::parameterize_domain(disk, po, ad, {}, {}, on_patch);
    REQUIRE(A.layout == "quad");
    REQUIRE(A.patches);
    // In order: the verdict on one patch, the layout, then the patches' lines.
    auto first = [&](const std::function<bool(const std::string&)>& is) {
      return std::find_if(events.begin(), events.end(), is) - events.begin();
    };
    // (Here the verdict comes at the single patch's corners, before its untangling.)
    const auto verdict = first([](const std::string& e) {
      return contains(e, "one patch cannot be good: ") || contains(e, "poor over the whole map");
    });
    const auto layout = first([](const std::string& e) { return e.rfind("layout: quad layout: ", 0) == 0; });
    const auto patches = first([](const std::string& e) {
      return e == "on_patch" || e.rfind("patches: ", 0) == 0 || contains(e, ": patch ");
    });
    const auto patch_lines = std::count_if(events.begin(), events.end(), [](const std::string& e) {
      return contains(e, ": patch ");
    });
    CHECK(verdict < layout);
    CHECK(layout < patches);
    CHECK(patch_lines > 0);
    CHECK(std::count(events.begin(), events.end(), "on_patch") >= static_cast<long>(A.patches->patches.size()));
    // The same map as the patches of layout quad (run after the layout, nothing ahead).
    tspline::DomainParameterizationOptions quad;
    quad.layout = tspline::LayoutMode::Quad;
    const tspline::DomainParameterization Q = tspline::parameterize_domain(disk, {}, ad, quad);
    REQUIRE(Q.patches);
    REQUIRE(Q.patches->patches.size() == A.patches->patches.size());
    for (std::size_t p = 0; p < Q.patches->patches.size(); ++p) {
      CHECK(Q.patches->patches[p].map->control_points() == A.patches->patches[p].map->control_points());
      CHECK(Q.patches->patches[p].dense_quality.min_mean_ratio == A.patches->patches[p].dense_quality.min_mean_ratio);
    }
  }

  TEST_CASE_FIXTURE(UnitSquareAtLevel2,
                    "layout choice: single keeps the one-patch run, auto keeps one patch where it is good") {
    tspline::DomainParameterizationOptions single;
    single.layout = tspline::LayoutMode::Single;
    const tspline::DomainParameterization S = tspline::parameterize_domain(square, po, ad, single);
    REQUIRE(S.single);
    const tspline::ParameterizationResult direct = tspline::run_parameterization(square.outer, po, ad);
    CHECK(S.single->map->mesh().num_cells() == direct.map->mesh().num_cells());
    CHECK(S.single->dense_quality.min_mean_ratio == direct.dense_quality.min_mean_ratio);
    // The unit square is mapped onto itself: certified and good, so auto keeps one patch.
    const tspline::DomainParameterization A = tspline::parameterize_domain(square, po, ad, {});
    CHECK(A.layout == "single");
    CHECK(contains(A.reason, "good over the whole map"));
    // A domain with holes is never one patch.
    const tspline::Domain holed{rectangle(0, 0, 3, 3), {rectangle(1, 1, 2, 2)}};
    CHECK(contains(message_of<tspline::InputError>([&] { (void)tspline::parameterize_domain(holed, po, ad, single); }),
                   "cannot be one patch"));
    CHECK(contains(message_of<tspline::InputError>([] { (void)tspline::parse_layout_mode("quads"); }),
                   "auto, single, quad"));
  }

  TEST_CASE("a quad layout's map below the thresholds: a second layout with larger patches, the better map kept") {
    // The flower (curved petals: no map of it has a scaled Jacobian of 1).
    const tspline::Domain flower{tspline::io::read_polygon(test_support::polygon_file("flower.txt")), {}};
    tspline::ParameterizationOptions po;
    const tspline::AdaptiveOptions ad;
    tspline::DomainParameterizationOptions c;
    c.layout = tspline::LayoutMode::Quad;
    const tspline::DomainParameterization first = tspline::parameterize_domain(flower, po, ad, c);
    REQUIRE(first.patches);
    CHECK(first.patches->certified_valid());
    CHECK_FALSE(contains(first.reason, "second quad layout"));  // good: no second layout
    // A threshold no map of it reaches: the second layout is made; the
    // map kept is certified, and is the second only where it is better.
    c.good.scaled_jacobian = 0.999;
    const tspline::DomainParameterization again = tspline::parameterize_domain(flower, po, ad, c);
    REQUIRE(again.patches);
    CHECK(again.patches->certified_valid());
    INFO(again.reason);
    // The first layout's patches stop at the first below the threshold, and
    // run in full only after the second layout's map is not good either.
    CHECK(contains(again.reason, "below the thresholds (the layout's patch "));
    CHECK(contains(again.reason, "is certified but below the thresholds (scaled Jacobian "));
    CHECK(contains(again.reason,
                   "its other patches were run only to compare), a second quad layout with patches 1.2 "
                   "times larger"));
    auto worse = [](const tspline::MultiPatchResult& R) {
      return std::min(R.min_scaled_jacobian_dense(), R.min_mean_ratio_dense());
    };
    if (contains(again.reason, "gave a better map")) {
      CHECK(worse(*again.patches) > worse(*first.patches));
      CHECK(again.patches->patches.size() != first.patches->patches.size());
    } else {
      CHECK(contains(again.reason, "the first kept"));
      CHECK(worse(*again.patches) == worse(*first.patches));
    }
    // A factor of 1: no second layout.
    c.retry_size_factor = 1.0;
    const tspline::DomainParameterization once = tspline::parameterize_domain(flower, po, ad, c);
    CHECK_FALSE(contains(once.reason, "second quad layout"));
    CHECK(worse(*once.patches) == worse(*first.patches));
  }

  TEST_CASE(
      "auto: the layout's patches run ahead of the single try also stop at the first below the thresholds") {
    // The flower under auto with a threshold no map of it reaches: the single
    // try is not good, the layout's patches (run while it was tried) stop at
    // the first patch, the second layout is not good either, so the first
    // layout's patches run in full to compare; the map kept is certified and
    // the same as under layout quad.
    const tspline::Domain flower{tspline::io::read_polygon(test_support::polygon_file("flower.txt")), {}};
    tspline::ParameterizationOptions po;
    const tspline::AdaptiveOptions ad;
    tspline::DomainParameterizationOptions c;
    c.good.scaled_jacobian = 0.999;
    const tspline::DomainParameterization A = tspline::parameterize_domain(flower, po, ad, c);
    INFO(A.reason);
    REQUIRE(A.patches);
    CHECK(A.layout == "quad");
    CHECK(A.patches->certified_valid());
    // (The flower's single patch has corners on its smooth petals: its try stops there.)
    CHECK(contains(A.reason, "one patch cannot be good: its corner at ("));
    CHECK(contains(A.reason, "(the layout's patch "));  // (which patch: the first to finish on its thread)
    CHECK(contains(A.reason, " is certified but below the thresholds (scaled Jacobian "));
    CHECK(contains(A.reason, "its other patches were run only to compare)"));
    c.layout = tspline::LayoutMode::Quad;
    const tspline::DomainParameterization Q = tspline::parameterize_domain(flower, po, ad, c);
    REQUIRE(Q.patches);
    CHECK(Q.patches->patches.size() == A.patches->patches.size());
    CHECK(Q.patches->min_mean_ratio_dense() == A.patches->min_mean_ratio_dense());
    CHECK(Q.patches->min_scaled_jacobian_dense() == A.patches->min_scaled_jacobian_dense());
  }

  TEST_CASE("auto: a single try whose corners rule out the thresholds stops at its frozen boundary") {
    // The disk: one patch has its four corners on the smooth circle, where the
    // boundary curves meet at about 180 degrees; J there caps both whole-map
    // figures far below the thresholds (corner_quality.h). The try stops
    // before its untangling, and the map kept is the layout's, the same as
    // under layout quad.
    const tspline::Domain disk{tspline::io::read_polygon(test_support::polygon_file("disk.txt")), {}};
    tspline::ParameterizationOptions po;
    const tspline::AdaptiveOptions ad;
    tspline::DomainParameterizationOptions c;
    std::vector<std::string> steps;
    po.progress = [&steps](const tspline::ProgressEvent& e) { steps.push_back(e.text); };
    const tspline::DomainParameterization A = tspline::parameterize_domain(disk, po, ad, c);
    INFO(A.reason);
    REQUIRE(A.patches);
    CHECK(A.layout == "quad");
    CHECK(contains(A.reason, "one patch cannot be good: its corner at ("));
    CHECK(contains(A.reason, "fixes the scaled Jacobian at "));
    CHECK_FALSE(A.rejected_single);
    REQUIRE(A.single_corners);
    const tspline::BoundaryCornerQuality& sj = A.single_corners->scaled;
    CHECK(sj.scaled_jacobian < 0.01);
    CHECK(sj.angle_degrees > 179.0);
    // The scaled Jacobian at a corner is the sine of the angle between the boundary curves.
    CHECK(sj.scaled_jacobian ==
          doctest::Approx(std::sin(sj.angle_degrees * std::numbers::pi / 180.0)).epsilon(1e-6));
    CHECK(A.single_corners->mean_ratio.mean_ratio <= sj.mean_ratio);
    // The try stopped before its untangling and its map's check: no such step
    // before the stop (the layout's patches' steps, run ahead, are held until
    // the layout is kept, after it).
    const auto stop = std::find_if(steps.begin(), steps.end(), [](const std::string& m) {
      return contains(m, "stopped: its corner at (");
    });
    REQUIRE(stop != steps.end());
    CHECK(std::none_of(steps.begin(), stop, [](const std::string& m) {
      return contains(m, "untangling:") || contains(m, "map (iteration");
    }));
    CHECK(std::any_of(stop, steps.end(),
                      [](const std::string& m) { return contains(m, "patch 0: map (iteration 0)"); }));
    c.layout = tspline::LayoutMode::Quad;
    po.progress = nullptr;
    const tspline::DomainParameterization Q = tspline::parameterize_domain(disk, po, ad, c);
    REQUIRE(Q.patches);
    CHECK(Q.patches->patches.size() == A.patches->patches.size());
    CHECK(Q.patches->min_mean_ratio_dense() == A.patches->min_mean_ratio_dense());
    CHECK(Q.patches->min_scaled_jacobian_dense() == A.patches->min_scaled_jacobian_dense());
  }

  TEST_CASE(
      "auto: a single try whose interpolating map folds widely stops at its frozen boundary; a good layout "
      "is kept over it, else the try runs in full") {
    if (!tspline::quad_mesher_available()) return;
    // Bali's one patch: its interpolating map folds (det J <= 0) at about 2 % of
    // the untangling's samples, and untangles to a map far below the thresholds.
    tspline::DomainCleaningOptions how;
    how.blunt_tips_below_degrees = 17.5;
    const tspline::Domain bali = tspline::validate_domain(
        {tspline::io::read_polygon(std::string(TSPLINE_TEST_DATA_DIR) + "/coastlines/bali.txt"), {}}, how);
    tspline::ParameterizationOptions po;
    std::vector<std::string> steps;
    po.progress = [&steps](const tspline::ProgressEvent& e) { steps.push_back(e.text); };
    const tspline::AdaptiveOptions ad;
    tspline::DomainParameterizationOptions c;
    // (Its four corner trials are tangled 100 sweeps into their final stages,
    // which stops the try before this rule: here without that stop.)
    c.first_try_stop_when_tangled = false;
    const tspline::DomainParameterization A = tspline::parameterize_domain(bali, po, ad, c);
    po.progress = nullptr;
    INFO(A.reason);
    REQUIRE(A.patches);
    CHECK(A.layout == "quad");
    CHECK(contains(A.reason, "one patch is stopped: its interpolating map folds (det J <= 0) at "));
    CHECK(contains(A.single_stopped, "% of the untangling's "));
    REQUIRE(A.single_corners);
    CHECK_FALSE(A.rejected_single);
    CHECK(std::none_of(steps.begin(), steps.end(), [](const std::string& m) {
      return contains(m, "untangling:") && !contains(m, "patch ");
    }));
    // The whole try: poor, and the same layout kept (the same map).
    c.first_try_max_folded = 0.0;
    const tspline::DomainParameterization W = tspline::parameterize_domain(bali, po, ad, c);
    REQUIRE(W.patches);
    REQUIRE(W.rejected_single);
    CHECK(W.rejected_single->min_scaled < c.good.scaled_jacobian);
    CHECK(W.single_stopped.empty());
    REQUIRE(W.patches->patches.size() == A.patches->patches.size());
    CHECK(W.patches->min_mean_ratio_dense() == A.patches->min_mean_ratio_dense());
    CHECK(W.patches->min_scaled_jacobian_dense() == A.patches->min_scaled_jacobian_dense());
    // The gear's one patch is good (certified, scaled Jacobian 0.39) though its
    // interpolating map folds at 0.28 % of its samples; stopped at 0.1 % with
    // thresholds its layout misses (0.64) but its corners do not rule out, the
    // try runs again in full and the choice is the whole try's.
    const tspline::Domain gear{tspline::io::read_polygon(test_support::polygon_file("gear.txt")), {}};
    tspline::DomainParameterizationOptions g;
    g.first_try_max_folded = 0.001;
    g.good = {0.7, 0.7};
    g.retry_size_factor = 1.0;
    steps.clear();
    po.progress = [&steps](const tspline::ProgressEvent& e) { steps.push_back(e.text); };
    const tspline::DomainParameterization B = tspline::parameterize_domain(gear, po, ad, g);
    po.progress = nullptr;
    INFO(B.reason);
    CHECK(std::any_of(steps.begin(), steps.end(), [](const std::string& m) {
      return contains(m, "stopped: its interpolating map folds");
    }));
    CHECK(std::any_of(steps.begin(), steps.end(), [](const std::string& m) {
      return contains(m, "one patch tried again to the end, to compare");
    }));
    g.first_try_max_folded = 0.0;
    const tspline::DomainParameterization F = tspline::parameterize_domain(gear, po, ad, g);
    CHECK(B.layout == F.layout);
    CHECK(B.single_stopped.empty());
    REQUIRE(B.rejected_single.has_value() == F.rejected_single.has_value());
    if (B.rejected_single) CHECK(B.rejected_single->min_mean_ratio == F.rejected_single->min_mean_ratio);
    c.first_try_max_folded = 1.5;
    CHECK(contains(
        message_of<tspline::InputError>([&] { (void)tspline::parameterize_domain(bali, po, ad, c); }),
        "largest folded fraction"));
  }

  TEST_CASE("auto: a single try whose every corner trial is tangled after its stages stops there") {
    if (!tspline::quad_mesher_available()) return;
    // The fjords with 20 sweeps per stage: every corner trial's T-mesh keeps
    // inverted cells after its nested stages. The try stops there, before any
    // repair round and fit; a good layout is kept over it, the same map as
    // when the try runs on (it is then stopped by a corner of 179 degrees).
    const tspline::Domain fjords{tspline::io::read_polygon(test_support::polygon_file("fjords.txt")), {}};
    tspline::ParameterizationOptions po;
    po.smoothing.max_sweeps = 20;
    const tspline::AdaptiveOptions ad;
    tspline::DomainParameterizationOptions c;
    const tspline::DomainParameterization A = tspline::parameterize_domain(fjords, po, ad, c);
    INFO(A.reason);
    REQUIRE(A.patches);
    CHECK(A.layout == "quad");
    CHECK(contains(A.reason,
                   "one patch is stopped: every corner trial's T-mesh is tangled after its nested stages"));
    CHECK(contains(A.single_stopped, "not a quick try (it would need repair rounds)"));
    CHECK_FALSE(A.single_corners);
    CHECK_FALSE(A.rejected_single);
    CHECK(tspline::io::layout_report(A)["single_patch_first_try"]["stopped"].get<std::string>().rfind(
              "after its T-mesh optimization: ", 0) == 0);
    c.first_try_stop_when_tangled = false;
    const tspline::DomainParameterization W = tspline::parameterize_domain(fjords, po, ad, c);
    INFO(W.reason);
    REQUIRE(W.patches);
    CHECK(contains(W.reason, "one patch cannot be good: its corner at "));
    REQUIRE(W.patches->patches.size() == A.patches->patches.size());
    CHECK(W.patches->min_mean_ratio_dense() == A.patches->min_mean_ratio_dense());
    CHECK(W.patches->min_scaled_jacobian_dense() == A.patches->min_scaled_jacobian_dense());
  }

  TEST_CASE_FIXTURE(UnitSquareAtLevel2,
                    "auto: a stopped single try is run to the end where the layout is below its corners") {
    // The unit square's single patch has J = I at its corners (scaled
    // Jacobian and J_r 1). A threshold above 1 rules it out at the corners,
    // so its try stops; the layout is not good either, and where its map is
    // below the single patch's corners the try runs again to the end and the
    // usual comparison decides (one patch, better than the layout).
    tspline::DomainParameterizationOptions c;
    c.good.scaled_jacobian = 1.5;
    std::vector<std::string> steps;
    po.progress = [&steps](const tspline::ProgressEvent& e) { steps.push_back(e.text); };
    const tspline::DomainParameterization A = tspline::parameterize_domain(square, po, ad, c);
    po.progress = nullptr;
    INFO(A.reason);
    auto step = [&steps](const std::string& text) {
      return std::any_of(steps.begin(), steps.end(), [&](const std::string& m) { return contains(m, text); });
    };
    CHECK(step("one patch cannot be good: its corner at ("));
    // The layout's map (J_r about 0.7 on the square's patches) is below the
    // single patch's corners (1): the try runs to the end.
    REQUIRE_FALSE(A.patches);
    REQUIRE(A.single);
    CHECK(A.layout == "single");
    CHECK(contains(A.reason, "poorer than one patch"));
    CHECK(step("one patch tried again to the end, to compare"));
    CHECK_FALSE(A.single_corners);
    // The same map as the whole try would give (layout single).
    c.layout = tspline::LayoutMode::Single;
    const tspline::DomainParameterization S = tspline::parameterize_domain(square, po, ad, c);
    REQUIRE(S.single);
    CHECK(S.single->map->mesh().num_cells() == A.single->map->mesh().num_cells());
    CHECK(S.single->dense_quality.min_mean_ratio == A.single->dense_quality.min_mean_ratio);
    CHECK(S.single->dense_quality.min_scaled == A.single->dense_quality.min_scaled);
  }

  TEST_CASE("auto's choice between a certified layout and one patch: the layout where it is good") {
    const tspline::DomainParameterizationOptions c;  // scaled Jacobian >= 0.3 and J_r >= 0.1
    auto figures = [](double sj, double jr) {
      tspline::DenseMapQuality q;
      q.min_scaled = sj;
      q.min_mean_ratio = jr;
      return q;
    };
    CHECK(tspline::reaches_good_quality(figures(0.3, 0.1), c));
    CHECK_FALSE(tspline::reaches_good_quality(figures(0.29, 0.5), c));
    CHECK_FALSE(tspline::reaches_good_quality(figures(0.5, 0.09), c));
    // A mirrored Corsica: one patch SJ 0.282 / J_r 0.279 (certified, below the
    // thresholds), the layout SJ 0.448 / J_r 0.275. The layout is good: kept,
    // though the worse of its figures is 0.004 lower than one patch's.
    CHECK(tspline::keep_layout_over_single(figures(0.448, 0.275), figures(0.282, 0.279), true, c));
    // Neither good: the better worse figure wins (a layout can split a tip one patch keeps whole).
    CHECK_FALSE(tspline::keep_layout_over_single(figures(0.25, 0.2), figures(0.28, 0.26), true, c));
    CHECK(tspline::keep_layout_over_single(figures(0.28, 0.26), figures(0.25, 0.2), true, c));
    // One patch not certified: the layout, whatever its figures.
    CHECK(tspline::keep_layout_over_single(figures(0.05, 0.05), figures(0.9, 0.9), false, c));
  }
}

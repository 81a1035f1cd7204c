// Domains with holes: rings input, domain validation, cut layouts, the
// multi-patch map (conforming interfaces, areas, certification) and its file.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "test_support.h"
#include "toolkit/io/vtu_reader.h"
#include "tspline/multipatch/automatic_cuts.h"
#include "tspline/boundary/border_knots.h"
#include "tspline/boundary/domain.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/multipatch/patch_layout.h"
#include "tspline/boundary/polygon_validation.h"

namespace {

using tspline::Cut;
using tspline::Domain;
using test_support::contains;
using test_support::make_polygon;
using test_support::message_of;

std::string holes_file(const std::string& name) {
  std::string path = TSPLINE_TEST_DATA_DIR;  // (as test_support::polygon_file)
  return path.append("/holes/").append(name);
}

tspline::Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}});
}

Domain read_text_domain(const std::string& path) {
  const tspline::io::DomainInput in = tspline::io::read_domain(path);
  return Domain{in.outer, in.holes};
}

std::string validation_error(const Domain& d) {
  return message_of<tspline::InputError>([&] { (void)tspline::validate_domain(d); });
}

// A domain validated with the default options, and the notes on what it cleaned.
struct ValidatedDomain {
  Domain domain;
  std::vector<std::string> notes;
};
ValidatedDomain validate_with_notes(const Domain& raw) {
  ValidatedDomain out;
  tspline::DomainCleaningOptions how;
  how.notes = &out.notes;
  out.domain = tspline::validate_domain(raw, how);
  return out;
}

// The square [0,4]^2 with the square hole [1,3]^2, cut along the diagonals.
Domain framed_square() { return Domain{square(0, 0, 4, 4), {square(1, 1, 3, 3)}}; }
std::vector<Cut> diagonal_cuts() {
  return {{{1, 1}, {0, 0}}, {{3, 1}, {4, 0}}, {{3, 3}, {4, 4}}, {{1, 3}, {0, 4}}};
}

}  // namespace

TEST_SUITE("holes") {
  TEST_CASE("text rings: blank lines separate rings, comment lines do not") {
    const auto rings = tspline::io::parse_text_rings(
        "# plate\n0 0\n4 0\n# still the outer ring\n4 4\n0 4\n\n1 1\n1 2\n2 2\n\n\n3 3\n3.5 3\n3.5 3.5\n", "t");
    REQUIRE(rings.size() == 3);
    CHECK(rings[0].vertices.size() == 4);
    CHECK(rings[1].vertices.size() == 3);
    CHECK(rings[2].vertices.size() == 3);
    CHECK(rings[2].vertices[1].x() == 3.5);
    CHECK(rings[1].file_index[2] == 2);  // numbering within the ring
    // The bundled plate: a square and a 64-gon.
    const Domain plate = read_text_domain(holes_file("plate_with_hole.txt"));
    CHECK(plate.outer.vertices.size() == 4);
    REQUIRE(plate.holes.size() == 1);
    CHECK(plate.holes[0].vertices.size() == 64);
  }

  TEST_CASE("domain validation: either orientation, area of the outer ring minus the holes") {
    Domain d = framed_square();
    std::reverse(d.holes[0].vertices.begin(), d.holes[0].vertices.end());  // clockwise hole
    std::reverse(d.outer.vertices.begin(), d.outer.vertices.end());        // clockwise outer ring
    const Domain v = tspline::validate_domain(d);
    CHECK(tspline::signed_area(v.outer) == doctest::Approx(16));
    CHECK(tspline::signed_area(v.holes[0]) == doctest::Approx(4));
    CHECK(tspline::domain_area(v) == doctest::Approx(12));
    CHECK(tspline::domain_contains(v, {0.5, 0.5}));
    CHECK_FALSE(tspline::domain_contains(v, {2, 2}));
  }

  TEST_CASE("domain validation: bad holes are named with their edges") {
    // Two holes that cross.
    std::string m = validation_error(Domain{square(0, 0, 10, 10), {square(1, 1, 4, 4), square(3, 3, 6, 6)}});
    CHECK(contains(m, "hole 2 crosses hole 1"));
    CHECK(contains(m, "edge"));
    // A hole touching the outer ring at a vertex.
    m = validation_error(Domain{square(0, 0, 10, 10), {make_polygon({{5, 0}, {6, 2}, {5, 3}, {4, 2}})}});
    CAPTURE(m);
    CHECK(contains(m, "hole 1 touches the outer ring"));
    // A hole crossing the outer ring.
    m = validation_error(Domain{square(0, 0, 10, 10), {square(8, 8, 12, 9)}});
    CHECK(contains(m, "hole 1 crosses the outer ring"));
    // A hole outside, a hole in a hole, a hole that is not a simple polygon.
    m = validation_error(Domain{square(0, 0, 10, 10), {square(20, 20, 21, 21)}});
    CHECK(contains(m, "hole 1 lies outside the outer ring"));
    m = validation_error(Domain{square(0, 0, 10, 10), {square(1, 1, 6, 6), square(2, 2, 3, 3)}});
    CHECK(contains(m, "hole 2 lies inside hole 1"));
    m = validation_error(Domain{square(0, 0, 10, 10), {make_polygon({{1, 1}, {3, 3}, {3, 1}, {1, 3}})}});
    CHECK(contains(m, "Hole 1: "));
  }

  TEST_CASE("domain validation removes needles in every ring, at vertex 0 and mid-ring, one note per ring") {
    const Domain raw = read_text_domain(holes_file("needles.txt"));
    auto raw_area = [](const Domain& d) {
      double a = std::abs(tspline::signed_area(d.outer));
      for (const tspline::Polygon& h : d.holes) a -= std::abs(tspline::signed_area(h));
      return a;
    };
    // The default needle width: 1e-5 x the outer diagonal (about 1.4e-4 here).
    std::vector<std::string> notes;
    tspline::DomainCleaningOptions how;
    how.notes = &notes;
    const Domain v = tspline::validate_domain(raw, how);
    REQUIRE(notes.size() == 3);
    CAPTURE(notes[0]);
    CAPTURE(notes[1]);
    CAPTURE(notes[2]);
    // The needle's tip goes, then its two base vertices are within the width of
    // each other and the later in the file goes too.
    CHECK(notes[0] ==
          "the outer ring: removed vertex 4 (tip of a needle of width 5e-05, narrower than 0.000164: edges 3-4 and "
          "4-5 fold back); removed vertex 5 (lies 5e-05 from vertex 3, closer than the needle width 0.000164)");
    CHECK(notes[1] == "hole 1: removed vertex 0 (tip of a zero-area spike: edges 4-0 and 0-1 overlap)");
    CHECK(notes[2] ==
          "hole 2: removed vertex 0 (tip of a needle of width 2e-05, narrower than 0.000164: edges 6-0 and 0-1 "
          "fold back); removed vertex 6 (lies 2e-05 from vertex 1, closer than the needle width 0.000164)");
    // The file numbering survives (the tips are gone; vertex 1 is now first).
    CHECK(v.outer.vertices.size() == 5);
    REQUIRE(v.holes.size() == 2);
    CHECK(v.holes[0].vertices.size() == 4);
    CHECK(v.holes[1].vertices.size() == 5);
    auto has = [](const tspline::Polygon& p, std::size_t i) {
      return std::find(p.file_index.begin(), p.file_index.end(), i) != p.file_index.end();
    };
    CHECK_FALSE(has(v.outer, 4));
    CHECK_FALSE(has(v.holes[0], 0));
    CHECK_FALSE(has(v.holes[1], 0));
    for (std::size_t i = 0; i < v.holes[1].vertices.size(); ++i)
      CHECK(v.holes[1].vertices[i] == raw.holes[1].vertices[v.holes[1].file_index[i]]);
    for (std::size_t i = 0; i < v.outer.vertices.size(); ++i)
      CHECK(v.outer.vertices[i] == raw.outer.vertices[v.outer.file_index[i]]);
    // Areas: 100 - 0.75 - 2 exactly; the input's area differs by the two thin
    // triangles removed (0.5 x 3 x 5e-5 and 0.5 x 2 x 2e-5); the zero-area
    // spike changes nothing.
    CHECK(tspline::domain_area(v) == doctest::Approx(97.25).epsilon(1e-14));
    CHECK(std::abs(tspline::signed_area(v.holes[0])) == doctest::Approx(0.75).epsilon(1e-14));
    CHECK(std::abs(tspline::signed_area(raw.holes[0])) == doctest::Approx(0.75).epsilon(1e-14));
    CHECK(raw_area(raw) - tspline::domain_area(v) == doctest::Approx(7.5e-5 - 2e-5).epsilon(1e-6));
    // A needle width below the needles' widths keeps the two thin needles (both
    // are simple polygons), and the exact spike still goes.
    notes.clear();
    how.needle_width = 1e-5;
    const Domain w = tspline::validate_domain(raw, how);
    REQUIRE(notes.size() == 1);
    CHECK(contains(notes[0], "hole 1: removed vertex 0"));
    CHECK(w.outer.vertices.size() == 7);
    CHECK(w.holes[1].vertices.size() == 7);
    // Without cleaning, hole 1 is what stopped the Maldives sea.
    CHECK(contains(message_of<tspline::InputError>([&] { (void)tspline::validate_polygon(raw.holes[0]); }),
                   "edges 0-1 and 4-0 overlap"));
  }

  TEST_CASE("Maldives islet 9: its 10 cm needle at vertex 0 goes, and the islet is a valid hole") {
    const Domain raw = read_text_domain(holes_file("maldives_islet9.txt"));
    REQUIRE(raw.holes.size() == 1);
    const auto [v, notes] = validate_with_notes(raw);
    REQUIRE(notes.size() == 1);
    CHECK(notes[0] == "hole 1: removed vertex 0 (tip of a zero-area spike: edges 6-0 and 0-1 overlap)");
    CHECK(v.holes[0].vertices.size() == 6);
    CHECK(std::abs(tspline::signed_area(v.holes[0])) ==
          doctest::Approx(std::abs(tspline::signed_area(raw.holes[0]))).epsilon(1e-13));
  }

  TEST_CASE("domain validation: a triangle is a hole; true crossings are still named with ring and edges") {
    // A triangular islet (the Maldives has 37).
    const Domain t = tspline::validate_domain(Domain{square(0, 0, 10, 10), {make_polygon({{1, 1}, {3, 1}, {2, 2}})}});
    CHECK(tspline::domain_area(t) == doctest::Approx(99));
    // The outer ring still needs four vertices (a patch's corners).
    CHECK(contains(validation_error(Domain{make_polygon({{0, 0}, {10, 0}, {0, 10}}), {}}),
                   "The outer ring: polygon has 3 vertices; at least 4 are needed"));
    // A bow tie in hole 2 (edges 1-2 and 3-4 cross), whatever the needle width.
    const Domain bow{square(0, 0, 10, 10),
                     {square(1, 1, 2, 2), make_polygon({{5, 5}, {6, 5}, {7, 6}, {7, 5}, {6, 6}})}};
    const std::string m = validation_error(bow);
    CAPTURE(m);
    CHECK(contains(m, "Hole 2: polygon is not simple: edges 1-2 and 3-4 intersect near (6.5, 5.5)"));
    tspline::DomainCleaningOptions wide;
    wide.needle_width = 0.1;
    CHECK(message_of<tspline::InputError>([&] { (void)tspline::validate_domain(bow, wide); }) == m);
    // Asked to, a hole that crosses itself becomes its convex hull, with a note.
    std::vector<std::string> notes;
    tspline::DomainCleaningOptions repair;
    repair.repair_crossing_holes = true;
    repair.notes = &notes;
    const Domain fixed = tspline::validate_domain(bow, repair);
    REQUIRE(fixed.holes.size() == 2);
    REQUIRE(notes.size() == 1);
    CHECK(contains(notes[0], "hole 2: crosses itself; replaced by its convex hull (4 of its 5 vertices"));
    // The hull of (5,5), (6,5), (7,6), (7,5), (6,6): the square [6,7] x [5,6] with the triangle to (5,5).
    CHECK(std::abs(tspline::signed_area(fixed.holes[1])) == doctest::Approx(1.5));
    CHECK(tspline::domain_area(fixed) == doctest::Approx(100.0 - 1.0 - 1.5));
    // By default a crossing islet is repaired only if its hull is below the
    // boundary tolerance's area (here 1e-5 x diagonal^2 = 0.002): the hull of
    // this one is 1.5, an input error; with the limit at 1.5 it is repaired.
    tspline::DomainCleaningOptions limit;
    limit.crossing_repair_area = 1.49;
    CHECK(message_of<tspline::InputError>([&] { (void)tspline::validate_domain(bow, limit); }) == m);
    limit.crossing_repair_area = 1.5;
    CHECK(tspline::domain_area(tspline::validate_domain(bow, limit)) == doctest::Approx(100.0 - 1.0 - 1.5));
    // A Maldives islet (hole 37 of seas/maldives.txt, scaled): a Z of four
    // vertices whose lobes cancel, its hull 0.0012 < 0.002: repaired by default.
    const Domain islet{square(0, 0, 10, 10),
                       {make_polygon({{5.04, 5.03}, {5.04, 5.0}, {5.0, 5.0}, {5.0, 4.97}})}};
    const ValidatedDomain islet_validated = validate_with_notes(islet);
    const Domain& hulled = islet_validated.domain;
    const std::vector<std::string>& islet_notes = islet_validated.notes;
    REQUIRE(islet_notes.size() == 1);
    CAPTURE(islet_notes[0]);
    CHECK(contains(islet_notes[0], "hole 1: crosses itself; replaced by its convex hull (4 of its 4 vertices; area 0"));
    CHECK(contains(islet_notes[0], "-> 0.0012, below the boundary tolerance 0.002)"));
    CHECK(tspline::domain_area(hulled) == doctest::Approx(100.0 - 0.0012).epsilon(1e-12));
    // The outer ring is never repaired.
    const Domain outer_bow{make_polygon({{0, 0}, {10, 0}, {0, 10}, {10, 10}}), {}};
    CHECK(contains(message_of<tspline::InputError>([&] { (void)tspline::validate_domain(outer_bow, repair); }),
                   "The outer ring: polygon is not simple"));
  }

  TEST_CASE("domain validation: a hole that is nothing but needles is dropped with a note; holes keep their numbers") {
    // Maldives islet 140: three nearly collinear vertices, no area at the needle width.
    const Domain sliver{square(0, 0, 10, 10),
                        {square(1, 1, 2, 2), make_polygon({{5, 5}, {7, 5.00001}, {6, 5}}), square(3, 3, 4, 4)}};
    const auto [d, notes] = validate_with_notes(sliver);
    CHECK(d.holes.size() == 2);
    REQUIRE(notes.size() == 1);
    CHECK(notes[0] ==
          "hole 2: dropped: it encloses no area once its needles narrower than 0.000141 are removed (an islet below "
          "the boundary tolerance)");
    CHECK(tspline::domain_area(d) == doctest::Approx(98.0));
    // Hole 3 is still hole 3 in messages after hole 2 is gone.
    Domain touching = sliver;
    touching.holes[2] = square(2, 1, 3, 2);  // shares the edge x = 2 with hole 1
    CHECK(contains(validation_error(touching), "hole 3 touches hole 1"));
  }

  TEST_CASE("cuts: crossing, off the rings or out of the domain are named") {
    const Domain d = tspline::validate_domain(framed_square());
    auto err = [&](const std::vector<Cut>& c) {
      return message_of<tspline::InputError>([&] { tspline::validate_cuts(d, c); });
    };
    CHECK(contains(err({{{1, 1}, {2, 0}}, {{2, 1}, {1, 0}}}), "cuts 1 and 2 cross"));
    CHECK(contains(err({{{1, 1}, {0.5, 0.7}}}), "cut 1: its end (0.5, 0.7) lies neither on a ring"));
    CHECK(contains(err({{{1, 2}, {3, 2}}}), "runs outside the domain"));
    CHECK(contains(err({{{0, 2}, {0.5, 2}, {4, 2}}}), "cut 1 crosses hole 1 (edge"));
    // A hole with a single cut leaves a face that is not simple.
    const std::string m =
        message_of<tspline::InputError>([&] { (void)tspline::build_patch_layout(d, {{{1, 1}, {0, 0}}}); });
    CHECK(contains(m, "not simply connected"));
  }

  TEST_CASE("patch layout: four trapezoids whose interfaces are whole sides traversed both ways") {
    const Domain d = tspline::validate_domain(framed_square());
    const tspline::PatchLayout L = tspline::build_patch_layout(d, diagonal_cuts());
    REQUIRE(L.patches.size() == 4);
    REQUIRE(L.interfaces.size() == 4);
    double area = 0;
    for (const tspline::Patch& p : L.patches) {
      CHECK(tspline::signed_area(p.polygon) == doctest::Approx(3));  // (4 + 2) / 2 * 1
      area += tspline::signed_area(p.polygon);
    }
    CHECK(area == doctest::Approx(tspline::domain_area(d)));
    for (const tspline::Interface& f : L.interfaces) {
      const tspline::Patch& a = L.patches[f.patch_a];
      const tspline::Patch& b = L.patches[f.patch_b];
      CHECK(f.patch_a != f.patch_b);
      // Side k runs from corner k to corner k+1: a's start is b's end and conversely.
      CHECK(a.polygon.vertices[a.corners[f.side_a]] == b.polygon.vertices[b.corners[(f.side_b + 1) % 4]]);
      CHECK(a.polygon.vertices[a.corners[(f.side_a + 1) % 4]] == b.polygon.vertices[b.corners[f.side_b]]);
      CHECK(a.side_cut[f.side_a] == static_cast<int>(f.cut));
    }
  }

  TEST_CASE("border knots: refinement makes dyadic border parameters vertices") {
    tspline::TMesh m(2);
    m.build_topology();
    CHECK(tspline::border_params(m, tspline::Side::Top) == std::vector<double>{0, 0.25, 0.5, 0.75, 1});
    tspline::BorderParams want;
    want[static_cast<int>(tspline::Side::Top)] = {0.375};
    want[static_cast<int>(tspline::Side::Left)] = {0.0625};
    CHECK(tspline::refine_to_border_params(m, want, 10) > 0);
    const auto top = tspline::border_params(m, tspline::Side::Top);
    const auto left = tspline::border_params(m, tspline::Side::Left);
    CHECK(std::count(top.begin(), top.end(), 0.375) == 1);
    CHECK(std::count(left.begin(), left.end(), 0.0625) == 1);
    // t on the top side is xi = 1 - t.
    CHECK(m.find_vertex({tspline::TMesh::kRoot * 5 / 8, tspline::TMesh::kRoot}) >= 0);
    CHECK(m.check_invariants().empty());
    want[0] = {0.3};
    CHECK_THROWS_AS(tspline::refine_to_border_params(m, want, 10), tspline::InputError);
  }

  TEST_CASE("automatic cuts of the plate: the plate's corners are corners of the patches, never inside a side") {
    const Domain d = tspline::validate_domain(read_text_domain(holes_file("plate_with_hole.txt")));
    const tspline::AutomaticCuts a = tspline::automatic_cuts(d);
    const tspline::PatchLayout L = tspline::build_patch_layout(d, a.cuts);
    CHECK(L.patches.size() >= 4);
    CHECK(L.patches.size() == L.cuts.size());  // Euler: patches = cuts - holes + 1
    for (const Eigen::Vector2d& corner : d.outer.vertices) {
      std::size_t as_corner = 0, inside_side = 0;
      for (const tspline::Patch& p : L.patches)
        for (std::size_t i = 0; i < p.polygon.vertices.size(); ++i) {
          if (p.polygon.vertices[i] != corner) continue;
          const bool is_corner = std::find(p.corners.begin(), p.corners.end(), i) != p.corners.end();
          (is_corner ? as_corner : inside_side) += 1;
        }
      CHECK(as_corner >= 1);
      CHECK(inside_side == 0);
    }
    // Every cut end lies on a ring: the hole (radius 1 about (2, 2)) or the square's border.
    for (const Cut& c : a.cuts)
      for (const Eigen::Vector2d& e : {c.front(), c.back()}) {
        const bool on_hole = std::abs((e - Eigen::Vector2d(2, 2)).norm() - 1.0) < 1e-6;
        const bool on_square = e.x() == 0 || e.x() == 4 || e.y() == 0 || e.y() == 4;
        CHECK((on_hole || on_square));
      }
  }

  TEST_CASE("multi-patch map of the plate: certified, watertight, area of the plate minus the hole") {
    const Domain d = read_text_domain(holes_file("plate_with_hole.txt"));
    const tspline::MultiPatchResult R =
        tspline::run_multipatch_parameterization(d, std::nullopt, {}, {});
    CHECK(R.patches.size() >= 4);
    CHECK(R.certified_valid());
    CHECK(R.min_relative_det_bound() > 0);
    CHECK(R.min_mean_ratio_dense() > 0.2);
    // Polygon areas: 16 minus the 64-gon inscribed in the unit circle.
    const double hole = 0.5 * 64 * std::sin(2 * std::numbers::pi / 64);
    CHECK(R.domain_area == doctest::Approx(16 - hole).epsilon(1e-6));
    CHECK(std::abs(R.map_area - R.domain_area) < 1e-3 * R.domain_area);
    CHECK(R.max_gap() <= 1e-12 * R.diameter);
    for (const auto& i : R.interfaces) CHECK(i.same_knots);
    // The gap is measured, not assumed: patch 0 against itself along another side is far off.
    const tspline::Interface& f = R.layout.interfaces[0];
    CHECK(tspline::interface_gap(*R.patches[f.patch_a].map, f.side_a, *R.patches[f.patch_a].map,
                                 (f.side_a + 1) % 4) > 0.1);

    SUBCASE("format version 2 reads back bit-identically; the version-1 reader refuses it") {
      const auto dir = test_support::scratch_dir("holes", "v2");
      const nlohmann::json report = tspline::io::multipatch_report(R, "plate_with_hole.txt", 0.0);
      tspline::io::write_multipatch_outputs(R, dir.string(), report, 2);
      const tspline::io::LoadedMaps m = tspline::io::read_maps_file((dir / "tspline.json").string());
      CHECK(m.version == 2);
      REQUIRE(m.patches.size() == R.patches.size());
      REQUIRE(m.interfaces.size() == R.layout.interfaces.size());
      CHECK(m.interfaces[2].side_b == R.layout.interfaces[2].side_b);
      for (std::size_t p = 0; p < R.patches.size(); ++p)
        for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0.3, 0.7), Eigen::Vector2d(1, 0.25)})
          CHECK(m.patches[p].map.point(uv) == R.patches[p].map->point(uv));
      const std::string msg = message_of<tspline::InputError>(
          [&] { (void)tspline::io::read_tspline_file((dir / "tspline.json").string()); });
      CHECK(contains(msg, "unsupported version 2"));
      for (const char* f : {"surface.vtu", "boundary.vtu", "parametric_tmesh.vtu", "physical_tmesh.vtu",
                            "control_net.vtu", "report.json"})
        CHECK(std::filesystem::exists(dir / f));
      // physical_tmesh.vtu (read back with VTK): every patch's cells drawn
      // through its map, none flagged invalid on this certified map.
      const toolkit::io::VtuMesh phys = toolkit::io::read_vtu((dir / "physical_tmesh.vtu").string());
      std::size_t cells = 0;
      for (const auto& r : R.patches) cells += r.map->mesh().num_cells();
      REQUIRE(phys.cells.size() == cells);
      std::size_t flagged = 0, uncertified = 0;
      for (std::size_t c = 0; c < cells; ++c) {
        flagged += phys.cell_scalars.at("valid")[c] != 1.0;
        uncertified += phys.cell_scalars.at("certified")[c] != 1.0;
        CHECK(phys.cell_scalars.at("det_lower_bound")[c] > 0.0);
      }
      CHECK(flagged == 0);
      CHECK(uncertified == 0);
      CHECK(phys.cell_scalars.at("patch").back() == static_cast<double>(R.patches.size() - 1));

      // The VTU files in pieces of one patch each: the same grids as in one piece.
      const auto pieces_dir = test_support::scratch_dir("holes", "v2_pieces");
      tspline::io::write_multipatch_outputs(R, pieces_dir.string(), report, 2,
                                            toolkit::io::VtuCompression::LZ4, 1);
      for (const char* f : {"surface.vtu", "surface_bezier.vtu", "physical_tmesh.vtu", "control_net.vtu",
                            "boundary.vtu", "parametric_tmesh.vtu"}) {
        CAPTURE(f);
        const toolkit::io::VtuMesh one = toolkit::io::read_vtu((dir / f).string());
        const toolkit::io::VtuMesh many = toolkit::io::read_vtu((pieces_dir / f).string());
        CHECK(many.points == one.points);
        CHECK(many.cells == one.cells);
        CHECK(many.point_scalars == one.point_scalars);
        CHECK(many.cell_scalars == one.cell_scalars);
        std::size_t piece_tags = 0;
        const std::string text = test_support::slurp(pieces_dir / f);
        for (std::size_t at = text.find("<Piece"); at != std::string::npos; at = text.find("<Piece", at + 1))
          ++piece_tags;
        CHECK(piece_tags == R.patches.size());
      }
    }

    SUBCASE(
        "report.json comes last: where a file of any lane cannot be written, there is none, nor a "
        "temporary") {
      const nlohmann::json report = tspline::io::multipatch_report(R, "plate_with_hole.txt", 0.0);
      // A directory where the file should go: its rename fails. One file of
      // each of the three lanes (physical_tmesh.vtu's lane writes report.json),
      // and a file after the shared pieces.
      for (const char* blocked :
           {"surface.vtu", "surface_bezier.vtu", "physical_tmesh.vtu", "control_net.vtu"}) {
        CAPTURE(blocked);
        const auto dir = test_support::scratch_dir("holes", std::string("blocked_") + blocked);
        std::filesystem::create_directory(dir / blocked);
        CHECK_THROWS(tspline::io::write_multipatch_outputs(R, dir.string(), report, 2));
        CHECK(!std::filesystem::exists(dir / "report.json"));
        for (const auto& e : std::filesystem::directory_iterator(dir))
          CHECK(e.path().filename().string().find(".tmp.") == std::string::npos);
      }
    }
  }

  TEST_CASE("stop_when: the run stops at the first patch it names, later patches are not run") {
    const Domain d = read_text_domain(holes_file("plate_with_hole.txt"));
    tspline::MultiPatchOptions multi;
    multi.threads = 1;  // the patches one after the other
    std::vector<std::size_t> seen;
    multi.stop_when = [&seen](std::size_t p, const tspline::ParameterizationResult& r) {
      seen.push_back(p);
      CHECK(r.map);
      return seen.size() == 3 ? std::string("is the one asked for") : std::string();
    };
    const std::string what = message_of<tspline::MultiPatchStopped>(
        [&] { (void)tspline::run_multipatch_parameterization(d, std::nullopt, {}, {}, multi); });
    REQUIRE(seen.size() == 3);
    CHECK(what == "patch " + std::to_string(seen[2]) + " is the one asked for");
    const std::vector<std::size_t> stopped = seen;
    // Never stopping: every patch once (the first round), the same map as
    // without; with a stop_when the patches run sharpest corner first (the
    // least sine of a patch polygon's corner angles), the run above in the same order.
    seen.clear();
    multi.stop_when = [&seen](std::size_t p, const tspline::ParameterizationResult&) {
      seen.push_back(p);
      return std::string();
    };
    const tspline::MultiPatchResult R =
        tspline::run_multipatch_parameterization(d, std::nullopt, {}, {}, multi);
    REQUIRE(seen.size() == R.patches.size());
    std::vector<std::size_t> sorted = seen;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t p = 0; p < sorted.size(); ++p) CHECK(sorted[p] == p);
    CHECK(std::equal(stopped.begin(), stopped.end(), seen.begin()));
    auto worst_sine = [&R](std::size_t p) {
      const tspline::Patch& patch = R.layout.patches[p];
      const auto& v = patch.polygon.vertices;
      double w = 1.0;
      for (const std::size_t c : patch.corners) {
        const Eigen::Vector2d a = v[(c + 1) % v.size()] - v[c], b = v[(c + v.size() - 1) % v.size()] - v[c];
        w = std::min(w, (a.x() * b.y() - a.y() * b.x()) / (a.norm() * b.norm()));
      }
      return w;
    };
    for (std::size_t k = 0; k + 1 < seen.size(); ++k) CHECK(worst_sine(seen[k]) <= worst_sine(seen[k + 1]));
    CHECK(worst_sine(seen.front()) < worst_sine(seen.back()));  // (the plate's patches differ)
    CHECK(R.certified_valid());
    // Without a stop_when the same map.
    multi.stop_when = nullptr;
    const tspline::MultiPatchResult plain =
        tspline::run_multipatch_parameterization(d, std::nullopt, {}, {}, multi);
    REQUIRE(plain.patches.size() == R.patches.size());
    for (std::size_t p = 0; p < R.patches.size(); ++p)
      CHECK(plain.patches[p].map->control_points() == R.patches[p].map->control_points());
  }

  TEST_CASE("multi-patch map of the flange (bore and four bolt holes)") {
    const Domain d = read_text_domain(holes_file("flange.txt"));
    REQUIRE(d.holes.size() == 5);
    const tspline::MultiPatchResult R = tspline::run_multipatch_parameterization(d, std::nullopt, {}, {});
    CHECK(R.certified_valid());
    CHECK(std::abs(R.map_area - R.domain_area) < 1e-3 * R.domain_area);
    CHECK(R.max_gap() <= 1e-12 * R.diameter);
    // Every cut is the side of exactly two patches.
    CHECK(R.layout.interfaces.size() == R.layout.cuts.size());
  }

  TEST_CASE("two holes in line in a disk: chords from cut ends into the rings where no chord between cut ends fits") {
    auto circle = [](double cx, double cy, double r, int n) {
      std::vector<Eigen::Vector2d> v;
      for (int k = 0; k < n; ++k)
        v.emplace_back(cx + r * std::cos(2 * std::numbers::pi * k / n), cy + r * std::sin(2 * std::numbers::pi * k / n));
      return make_polygon(v);
    };
    const Domain d{circle(0, 0, 5, 80), {circle(-2, 0, 1, 32), circle(2, 0, 1, 32)}};
    const tspline::MultiPatchResult R = tspline::run_multipatch_parameterization(d, std::nullopt, {}, {});
    CHECK(R.certified_valid());
    CHECK(std::abs(R.map_area - R.domain_area) < 1e-3 * R.domain_area);
    CHECK(R.max_gap() <= 1e-12 * R.diameter);
    // The layout partitions the domain: each patch's four corners are distinct
    // vertices of its polygon in counter-clockwise order (one descent in the
    // cyclic sequence of their indices), its polygon is counter-clockwise, and
    // the patches' areas add up to the domain's.
    double area = 0.0;
    for (const tspline::Patch& p : R.layout.patches) {
      int descents = 0;
      for (int k = 0; k < 4; ++k) {
        CHECK(p.corners[k] < p.polygon.vertices.size());
        CHECK(p.corners[(k + 1) % 4] != p.corners[k]);
        descents += p.corners[(k + 1) % 4] < p.corners[k];
      }
      CHECK(descents == 1);
      CHECK(tspline::signed_area(p.polygon) > 0.0);
      area += tspline::signed_area(p.polygon);
    }
    CHECK(area == doctest::Approx(tspline::domain_area(d)).epsilon(1e-12));
  }

  TEST_CASE("GeoJSON polygon with an interior ring: the hole is read and projected with the outer ring") {
    const tspline::io::DomainInput in = tspline::io::read_domain(holes_file("corsica_lake_lonlat.geojson"));
    REQUIRE(in.holes.size() == 1);
    CHECK(in.description["units"] == "m");
    const Domain v = tspline::validate_domain(Domain{in.outer, in.holes});
    // Corsica is some 8,700 km^2; the lake a small part of it.
    CHECK(tspline::domain_area(v) > 7e9);
    CHECK(tspline::domain_area(v) < 1e10);
    CHECK(tspline::signed_area(v.holes[0]) < 0.05 * tspline::signed_area(v.outer));
  }
}

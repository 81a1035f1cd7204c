// Boundary: reading polygons from text and GeoJSON (suite "boundary").
#include <doctest/doctest.h>

#include "test_support.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/boundary/polygon_validation.h"

using namespace tspline;
using V2 = Eigen::Vector2d;

namespace {

Polygon read(const std::string& name) {
  return io::read_polygon(test_support::polygon_file(name + ".txt"));
}

Polygon make(const std::vector<V2>& v) { return test_support::make_polygon(v); }
using test_support::contains;
using test_support::message_of;

std::string geojson_ring(const std::vector<V2>& v) {
  std::ostringstream s;
  s << "[";
  for (std::size_t i = 0; i <= v.size(); ++i) {
    const V2& q = v[i % v.size()];  // closed ring, as GeoJSON requires
    s << (i ? "," : "") << "[" << std::to_string(q.x()) << "," << std::to_string(q.y()) << "]";
  }
  s << "]";
  return s.str();
}

}  // namespace

TEST_SUITE("boundary_io") {
  TEST_CASE("text format: comments, blank lines, commas, repeated closing vertex dropped") {
    const std::string txt = "# header\n\n  0 0   # origin\n1,0\n 1 , 1\n\t0 1\n+0.0 0e0\n\n# end\n";
    const Polygon p = io::parse_polygon(txt, "mem.txt");
    REQUIRE(p.vertices.size() == 4);
    CHECK(p.vertices[2] == V2(1, 1));
    CHECK(p.file_index == std::vector<std::size_t>{0, 1, 2, 3});
    CHECK(signed_area(validate_polygon(p)) == doctest::Approx(1.0));
  }

  TEST_CASE("GeoJSON Polygon, Feature and FeatureCollection (through GDAL) give the same vertices as the text") {
    const Polygon txt = read("disk");
    const std::string ring = geojson_ring(txt.vertices);
    const std::string poly = R"({"type":"Polygon","coordinates":[)" + ring + "]}";
    const std::string feat = R"({"type":"Feature","properties":{},"geometry":)" + poly + "}";
    const std::string coll = R"({"type":"FeatureCollection","features":[)" + feat + "]}";
    io::DomainReadOptions planar;
    planar.planar = true;
    for (const std::string& s : {poly, feat, coll}) {
      const Polygon g = io::read_geojson_domain(s, planar, "mem.geojson").outer;
      REQUIRE(g.vertices.size() == txt.vertices.size());  // closing vertex dropped
      for (std::size_t i = 0; i < g.vertices.size(); ++i) {
        CHECK(g.vertices[i].x() == doctest::Approx(txt.vertices[i].x()).epsilon(1e-12));
        CHECK(g.vertices[i].y() == doctest::Approx(txt.vertices[i].y()).epsilon(1e-12));
        CHECK(g.file_index[i] == i);
      }
    }
    // The text reader refuses GeoJSON, saying where it goes.
    CHECK(contains(message_of<InputError>([&] { io::parse_polygon(poly, "mem.geojson"); }),
                   "mem.geojson: GeoJSON, not a text polygon: read it with read_domain"));
  }

  TEST_CASE("GeoJSON MultiPolygon: largest by default, or chosen by index; its holes kept") {
    const std::string small = geojson_ring({V2(5, 5), V2(6, 5), V2(6, 6), V2(5, 6)});
    const std::string big = geojson_ring({V2(0, 0), V2(3, 0), V2(3, 3), V2(0, 3)});
    const std::string hole = geojson_ring({V2(1, 1), V2(1, 2), V2(2, 2), V2(2, 1)});
    const std::string mp =
        R"({"type":"MultiPolygon","coordinates":[[)" + small + "],[" + big + "," + hole + "]]}";
    io::DomainReadOptions opt;
    opt.planar = true;
    const io::DomainInput largest = io::read_geojson_domain(mp, opt, "m.json");
    CHECK(largest.outer.vertices[1] == V2(3, 0));
    REQUIRE(largest.holes.size() == 1);
    CHECK(std::abs(signed_area(largest.holes[0])) == doctest::Approx(1.0));
    opt.polygon_index = 0;
    CHECK(io::read_geojson_domain(mp, opt, "m.json").outer.vertices[0] == V2(5, 5));
    opt.polygon_index = 2;
    CHECK(contains(message_of<InputError>([&] { io::read_geojson_domain(mp, opt, "m.json"); }),
                   "`polygon_index` 2 out of range (2 polygons)"));
  }

  // ---- bad input, one case each ------------------------------------------------

  TEST_CASE("error: empty file") {
    const std::string path = (std::filesystem::temp_directory_path() / "tspline_test_empty.txt").string();
    std::ofstream(path).close();
    CHECK(message_of<InputError>([&] { io::read_polygon(path); }) == path + ": empty (no vertices)");
    std::filesystem::remove(path);
  }

  TEST_CASE("error: only comments") {
    CHECK(message_of<InputError>([] { io::parse_polygon("# a\n\n  # b\n", "c.txt"); }) ==
          "c.txt: empty (no vertices)");
  }

  TEST_CASE("error: NaN and inf coordinates") {
    CHECK(message_of<InputError>([] { io::parse_polygon("0 0\n1 0\nnan 1\n0 1\n", "n.txt"); }) ==
          "n.txt:3: coordinate is not finite");
    CHECK(message_of<InputError>([] { io::parse_polygon("0 0\n1 -inf\n", "i.txt"); }) ==
          "i.txt:2: coordinate is not finite");
    // Polygons built in code are checked by validation, naming the vertex.
    const Polygon p = make({V2(0, 0), V2(1, 0), V2(1, std::nan("")), V2(0, 1)});
    CHECK(contains(message_of<InputError>([&] { validate_polygon(p); }),
                   "vertex 2 has a non-finite coordinate"));
  }

  TEST_CASE("error: non-numeric line") {
    CHECK(message_of<InputError>([] { io::parse_polygon("# c\n0 0\n1 zero\n", "b.txt"); }) ==
          "b.txt:3: expected two numbers 'x y', got '1 zero'");
    CHECK(message_of<InputError>([] { io::parse_polygon("0 0 0\n", "b.txt"); }) ==
          "b.txt:1: expected two numbers 'x y', got '0 0 0'");
  }

  TEST_CASE("error: invalid GeoJSON") {
    CHECK_THROWS_AS(io::read_geojson_domain("{\"type\": ", {}, "j.json"), InputError);
    CHECK_THROWS_AS(io::read_geojson_domain(R"({"type":"Polygon","coordinates":[[[0,0],[1]]]})", {}, "j.json"),
                    InputError);
  }

  TEST_CASE("error: unreadable path") {
    CHECK(message_of<IoError>([] { io::read_polygon("/nonexistent/dir/x.txt"); }) ==
          "cannot open '/nonexistent/dir/x.txt': No such file or directory");
  }

  TEST_CASE("error: directory path") {
    const std::string dir = std::string(TSPLINE_TEST_DATA_DIR) + "/polygons";
    CHECK(message_of<IoError>([&] { io::read_polygon(dir); }) == "cannot read '" + dir + "': Is a directory");
  }

}  // TEST_SUITE

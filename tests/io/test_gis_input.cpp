// GIS input through GDAL/OGR (gis_reader.h): a Shapefile and a GeoPackage made
// here with GDAL's API from a bundled coastline's text file give the same
// polygon and the same map as the text; holes are kept; a GeoJSON in
// longitude/latitude (Corsica) is projected to metres with an equal-area
// projection, and the map's area is Corsica's; bad choices are input errors.
#include <doctest/doctest.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <Eigen/LU>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "test_support.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/errors.h"
#include "tspline/io/gis_reader.h"
#include "tspline/io/polygon_reader.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string gis_file(const std::string& name) {
  std::string path = TSPLINE_TEST_DATA_DIR;  // (as test_support::polygon_file)
  return path.append("/gis/").append(name);
}

using Ring = std::vector<Eigen::Vector2d>;

/// Writes one layer "coast" of polygons (outer ring, holes) with the given CRS
/// (EPSG code, 0: none) through the GDAL driver `driver`.
void write_layer(const std::string& driver, const fs::path& path, const std::vector<std::vector<Ring>>& polygons,
                 int epsg) {
  GDALAllRegister();
  GDALDriver* drv = GetGDALDriverManager()->GetDriverByName(driver.c_str());
  REQUIRE(drv != nullptr);
  GDALDataset* ds = drv->Create(path.string().c_str(), 0, 0, 0, GDT_Unknown, nullptr);
  REQUIRE(ds != nullptr);
  OGRSpatialReference srs;
  if (epsg) REQUIRE(srs.importFromEPSG(epsg) == OGRERR_NONE);
  OGRLayer* layer = ds->CreateLayer("coast", epsg ? &srs : nullptr, wkbPolygon, nullptr);
  REQUIRE(layer != nullptr);
  for (const auto& rings : polygons) {
    OGRFeature f(layer->GetLayerDefn());
    OGRPolygon poly;
    for (const Ring& r : rings) {
      OGRLinearRing ring;
      for (const auto& p : r) ring.addPoint(p.x(), p.y());
      ring.closeRings();
      poly.addRing(&ring);
    }
    f.SetGeometry(&poly);
    REQUIRE(layer->CreateFeature(&f) == OGRERR_NONE);
  }
  GDALClose(ds);
}

/// Area of the map's image: the integral of det J over [0,1]^2 (4x4 Gauss
/// points on every Bezier element, where the map is smooth).
double map_area(const tspline::TSplineMap& map) {
  double area = 0.0;
  std::vector<tspline::QuadraturePoint> q;
  for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c) {
    tspline::cell_quadrature(map.basis(), c, 4, q);
    for (const auto& p : q) area += p.weight * map.jacobian(p.uv).determinant();
  }
  return area;
}

double shoelace(const Ring& r) {
  double a = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const auto& p = r[i];
    const auto& q = r[(i + 1) % r.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

/// Control points of a tspline.json, as written.
json control_points(const fs::path& tspline_json) {
  const json doc = json::parse(test_support::slurp(tspline_json));
  json pts = json::array();
  for (const json& f : doc["functions"]) pts.push_back(f["control_point"]);
  return pts;
}

}  // namespace

TEST_SUITE("gis_input") {
  TEST_CASE("Shapefile and GeoPackage of a coastline: the text's polygon and map") {
    const fs::path d = test_support::scratch_dir("gis_input", "shp_gpkg");
    const std::string txt = gis_file("isle_of_man.txt");
    const tspline::Polygon text = tspline::io::read_polygon(txt);
    REQUIRE(text.vertices.size() > 50);
    // A projected CRS (ETRS89-extended / LAEA Europe) is kept as it is.
    write_layer("ESRI Shapefile", d / "isle_of_man.shp", {{text.vertices}}, 3035);
    write_layer("GPKG", d / "isle_of_man.gpkg", {{text.vertices}}, 3035);
    for (const char* f : {"isle_of_man.shp", "isle_of_man.gpkg"}) {
      CAPTURE(f);
      CHECK(tspline::io::is_gis_file((d / f).string()));
      const tspline::io::DomainInput dom = tspline::io::read_domain((d / f).string());
      CHECK(dom.outer.vertices == text.vertices);
      CHECK(dom.outer.file_index == text.file_index);
      CHECK(dom.holes.empty());
      CHECK(dom.description["projection"].is_null());
      CHECK(test_support::contains(dom.description["crs"].get<std::string>(), "LAEA Europe"));
    }
    CHECK(!tspline::io::is_gis_file(txt));
    // The same map through the command, file by file.
    json reference;
    for (const std::string& f :
         std::vector<std::string>{txt, (d / "isle_of_man.shp").string(), (d / "isle_of_man.gpkg").string()}) {
      CAPTURE(f);
      const fs::path out = d / ("out_" + fs::path(f).extension().string().substr(1));
      const auto r = test_support::run_app("param --layout single " + test_support::quoted(f) + " -q --out " +
                                           test_support::quoted(out), d);
      CAPTURE(r.err);
      REQUIRE(r.exit_code == 0);
      const json pts = control_points(out / "tspline.json");
      CHECK(pts.size() > 100);
      if (reference.is_null()) reference = pts;
      CHECK(pts == reference);
      const json rep = json::parse(test_support::slurp(out / "report.json"));
      CHECK(rep["input_geometry"]["format"] == (f == txt ? "text" : f.ends_with(".shp") ? "ESRI Shapefile" : "GPKG"));
    }
  }

  TEST_CASE("holes are kept, several features and layers chosen by option") {
    const fs::path d = test_support::scratch_dir("gis_input", "holes");
    const Ring outer = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
    const Ring hole = {{4, 4}, {4, 6}, {6, 6}, {6, 4}};
    const Ring small = {{20, 0}, {21, 0}, {21, 1}, {20, 1}};
    write_layer("GPKG", d / "two.gpkg", {{small}, {outer, hole}}, 0);
    tspline::io::DomainInput dom = tspline::io::read_domain((d / "two.gpkg").string());
    CHECK(dom.outer.vertices == outer);  // the largest by default
    REQUIRE(dom.holes.size() == 1);
    CHECK(dom.holes[0].vertices == hole);
    CHECK(dom.description["feature"] == 1);
    // GDAL writes GeoPackage's "Undefined geographic SRS" for a layer without a CRS: kept planar.
    CHECK(dom.description["projection"].is_null());
    CHECK(test_support::contains(dom.description["units"].get<std::string>(), "no CRS"));
    CHECK(dom.description["holes"] == 1);
    tspline::io::DomainReadOptions opt;
    opt.feature = 0;
    dom = tspline::io::read_domain((d / "two.gpkg").string(), opt);
    CHECK(dom.outer.vertices == small);
    opt = {};
    opt.layer = "coast";
    opt.polygon_index = 0;
    CHECK(tspline::io::read_domain((d / "two.gpkg").string(), opt).outer.vertices == small);
    opt.layer = "nonesuch";
    CHECK(test_support::contains(test_support::message_of<tspline::InputError>(
                                     [&] { tspline::io::read_domain((d / "two.gpkg").string(), opt); }),
                                 "no layer 'nonesuch' (layers: coast)"));
    opt = {};
    opt.feature = 5;
    CHECK(test_support::contains(test_support::message_of<tspline::InputError>(
                                     [&] { tspline::io::read_domain((d / "two.gpkg").string(), opt); }),
                                 "`feature` 5 out of range"));
    // The command: a bad layer is one error line, exit 1; --layer on a text polygon too.
    auto r = test_support::run_app("param " + test_support::quoted(d / "two.gpkg") + " --layer x --out " +
                                       test_support::quoted(d / "o"),
                                   d);
    CHECK(r.exit_code == 1);
    CHECK(test_support::count_lines(r.err) == 1);
    r = test_support::run_app("param " + test_support::quoted(gis_file("isle_of_man.txt")) + " --layer 0 --out " +
                                  test_support::quoted(d / "o"),
                              d);
    CHECK(r.exit_code == 1);
    CHECK(test_support::contains(r.err, "apply to GIS files"));
    CHECK(test_support::count_lines(r.err) == 1);
  }

  TEST_CASE("GeoJSON is longitude/latitude: Corsica in metres, equal-area, 8,665 km2") {
    const std::string file = gis_file("corsica_lonlat.geojson");
    const tspline::io::DomainInput dom = tspline::io::read_domain(file);
    const json& proj = dom.description["projection"];
    REQUIRE(proj.is_object());
    CHECK(proj["name"] == "Lambert azimuthal equal-area");
    CHECK(test_support::contains(proj["proj"].get<std::string>(), "+proj=laea"));
    // The centre lies on Corsica (about 9.1 E, 42.15 N).
    CHECK(proj["lon_0"].get<double>() == doctest::Approx(9.1).epsilon(0.01));
    CHECK(proj["lat_0"].get<double>() == doctest::Approx(42.15).epsilon(0.005));
    CHECK(dom.description["units"] == "m");
    const double polygon_area = std::abs(shoelace(dom.outer.vertices));
    // A boundary tolerance of 1e-4 of the squared diagonal (default 1e-5): 292
    // cells instead of ~1,500, about 1 s instead of 12 (3 min under ASan), and
    // the area is still well within 1 %.
    tspline::ParameterizationOptions opt;
    opt.tolerance_relative = 1e-4;
    const tspline::ParameterizationResult r = tspline::run_parameterization(dom.outer, opt, {});
    REQUIRE(r.map.has_value());
    CHECK(r.certified_valid());
    const double area = map_area(*r.map);
    MESSAGE("Corsica: polygon area " << polygon_area / 1e6 << " km2, map area " << area / 1e6 << " km2");
    CHECK(area / 1e6 == doctest::Approx(8665.0).epsilon(0.01));
    CHECK(area == doctest::Approx(polygon_area).epsilon(5e-3));  // measured 0.09 %
    // --planar keeps the degrees.
    tspline::io::DomainReadOptions planar;
    planar.planar = true;
    const tspline::io::DomainInput deg = tspline::io::read_domain(file, planar);
    CHECK(deg.description["projection"].is_null());
    CHECK(deg.outer.vertices[0].x() == doctest::Approx(8.566286).epsilon(1e-12));
    CHECK(deg.outer.vertices[0].y() == doctest::Approx(42.208234).epsilon(1e-12));
  }

  TEST_CASE("planar GeoJSON coordinates are an input error without --planar") {
    const fs::path d = test_support::scratch_dir("gis_input", "planar_geojson");
    {
      std::ofstream f(d / "big.geojson");
      f << R"({"type": "Polygon", "coordinates": [[[0, 0], [1000, 0], [1000, 1000], [0, 1000], [0, 0]]]})";
    }
    const std::string msg = test_support::message_of<tspline::InputError>(
        [&] { tspline::io::read_domain((d / "big.geojson").string()); });
    CHECK(test_support::contains(msg, "not longitude/latitude"));
    CHECK(test_support::contains(msg, "set `planar` to keep them"));
    tspline::io::DomainReadOptions planar;
    planar.planar = true;
    CHECK(tspline::io::read_domain((d / "big.geojson").string(), planar).outer.vertices.size() == 4);
    const auto r = test_support::run_app("param " + test_support::quoted(d / "big.geojson") + " --out " +
                                             test_support::quoted(d / "o"),
                                         d);
    CHECK(r.exit_code == 1);
    CHECK(test_support::count_lines(r.err) == 1);
    // A missing file is an I/O error.
    CHECK_THROWS_AS(tspline::io::read_domain((d / "nonesuch.shp").string()), tspline::IoError);
  }
}

"""tspline.parameterize on domains with holes given as Python objects (rings,
a shapely polygon, a GeoJSON dict in longitude/latitude, a shapely polygon in
longitude/latitude with crs=, an object with its own .crs as GeoPandas gives
it) against `tspline param` on the domain's file: the same certified
multi-patch map, every patch equal to `tspline eval` to round-off. (The
layouts are the layout builder's and may change: the tests compare the module
with the program, not with patch counts.)"""
import json

import numpy as np
import pytest
import shapely.geometry as sg

import tspline
from conftest import DATA, cli_eval, cli_param, diameter, text_rings

PLATE = DATA / "holes" / "plate_with_hole.txt"
PLATE_LONLAT = DATA / "holes" / "plate_with_hole_lonlat.geojson"


@pytest.fixture(scope="module")
def plate_cli(tmp_path_factory):
    out = tmp_path_factory.mktemp("plate_cli")
    return out / "tspline.json", cli_param(PLATE, out)


@pytest.fixture(scope="module")
def plate_lonlat_cli(tmp_path_factory):
    out = tmp_path_factory.mktemp("plate_lonlat_cli")
    return out / "tspline.json", cli_param(PLATE_LONLAT, out)


def check_same_as_cli(m, cli, with_eval=False):
    """m is the map `tspline param` wrote: patches, interfaces, layout, and every
    patch's S at random parameters and the square's corners equal to the
    program's file read back (bit for bit), and with_eval to what `tspline eval`
    prints for every patch (17 digits: to round-off)."""
    cli_file, cli_report = cli
    doc = json.loads(cli_file.read_text())
    assert m.certified_valid and cli_report["totals"]["certified_valid"]
    assert m.version == doc["version"] == 2
    assert m.patches == len(doc["patches"]) >= 2
    assert [(f["patch_a"], f["side_a"], f["patch_b"], f["side_b"]) for f in m.interfaces] == [
        (f["patch_a"], f["side_a"], f["patch_b"], f["side_b"]) for f in doc["interfaces"]]
    assert m.report["layout"]["chosen"] == cli_report["layout"]["chosen"]
    assert m.report["totals"]["cells"] == cli_report["totals"]["cells"]
    uv = np.concatenate([np.random.default_rng(3).uniform(0, 1, (8, 2)), [[0, 0], [1, 0], [1, 1], [0, 1]]])
    tol = 1e-13 * diameter(m)
    written = tspline.load(cli_file)
    for p in range(m.patches):
        assert np.array_equal(m.evaluate(uv, patch=p), written.evaluate(uv, patch=p))
        if with_eval:
            assert np.abs(m.evaluate(uv, patch=p) - cli_eval(cli_file, uv, patch=p)).max() <= tol


def test_holes_from_rings(plate_cli):
    rings = text_rings(PLATE)
    assert len(rings) == 2
    m = tspline.parameterize(rings)
    check_same_as_cli(m, plate_cli, with_eval=True)
    assert m.source == "rings"
    assert m.report["input_geometry"]["format"] == "rings"
    assert m.report["input_geometry"]["holes"] == 1


def test_holes_from_a_shapely_polygon(plate_cli):
    outer, hole = text_rings(PLATE)
    m = tspline.parameterize(sg.Polygon(outer, [hole]))
    check_same_as_cli(m, plate_cli)
    geometry = m.report["input_geometry"]
    assert geometry["crs"] is None and geometry["projection"] is None  # shapely: no CRS, planar
    assert geometry["holes"] == 1


def test_a_shapely_multipolygon_picks_the_largest_or_the_given_polygon(plate_cli):
    outer, hole = text_rings(PLATE)
    islet = sg.box(10.0, 10.0, 10.5, 10.5)
    both = sg.MultiPolygon([islet, sg.Polygon(outer, [hole])])
    check_same_as_cli(tspline.parameterize(both), plate_cli)  # the largest
    small = tspline.parameterize(both, polygon=0, layout="single", init_level=2, max_adapt=1)
    assert small.patches == 1 and small.certified_valid
    corners = small.evaluate(np.array([[0.0, 0.0], [1.0, 1.0]]))
    assert np.allclose(np.sort(corners[:, 0]), [10.0, 10.5], atol=1e-12)


def test_holes_from_a_geojson_dict_in_longitude_latitude(plate_lonlat_cli):
    doc = json.loads(PLATE_LONLAT.read_text())
    m = tspline.parameterize(doc)
    check_same_as_cli(m, plate_lonlat_cli, with_eval=True)
    geometry, cli_geometry = m.report["input_geometry"], plate_lonlat_cli[1]["input_geometry"]
    assert geometry["units"] == "m"
    assert geometry["projection"]["lon_0"] == cli_geometry["projection"]["lon_0"]
    assert geometry["projection"]["lat_0"] == cli_geometry["projection"]["lat_0"]
    # Projected to metres: the plate is 0.04 degrees, some 3.3 km by 4.4 km.
    assert 3.0e3 < diameter(m) / np.sqrt(2) < 5.0e3


def test_a_shapely_polygon_in_longitude_latitude_with_crs(plate_lonlat_cli):
    geometry = sg.shape(json.loads(PLATE_LONLAT.read_text())["features"][0]["geometry"])
    check_same_as_cli(tspline.parameterize(geometry, crs="EPSG:4326"), plate_lonlat_cli)
    # The same rings as arrays, with the same CRS.
    rings = [np.array(geometry.exterior.coords), np.array(geometry.interiors[0].coords)]
    check_same_as_cli(tspline.parameterize(rings, crs="EPSG:4326"), plate_lonlat_cli)


def test_planar_keeps_a_geojson_dict_as_given(plate_cli):
    outer, hole = text_rings(PLATE)
    doc = {"type": "Polygon", "coordinates": [outer.tolist() + [outer[0].tolist()], hole.tolist() + [hole[0].tolist()]]}
    check_same_as_cli(tspline.parameterize(doc, planar=True), plate_cli)
    # Without planar=True a GeoJSON dict is longitude/latitude (RFC 7946), as a
    # .geojson file: coordinates beyond 360 / 90 degrees are an input error that says so.
    far = {"type": "Polygon", "coordinates": [[[100 * x, 100 * y] for x, y in ring] for ring in doc["coordinates"]]}
    with pytest.raises(tspline.InputError, match="longitude/latitude.*set planar"):
        tspline.parameterize(far)


class WGS84:
    """What pyproj.CRS offers the module: to_wkt() (here WGS 84 as OGC WKT 1, longitude first)."""

    def to_wkt(self):
        return ('GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],'
                'PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]]')


class GeoSeriesLike:
    """What a GeoPandas GeoSeries / GeoDataFrame offers: __geo_interface__ (a
    FeatureCollection) and .crs (a pyproj.CRS, or None)."""

    def __init__(self, collection, crs):
        self.__geo_interface__ = collection
        self.crs = crs


def test_an_object_in_its_own_crs_as_geopandas_gives_it(plate_lonlat_cli, plate_cli):
    doc = json.loads(PLATE_LONLAT.read_text())
    m = tspline.parameterize(GeoSeriesLike(doc, WGS84()))
    check_same_as_cli(m, plate_lonlat_cli)
    assert m.report["input_geometry"]["units"] == "m"
    # Without a CRS (.crs None) the coordinates are planar, as given: the plate's text file.
    outer, hole = text_rings(PLATE)
    planar = {"type": "Polygon", "coordinates": [outer.tolist(), hole.tolist()]}
    check_same_as_cli(tspline.parameterize(GeoSeriesLike(planar, None)), plate_cli)
    with pytest.raises(TypeError, match="crs: expected a str"):
        tspline.parameterize(GeoSeriesLike(planar, 4326))

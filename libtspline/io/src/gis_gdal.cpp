// GIS input through GDAL/OGR, geographic coordinates projected with PROJ: the
// GIS part of read_domain and read_geojson_domain (gis_reader.cpp), linked into
// the libraries and built alone as the module the tspline program loads
// (tspline/detail/gis_backend.h).
#include <cpl_error.h>
#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>

#include "tspline/boundary/plane.h"
#include "tspline/detail/gis_backend.h"
#include "tspline/errors.h"

namespace tspline::io {
namespace {

namespace fs = std::filesystem;
using Ring = std::vector<Eigen::Vector2d>;

struct RawPolygon {
  Ring outer;
  std::vector<Ring> holes;
  std::size_t feature = 0;
};

/// GDAL's error handler for the scope: nothing printed (the library has no I/O
/// side effects); the last message is kept for our exception.
struct QuietGdal {
  QuietGdal() {
    static std::once_flag once;
    std::call_once(once, [] { GDALAllRegister(); });
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
  static std::string last() {
    const char* m = CPLGetLastErrorMsg();
    return m && *m ? std::string(": ") + m : std::string();
  }
};

struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};

Ring ring_of(const OGRLinearRing* r) {
  Ring out;
  if (!r) return out;
  out.reserve(static_cast<std::size_t>(r->getNumPoints()));
  for (int i = 0; i < r->getNumPoints(); ++i) out.emplace_back(r->getX(i), r->getY(i));
  if (out.size() >= 2 && out.front() == out.back()) out.pop_back();
  return out;
}

void add_polygon(const OGRPolygon* p, std::size_t feature, std::vector<RawPolygon>& out) {
  if (!p || p->IsEmpty()) return;
  RawPolygon raw;
  raw.outer = ring_of(p->getExteriorRing());
  for (int h = 0; h < p->getNumInteriorRings(); ++h) raw.holes.push_back(ring_of(p->getInteriorRing(h)));
  raw.feature = feature;
  out.push_back(std::move(raw));
}

void collect(const OGRGeometry* g, std::size_t feature, std::vector<RawPolygon>& out) {
  if (!g) return;
  switch (wkbFlatten(g->getGeometryType())) {
    case wkbPolygon:
      add_polygon(g->toPolygon(), feature, out);
      break;
    case wkbMultiPolygon:
      for (const OGRPolygon* p : *g->toMultiPolygon()) add_polygon(p, feature, out);
      break;
    case wkbGeometryCollection:
      for (const OGRGeometry* c : *g->toGeometryCollection()) collect(c, feature, out);
      break;
    default:
      break;  // points and lines are not domains
  }
}

using tspline::signed_area;  // of a Ring

/// Area centroid of a ring (its vertex mean if degenerate).
Eigen::Vector2d centroid(const Ring& r) {
  const double a = signed_area(r);
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  if (std::abs(a) > 0) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Eigen::Vector2d& p = r[i];
      const Eigen::Vector2d& q = r[(i + 1) % r.size()];
      c += (p + q) * (p.x() * q.y() - q.x() * p.y());
    }
    return c / (6.0 * a);
  }
  for (const auto& p : r) c += p;
  return c / static_cast<double>(std::max<std::size_t>(r.size(), 1));
}

Polygon to_polygon(const Ring& r) {
  Polygon p;
  p.vertices = r;
  p.file_index.resize(r.size());
  for (std::size_t i = 0; i < r.size(); ++i) p.file_index[i] = i;
  return p;
}

/// The domain of an open dataset; `path` names it in messages.
DomainInput read_dataset(GDALDataset& dataset, const std::string& path, const DomainReadOptions& options);

}  // namespace

namespace {

// The layer named (or numbered) `name`. \throw InputError listing the layers.
OGRLayer* named_layer(GDALDataset& ds, const std::string& path, const std::string& name) {
  OGRLayer* layer = ds.GetLayerByName(name.c_str());
  if (!layer && !name.empty() &&
      std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    const long index = std::stol(name);
    if (index < ds.GetLayerCount()) layer = ds.GetLayer(static_cast<int>(index));
  }
  if (layer) return layer;
  std::string names;
  for (int i = 0; i < ds.GetLayerCount(); ++i)
    names += std::string(i ? ", " : "") + ds.GetLayer(i)->GetName();
  throw InputError(path + ": no layer '" + name + "' (layers: " + names + ")");
}

// The polygons of the chosen layer (the named one, or the first with polygons)
// and feature (all, or the one asked for).
struct LayerPolygons {
  OGRLayer* layer = nullptr;
  std::vector<RawPolygon> polygons;
};

LayerPolygons layer_polygons(GDALDataset& ds, const std::string& path, const DomainReadOptions& options) {
  LayerPolygons out;
  std::size_t features = 0;
  auto read_layer = [&](OGRLayer* l, bool all_features) {
    out.polygons.clear();
    features = 0;
    l->ResetReading();
    for (const auto& f : *l) {
      if (all_features || !options.feature || *options.feature == features)
        collect(f->GetGeometryRef(), features, out.polygons);
      ++features;
    }
  };
  if (options.layer) out.layer = named_layer(ds, path, *options.layer);
  for (int i = 0; i < ds.GetLayerCount() && !out.layer; ++i) {  // the first layer with polygons
    read_layer(ds.GetLayer(i), true);
    if (!out.polygons.empty()) out.layer = ds.GetLayer(i);
  }
  if (!out.layer) throw InputError(path + ": no layer with polygons");
  read_layer(out.layer, false);
  if (options.feature && *options.feature >= features)
    throw InputError(path + ": `feature` " + std::to_string(*options.feature) + " out of range (layer '" +
                     out.layer->GetName() + "' has " + std::to_string(features) + " features)");
  if (out.polygons.empty())
    throw InputError(path + ": layer '" + std::string(out.layer->GetName()) + "' has no polygons");
  return out;
}

// The polygon asked for by index, or the one of largest area.
std::size_t pick_polygon(const std::vector<RawPolygon>& polys, const std::string& path,
                         const DomainReadOptions& options) {
  if (options.polygon_index) {
    if (*options.polygon_index >= polys.size())
      throw InputError(path + ": `polygon_index` " + std::to_string(*options.polygon_index) +
                       " out of range (" + std::to_string(polys.size()) + " polygons)");
    return *options.polygon_index;
  }
  std::size_t pick = 0;
  for (std::size_t i = 1; i < polys.size(); ++i)
    if (std::abs(signed_area(polys[i].outer)) > std::abs(signed_area(polys[pick].outer))) pick = i;
  return pick;
}

// Longitude/latitude in `srs` projected to metres by the Lambert azimuthal
// equal-area projection at the outer ring's centroid (areas kept); what was
// done goes to the description `d`.
void project_to_metres(RawPolygon& chosen, const OGRSpatialReference& srs, const std::string& path,
                       nlohmann::json& d) {
  for (const auto& p : chosen.outer)
    if (!(std::abs(p.x()) <= 360.0 && std::abs(p.y()) <= 90.0))
      throw InputError(path + ": coordinates (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) +
                       ") are not longitude/latitude degrees, which the layer's CRS (" +
                       d["crs"].get<std::string>() + ") requires; set `planar` to keep them as they are");
  const Eigen::Vector2d c = centroid(chosen.outer);
  OGRSpatialReference src(srs);
  src.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRSpatialReference dst;
  dst.CopyGeogCSFrom(&src);
  dst.SetProjCS("Lambert azimuthal equal-area at the domain's centroid");
  dst.SetLAEA(c.y(), c.x(), 0.0, 0.0);
  dst.SetLinearUnits(SRS_UL_METER, 1.0);
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&src, &dst));
  if (!ct) throw InputError(path + ": cannot project the layer's CRS with PROJ" + QuietGdal::last());
  auto project = [&](Ring& r) {
    std::vector<double> x(r.size()), y(r.size());
    for (std::size_t i = 0; i < r.size(); ++i) x[i] = r[i].x(), y[i] = r[i].y();
    std::vector<int> ok(r.size(), 0);
    if (!r.empty() && !ct->Transform(r.size(), x.data(), y.data(), nullptr, ok.data()))
      throw InputError(path + ": PROJ could not project the coordinates" + QuietGdal::last());
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (!ok[i] || !std::isfinite(x[i]) || !std::isfinite(y[i]))
        throw InputError(path + ": PROJ could not project vertex " + std::to_string(i));
      r[i] = {x[i], y[i]};
    }
  };
  project(chosen.outer);
  for (auto& h : chosen.holes) project(h);
  char* proj4 = nullptr;
  dst.exportToProj4(&proj4);
  d["projection"] = {{"name", "Lambert azimuthal equal-area"},
                     {"lon_0", c.x()},
                     {"lat_0", c.y()},
                     {"centre", "area centroid of the outer ring in longitude/latitude"},
                     {"proj", proj4 ? proj4 : ""}};
  CPLFree(proj4);
  d["units"] = "m";
}

DomainInput read_dataset(GDALDataset& ds, const std::string& path, const DomainReadOptions& options) {
  LayerPolygons found = layer_polygons(ds, path, options);
  const std::size_t pick = pick_polygon(found.polygons, path, options);
  RawPolygon chosen = std::move(found.polygons[pick]);
  if (chosen.outer.empty()) throw InputError(path + ": the chosen polygon has an empty outer ring");
  nlohmann::json d = {{"format", ds.GetDriver() ? ds.GetDriver()->GetDescription() : "unknown"},
                      {"layer", found.layer->GetName()},
                      {"feature", chosen.feature},
                      {"polygon", pick},
                      {"polygons", found.polygons.size()},
                      {"holes", chosen.holes.size()},
                      {"crs", nullptr},
                      {"projection", nullptr}};
  const OGRSpatialReference* layer_srs = found.layer->GetSpatialRef();
  OGRSpatialReference given_srs;
  if (options.crs) {  // the caller's CRS instead of the layer's
    if (given_srs.SetFromUserInput(options.crs->c_str()) != OGRERR_NONE)
      throw InputError(path + ": crs '" + *options.crs + "' is not a CRS that GDAL knows" +
                       QuietGdal::last());
    layer_srs = &given_srs;
  }
  if (layer_srs) d["crs"] = layer_srs->GetName() ? layer_srs->GetName() : "unnamed";
  // GeoPackage's placeholders for "no CRS" (srs_id 0 and -1, "Undefined
  // geographic/Cartesian SRS", what GDAL writes for a layer without one) are
  // no CRS: the coordinates are kept.
  if (layer_srs && layer_srs->GetName() && std::strncmp(layer_srs->GetName(), "Undefined", 9) == 0)
    layer_srs = nullptr;
  const bool geographic = layer_srs && layer_srs->IsGeographic();
  if (options.planar || !geographic)
    d["units"] = options.planar ? "as in the file (`planar`)"
                 : layer_srs    ? std::string(layer_srs->IsProjected() ? "projected CRS, kept" : "CRS kept")
                                : std::string("no CRS: planar, as in the file");
  else
    project_to_metres(chosen, *layer_srs, path, d);
  DomainInput out;
  out.outer = to_polygon(chosen.outer);
  for (const auto& h : chosen.holes) out.holes.push_back(to_polygon(h));
  out.description = std::move(d);
  return out;
}

DomainInput read_gis_file(const std::string& path, const DomainReadOptions& options) {
  const QuietGdal quiet;
  std::unique_ptr<GDALDataset, DatasetCloser> ds(static_cast<GDALDataset*>(
      GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr)));
  if (!ds) {
    std::error_code ec;
    if (fs::is_directory(path, ec))
      throw IoError("cannot read " + path + ": a directory, and not a vector dataset that GDAL reads");
    throw InputError(path + ": not a vector file that GDAL reads" + QuietGdal::last());
  }
  return read_dataset(*ds, path, options);
}

DomainInput read_gis_geojson(const std::string& geojson, const DomainReadOptions& options,
                             const std::string& name) {
  const QuietGdal quiet;
  // A GDAL in-memory file (/vsimem/), unique to this call.
  static std::atomic<unsigned long> counter{0};
  const std::string mem = "/vsimem/tspline_domain_" + std::to_string(++counter) + ".geojson";
  VSILFILE* f = VSIFileFromMemBuffer(mem.c_str(), reinterpret_cast<GByte*>(const_cast<char*>(geojson.data())),
                                     static_cast<vsi_l_offset>(geojson.size()), FALSE);
  if (!f) throw IoError(name + ": cannot make an in-memory file for GDAL" + QuietGdal::last());
  VSIFCloseL(f);
  struct Unlink {
    std::string path;
    ~Unlink() { VSIUnlink(path.c_str()); }
  } unlink{mem};
  const char* const drivers[] = {"GeoJSON", nullptr};
  std::unique_ptr<GDALDataset, DatasetCloser> ds(static_cast<GDALDataset*>(
      GDALOpenEx(mem.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, drivers, nullptr, nullptr)));
  if (!ds) throw InputError(name + ": not GeoJSON that GDAL reads" + QuietGdal::last());
  DomainInput in = read_dataset(*ds, name, options);
  in.description["layer"] = nullptr;  // GDAL's name of the in-memory file
  return in;
}

const detail::GisBackend kGdalBackend{&read_gis_file, &read_gis_geojson};

}  // namespace

namespace detail {

const GisBackend& gis_backend() { return kGdalBackend; }

}  // namespace detail
}  // namespace tspline::io

extern "C" const tspline::io::detail::GisBackend* tspline_gis_backend() {
  return &tspline::io::detail::gis_backend();
}

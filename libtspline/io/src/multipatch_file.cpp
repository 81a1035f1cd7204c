#include "tspline/io/multipatch_file.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tspline/errors.h"
#include "toolkit/io/atomic_file.h"

namespace tspline::io {
namespace {

using json = nlohmann::json;
constexpr int kVersion = 2;
const char* const kSides[4] = {"bottom", "right", "top", "left"};

int side_index(const json& v, const std::string& where) {
  if (v.is_string())
    for (int k = 0; k < 4; ++k)
      if (v.get<std::string>() == kSides[k]) return k;
  throw InputError(where + ": expected \"bottom\", \"right\", \"top\" or \"left\", found " + v.dump());
}

std::size_t index_in(const json& v, std::size_t n, const std::string& where) {
  if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<std::size_t>() >= n)
    throw InputError(where + ": expected an integer in [0, " + std::to_string(n) + "), found " + v.dump());
  return v.get<std::size_t>();
}

const json& member(const json& o, const char* key, const std::string& where) {
  if (!o.is_object() || !o.contains(key)) throw InputError(where + ": missing \"" + key + "\"");
  return o[key];
}

}  // namespace

const char* side_name(int side) { return kSides[side & 3]; }

void write_multipatch_file(const std::string& path, const std::vector<const TSplineMap*>& maps,
                           const std::vector<TSplineFileMeta>& metas, const std::vector<Interface>& interfaces,
                           const std::vector<Cut>& cuts, const std::string& source, const Domain* domain) {
  if (maps.size() != metas.size() || maps.empty())
    throw InputError("write_multipatch_file: one metadata record per map is required");
  for (std::size_t i = 0; i < interfaces.size(); ++i) {
    const Interface& f = interfaces[i];
    if (f.patch_a >= maps.size() || f.patch_b >= maps.size() || f.cut >= cuts.size())
      throw InputError("write_multipatch_file: interface " + std::to_string(i) + " is out of range");
  }
  // Streamed to the file patch by patch: a sea of 9,000 patches makes a file
  // of 110 MB, which a string would hold twice.
  toolkit::io::write_atomic(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw IoError("cannot write '" + path + "': cannot open the temporary file");
    out << "{\n  \"format\": \"tspline\",\n  \"version\": " << kVersion << ",\n  \"degree\": 3,\n";
    out << "  \"source\": " << json(source).dump() << ",\n  \"patches\": [\n";
    for (std::size_t p = 0; p < maps.size(); ++p) out << (p ? ",\n" : "") << tspline_file_text(*maps[p], metas[p]);
    out << "  ],\n  \"interfaces\": [";
    for (std::size_t i = 0; i < interfaces.size(); ++i) {
      const Interface& f = interfaces[i];
      out << (i ? ",\n    " : "\n    ") << json({{"cut", f.cut},
                                                {"patch_a", f.patch_a},
                                                {"side_a", side_name(f.side_a)},
                                                {"patch_b", f.patch_b},
                                                {"side_b", side_name(f.side_b)},
                                                {"orientation", "reversed"}})
                                              .dump();
    }
    out << "\n  ],\n  \"cuts\": [";
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      json pts = json::array();
      for (const auto& p : cuts[c]) pts.push_back({p.x(), p.y()});
      out << (c ? ",\n    " : "\n    ") << pts.dump();
    }
    out << "\n  ]";
    if (domain) {
      // The rings, one per line: {"polygon": [[x, y], ...], "file_index": [...]}.
      out << ",\n  \"domain\": [";
      std::vector<const Polygon*> rings = {&domain->outer};
      for (const Polygon& h : domain->holes) rings.push_back(&h);
      for (std::size_t r = 0; r < rings.size(); ++r) {
        json pts = json::array();
        for (const auto& p : rings[r]->vertices) pts.push_back({p.x(), p.y()});
        out << (r ? ",\n    " : "\n    ") << json({{"polygon", pts}, {"file_index", rings[r]->file_index}}).dump();
      }
      out << "\n  ]";
    }
    out << "\n}\n";
    out.flush();
    if (!out) throw IoError("cannot write '" + path + "': write failed (disk full?)");
  });
}

namespace {

// The document at path; null if it is not JSON.
json parsed_or_null(const std::string& path) {
  try {
    return json::parse(read_text_file(path));
  } catch (const json::exception&) {
    return nullptr;
  }
}

// The points [x, y] of array a.
std::vector<Eigen::Vector2d> points_of(const json& a, const std::string& where) {
  std::vector<Eigen::Vector2d> points;
  for (const json& q : a) {
    if (!q.is_array() || q.size() != 2 || !q[0].is_number() || !q[1].is_number())
      throw InputError(where + ": expected points [x, y]");
    points.emplace_back(q[0].get<double>(), q[1].get<double>());
  }
  return points;
}

std::vector<LoadedTSpline> read_patches(const json& doc, const std::string& path) {
  const json& patches = member(doc, "patches", path + ": /");
  if (!patches.is_array() || patches.empty()) throw InputError(path + ": /patches: expected a non-empty array");
  std::vector<LoadedTSpline> out;
  for (std::size_t p = 0; p < patches.size(); ++p)
    out.push_back(tspline_from_json(patches[p], path + ": /patches/" + std::to_string(p)));
  return out;
}

std::vector<Cut> read_cuts(const json& doc, const std::string& path) {
  const json& cuts = member(doc, "cuts", path + ": /");
  if (!cuts.is_array()) throw InputError(path + ": /cuts: expected an array");
  std::vector<Cut> out;
  for (std::size_t c = 0; c < cuts.size(); ++c) {
    const std::string where = path + ": /cuts/" + std::to_string(c);
    if (!cuts[c].is_array()) throw InputError(where + ": expected an array of points");
    out.push_back(points_of(cuts[c], where));
  }
  return out;
}

// One ring of "domain": {"polygon": [[x, y], ...], "file_index": [...]}.
Polygon read_ring(const json& r, const std::string& where) {
  Polygon ring;
  const json& pts = member(r, "polygon", where);
  const json& idx = member(r, "file_index", where);
  if (!pts.is_array() || !idx.is_array() || idx.size() != pts.size())
    throw InputError(where + ": expected \"polygon\" and \"file_index\" arrays of one size");
  ring.vertices = points_of(pts, where + "/polygon");
  for (const json& f : idx) {
    if (!f.is_number_integer() || f.get<long long>() < 0)
      throw InputError(where + "/file_index: expected non-negative integers");
    ring.file_index.push_back(f.get<std::size_t>());
  }
  return ring;
}

// The rings of "domain": the outer ring, then the holes.
Domain read_domain(const json& rings, const std::string& path) {
  if (!rings.is_array() || rings.empty()) throw InputError(path + ": /domain: expected a non-empty array of rings");
  Domain d;
  for (std::size_t r = 0; r < rings.size(); ++r) {
    Polygon ring = read_ring(rings[r], path + ": /domain/" + std::to_string(r));
    if (r == 0) d.outer = std::move(ring);
    else d.holes.push_back(std::move(ring));
  }
  return d;
}

// The interfaces, whose cuts and patches are checked against those read.
std::vector<Interface> read_interfaces(const json& doc, const std::string& path, std::size_t cuts,
                                       std::size_t patches) {
  const json& faces = member(doc, "interfaces", path + ": /");
  if (!faces.is_array()) throw InputError(path + ": /interfaces: expected an array");
  std::vector<Interface> out;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const std::string where = path + ": /interfaces/" + std::to_string(i);
    const json& f = faces[i];
    Interface itf;
    itf.cut = index_in(member(f, "cut", where), cuts, where + "/cut");
    itf.patch_a = index_in(member(f, "patch_a", where), patches, where + "/patch_a");
    itf.patch_b = index_in(member(f, "patch_b", where), patches, where + "/patch_b");
    itf.side_a = side_index(member(f, "side_a", where), where + "/side_a");
    itf.side_b = side_index(member(f, "side_b", where), where + "/side_b");
    if (member(f, "orientation", where) != "reversed")
      throw InputError(where + "/orientation: expected \"reversed\"");
    out.push_back(itf);
  }
  return out;
}

}  // namespace

LoadedMaps read_maps_file(const std::string& path) {
  const json doc = parsed_or_null(path);
  LoadedMaps out;
  // Version 1 (or anything that is not a version-2 document): the single-patch reader and its messages.
  if (!doc.is_object() || !doc.contains("version") || doc["version"] != kVersion) {
    out.patches.push_back(read_tspline_file(path));
    out.source = out.patches.front().meta.source;
    return out;
  }
  out.version = kVersion;
  if (member(doc, "format", path + ": /") != "tspline") throw InputError(path + ": /format: expected \"tspline\"");
  if (doc.contains("source") && doc["source"].is_string()) out.source = doc["source"].get<std::string>();
  out.patches = read_patches(doc, path);
  out.cuts = read_cuts(doc, path);
  if (doc.contains("domain")) out.domain = read_domain(doc["domain"], path);
  out.interfaces = read_interfaces(doc, path, out.cuts.size(), out.patches.size());
  return out;
}

}  // namespace tspline::io

// The T-spline file (tspline.json), format version 1. The format is documented
// in docs/tspline_format.md; keep the two in step.
//
// Reading validates everything and reports the first problem as an InputError
// "<file>: <JSON pointer>: <what is wrong>". The T-mesh is rebuilt from its
// leaves, the basis is rebuilt from the T-mesh, and every stored function is
// matched to a basis function by (kind, vertex, knot vectors); the file's
// knot vectors are thereby checked, not trusted.
#include "tspline/io/tspline_file.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "toolkit/io/atomic_file.h"
#include "tspline/detail/enum_names.h"
#include "tspline/errors.h"

namespace tspline::io {

namespace {

using nlohmann::json;
using I64 = std::int64_t;
using Kind = BlendingFunction::Kind;

constexpr int kVersion = 1;
constexpr const char* kNormalization = "R_alpha = N_alpha / sum_beta N_beta";

constexpr std::array<detail::EnumName<Kind>, 3> kKindNames{
    {{Kind::Anchor, "anchor"}, {Kind::EdgeExtra, "edge"}, {Kind::CornerExtra, "corner"}}};

const char* kind_name(Kind k) { return detail::enum_name(kKindNames, k, "?"); }

json vec2(const Eigen::Vector2d& p) { return json::array({p.x(), p.y()}); }
json knots(const std::array<double, 5>& k) { return json(k); }

std::string fmt_knots(const std::array<double, 5>& k) { return knots(k).dump(); }

// ------------------------------------------------------------------ writing

void check_meta(const TSplineMap& map, const TSplineFileMeta& meta) {
  for (std::size_t a = 0; a < map.control_points().size(); ++a)
    if (!map.control_points()[a].allFinite())
      throw InputError("write_tspline_file: control point " + std::to_string(a) + " is not finite");
  const Polygon& b = meta.boundary;
  if (b.vertices.empty()) return;
  if (b.file_index.size() != b.vertices.size())
    throw InputError("write_tspline_file: the boundary has " + std::to_string(b.vertices.size()) +
                     " vertices but " + std::to_string(b.file_index.size()) + " file indices");
  for (const auto& v : b.vertices)
    if (!v.allFinite()) throw InputError("write_tspline_file: a boundary vertex is not finite");
  for (std::size_t c : meta.corners)
    if (c >= b.vertices.size())
      throw InputError("write_tspline_file: corner index " + std::to_string(c) + " is out of range");
}

}  // namespace

void write_tspline_file(const std::string& path, const TSplineMap& map, const TSplineFileMeta& meta) {
  toolkit::io::write_text_atomic(path, tspline_file_text(map, meta));
}

std::string tspline_file_text(const TSplineMap& map, const TSplineFileMeta& meta) {
  check_meta(map, meta);
  const TMesh& mesh = map.mesh();
  const TSplineBasis& basis = map.basis();
  // Hand-made layout (one cell / function per line) so that diffs and `grep`
  // stay useful; every number is the text nlohmann's dump gives it (doubles:
  // the shortest decimal that reads back to the same double), appended to one
  // string without a json value per number (Newfoundland's 5,151 patches:
  // 79 MB of text).
  std::string out;
  out.reserve(256 + 48 * mesh.num_cells() + 240 * basis.size());
  char buf[64];
  auto integer = [&](long long v) {
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
  };
  auto number = [&](double v) {
    if (!std::isfinite(v)) {
      out += "null";
      return;
    }
    out.append(buf, nlohmann::detail::to_chars(buf, buf + sizeof buf, v));
  };
  auto numbers = [&](const double* v, std::size_t n) {
    out += '[';
    for (std::size_t k = 0; k < n; ++k) {
      if (k) out += ',';
      number(v[k]);
    }
    out += ']';
  };
  out += "{\n";
  out += "  \"format\": \"tspline\",\n";
  out += "  \"version\": ";
  integer(kVersion);
  out += ",\n";
  out += "  \"degree\": 3,\n";
  out += "  \"source\": " + json(meta.source).dump() + ",\n";
  out += "  \"parametric_domain\": [[0, 0], [1, 1]],\n";
  out += "  \"normalization\": " + json(kNormalization).dump() + ",\n";
  out += "  \"tmesh\": {\n    \"root\": ";
  integer(TMesh::kRoot);
  out += ",\n    \"cells\": [";
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const QuadNode& q = mesh.node(mesh.cell_node(static_cast<int>(c)));
    out += c ? ",\n      [" : "\n      [";
    integer(q.level);
    out += ", ";
    integer(q.i);
    out += ", ";
    integer(q.j);
    out += ']';
  }
  out += "\n    ]\n  },\n  \"functions\": [";
  for (std::size_t a = 0; a < basis.size(); ++a) {
    const BlendingFunction& f = basis.function(static_cast<int>(a));
    const IPoint v = mesh.vertex_ipos(f.vertex);
    out += a ? ",\n    {\"kind\": \"" : "\n    {\"kind\": \"";
    out += kind_name(f.kind);
    out += "\", \"vertex\": [";
    integer(v.x);
    out += ", ";
    integer(v.y);
    out += "], \"knots_xi\": ";
    numbers(f.knots_xi.data(), 5);
    out += ", \"knots_eta\": ";
    numbers(f.knots_eta.data(), 5);
    out += ", \"interpolation_point\": ";
    numbers(f.interpolation_point.data(), 2);
    out += ", \"control_point\": ";
    numbers(map.control_points()[a].data(), 2);
    out += '}';
  }
  out += "\n  ],\n  \"boundary\": ";
  const Polygon& b = meta.boundary;
  if (b.vertices.empty()) {
    out += "null";
  } else {
    out += "{\n    \"polygon\": [";
    for (std::size_t i = 0; i < b.vertices.size(); ++i) {
      if (i) out += ", ";
      numbers(b.vertices[i].data(), 2);
    }
    out += "],\n    \"file_index\": " + json(b.file_index).dump() +
           ",\n    \"corners\": " + json(meta.corners).dump() + "\n  }";
  }
  out += "\n}\n";
  return out;
}

// ------------------------------------------------------------------ reading

namespace {

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const {
    throw InputError(file_ + ": " + (ptr.empty() ? "/" : ptr) + ": " + what);
  }

  const json& member(const json& obj, const std::string& ptr, const char* key) const {
    if (!obj.is_object()) fail(ptr, "expected an object");
    const auto it = obj.find(key);
    if (it == obj.end()) fail(ptr + "/" + key, "missing field");
    return *it;
  }
  const json& array(const json& v, const std::string& ptr) const {
    if (!v.is_array()) fail(ptr, std::string("expected an array, found ") + v.type_name());
    return v;
  }
  I64 integer(const json& v, const std::string& ptr, I64 lo, I64 hi) const {
    I64 x = 0;
    if (v.is_number_unsigned()) {
      const auto u = v.get<std::uint64_t>();
      x = u > static_cast<std::uint64_t>(hi) ? hi + 1 : static_cast<I64>(u);  // reported below
    } else if (v.is_number_integer()) {
      x = v.get<I64>();
    } else {
      fail(ptr, "expected an integer, found " + v.dump());
    }
    if (x < lo || x > hi)
      fail(ptr, "integer " + v.dump() + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return x;
  }
  double finite(const json& v, const std::string& ptr) const {
    if (!v.is_number()) fail(ptr, "expected a finite number, found " + v.dump());
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(ptr, "expected a finite number, found " + v.dump());
    return d;
  }
  template <std::size_t N>
  std::array<double, N> numbers(const json& v, const std::string& ptr) const {
    const std::string what = "expected " + std::to_string(N) + " finite numbers";
    if (!v.is_array() || v.size() != N) fail(ptr, what + ", found " + short_dump(v));
    std::array<double, N> out{};
    for (std::size_t k = 0; k < N; ++k) {
      if (!v[k].is_number() || !std::isfinite(v[k].get<double>())) fail(ptr, what + ", found " + short_dump(v));
      out[k] = v[k].get<double>();
    }
    return out;
  }
  std::string string(const json& v, const std::string& ptr) const {
    if (!v.is_string()) fail(ptr, std::string("expected a string, found ") + v.type_name());
    return v.get<std::string>();
  }
  static std::string short_dump(const json& v) {
    std::string s = v.dump();
    if (s.size() > 80) s = s.substr(0, 77) + "...";
    return s;
  }

  void header(const json& doc) const {
    if (!doc.is_object()) fail("", "expected a JSON object at the top level");
    if (string(member(doc, "", "format"), "/format") != "tspline")
      fail("/format", "expected \"tspline\", found " + doc["format"].dump());
    const json& ver = member(doc, "", "version");
    if (!ver.is_number_integer()) fail("/version", "expected an integer, found " + short_dump(ver));
    if (ver.get<I64>() != kVersion)
      fail("/version", "unsupported version " + ver.dump() + " (this program reads version " +
                           std::to_string(kVersion) + ")");
    if (integer(member(doc, "", "degree"), "/degree", 0, 1000) != 3) fail("/degree", "only degree 3 is supported");
    if (member(doc, "", "parametric_domain") != json::parse("[[0,0],[1,1]]"))
      fail("/parametric_domain", "expected [[0, 0], [1, 1]]");
    if (string(member(doc, "", "normalization"), "/normalization") != kNormalization)
      fail("/normalization", std::string("expected \"") + kNormalization + "\"");
  }

  TMesh tmesh(const json& doc) const {
    const json& tm = member(doc, "", "tmesh");
    if (integer(member(tm, "/tmesh", "root"), "/tmesh/root", 0, I64{1} << 62) != TMesh::kRoot)
      fail("/tmesh/root", "expected " + std::to_string(TMesh::kRoot) + " (2^30)");
    const json& cells = array(member(tm, "/tmesh", "cells"), "/tmesh/cells");
    if (cells.empty()) fail("/tmesh/cells", "expected at least one cell");
    struct Cell {
      I64 level, i, j;
    };
    std::vector<Cell> cs(cells.size());
    std::map<std::tuple<I64, I64, I64>, std::size_t> seen;
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const std::string p = "/tmesh/cells/" + std::to_string(k);
      if (!cells[k].is_array() || cells[k].size() != 3) fail(p, "expected [level, i, j]");
      Cell& c = cs[k];
      c.level = integer(cells[k][0], p + "/0", 0, TMesh::kMaxLevel);
      c.i = integer(cells[k][1], p + "/1", 0, (I64{1} << c.level) - 1);
      c.j = integer(cells[k][2], p + "/2", 0, (I64{1} << c.level) - 1);
      const auto [it, fresh] = seen.emplace(std::tuple{c.level, c.i, c.j}, k);
      if (!fresh) fail(p, "duplicate of cell /tmesh/cells/" + std::to_string(it->second));
    }
    // Refine from the root in level order; a cell is the leaf reached by
    // descending along the bits of (i, j).
    std::vector<std::size_t> order(cs.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cs[a].level < cs[b].level; });
    TMesh mesh(0);
    std::vector<long long> owner(1, -1);  // node -> cell index in the file
    for (std::size_t k : order) {
      const Cell& c = cs[k];
      int n = 0;
      for (I64 l = 0; l < c.level; ++l) {
        if (mesh.node(n).is_leaf()) {
          if (owner[n] >= 0)
            fail("/tmesh/cells/" + std::to_string(k),
                 "overlaps the larger cell /tmesh/cells/" + std::to_string(owner[n]));
          mesh.refine(n);
          owner.resize(mesh.nodes().size(), -1);
        }
        const I64 bit = c.level - l - 1;
        n = mesh.node(n).first_child + static_cast<int>((c.i >> bit) & 1) + 2 * static_cast<int>((c.j >> bit) & 1);
      }
      owner[n] = static_cast<long long>(k);  // a leaf: cells are processed coarse to fine, duplicates excluded
    }
    for (std::size_t n = 0; n < mesh.nodes().size(); ++n) {
      const QuadNode& q = mesh.node(static_cast<int>(n));
      if (q.is_leaf() && owner[n] < 0)
        fail("/tmesh/cells", "the cells do not tile the unit square: cell [" + std::to_string(q.level) + ", " +
                                 std::to_string(q.i) + ", " + std::to_string(q.j) + "] is not covered");
    }
    try {
      mesh.build_topology();
    } catch (const InternalError& e) {
      fail("/tmesh/cells", std::string("the cells are not 2:1 balanced (") + e.what() + ")");
    }
    const std::string inv = mesh.check_invariants();
    if (!inv.empty()) fail("/tmesh/cells", "invalid T-mesh: " + inv);
    return mesh;
  }

  std::vector<Eigen::Vector2d> control_points(const json& doc, const TMesh& mesh) const {
    const TSplineBasis basis(mesh);
    using VKey = std::tuple<int, I64, I64>;
    std::map<VKey, std::vector<int>> by_vertex;
    for (std::size_t a = 0; a < basis.size(); ++a) {
      const BlendingFunction& f = basis.function(static_cast<int>(a));
      const IPoint v = mesh.vertex_ipos(f.vertex);
      by_vertex[{static_cast<int>(f.kind), v.x, v.y}].push_back(static_cast<int>(a));
    }
    const json& fs = array(member(doc, "", "functions"), "/functions");
    std::vector<Eigen::Vector2d> cps(basis.size());
    std::vector<long long> from(basis.size(), -1);  // basis function -> index in the file
    for (std::size_t k = 0; k < fs.size(); ++k) {
      const std::string p = "/functions/" + std::to_string(k);
      const json& f = fs[k];
      if (!f.is_object()) fail(p, "expected an object");
      const std::string kind = string(member(f, p, "kind"), p + "/kind");
      const std::optional<Kind> parsed = detail::enum_value(kKindNames, kind);
      if (!parsed) fail(p + "/kind", "expected \"anchor\", \"edge\" or \"corner\", found \"" + kind + "\"");
      const Kind kd = *parsed;
      const json& vj = member(f, p, "vertex");
      if (!vj.is_array() || vj.size() != 2) fail(p + "/vertex", "expected 2 integers [X, Y]");
      const I64 X = integer(vj[0], p + "/vertex/0", 0, TMesh::kRoot);
      const I64 Y = integer(vj[1], p + "/vertex/1", 0, TMesh::kRoot);
      const auto kx = numbers<5>(member(f, p, "knots_xi"), p + "/knots_xi");
      const auto ky = numbers<5>(member(f, p, "knots_eta"), p + "/knots_eta");
      const auto ip = numbers<2>(member(f, p, "interpolation_point"), p + "/interpolation_point");
      const auto cp = numbers<2>(member(f, p, "control_point"), p + "/control_point");
      const std::string what = "the " + kind + " function of vertex [" + std::to_string(X) + ", " + std::to_string(Y) + "]";
      const auto it = by_vertex.find({static_cast<int>(kd), X, Y});
      if (it == by_vertex.end()) fail(p, "the T-mesh has no " + kind + " function at vertex [" + std::to_string(X) + ", " + std::to_string(Y) + "]");
      int match = -1;
      for (int a : it->second)
        if (basis.function(a).knots_xi == kx && basis.function(a).knots_eta == ky) match = a;
      if (match < 0) {
        // Report the direction that differs, against the closest candidate.
        const BlendingFunction* g = &basis.function(it->second.front());
        for (int a : it->second)
          if (basis.function(a).knots_xi == kx || basis.function(a).knots_eta == ky) g = &basis.function(a);
        const bool xi_bad = g->knots_xi != kx;
        fail(p + (xi_bad ? "/knots_xi" : "/knots_eta"),
             "knot vector " + fmt_knots(xi_bad ? kx : ky) + " is not the one the T-mesh gives for " + what + " (" +
                 fmt_knots(xi_bad ? g->knots_xi : g->knots_eta) + ")");
      }
      if (from[match] >= 0) fail(p, "duplicates /functions/" + std::to_string(from[match]));
      const Eigen::Vector2d& bip = basis.function(match).interpolation_point;
      if (bip.x() != ip[0] || bip.y() != ip[1])
        fail(p + "/interpolation_point", "expected " + vec2(bip).dump() + " for " + what);
      from[match] = static_cast<long long>(k);
      cps[match] = {cp[0], cp[1]};
    }
    for (std::size_t a = 0; a < basis.size(); ++a) {
      if (from[a] >= 0) continue;
      const BlendingFunction& g = basis.function(static_cast<int>(a));
      const IPoint v = mesh.vertex_ipos(g.vertex);
      fail("/functions", "missing the " + std::string(kind_name(g.kind)) + " function of vertex [" +
                             std::to_string(v.x) + ", " + std::to_string(v.y) + "] with knots_xi " +
                             fmt_knots(g.knots_xi) + ", knots_eta " + fmt_knots(g.knots_eta) + " (the file has " +
                             std::to_string(fs.size()) + " functions, the T-mesh " + std::to_string(basis.size()) + ")");
    }
    return cps;
  }

  TSplineFileMeta meta(const json& doc) const {
    TSplineFileMeta m;
    m.source = string(member(doc, "", "source"), "/source");
    const json& b = member(doc, "", "boundary");
    if (b.is_null()) return m;
    const json& poly = array(member(b, "/boundary", "polygon"), "/boundary/polygon");
    const json& fi = array(member(b, "/boundary", "file_index"), "/boundary/file_index");
    const json& co = array(member(b, "/boundary", "corners"), "/boundary/corners");
    if (poly.size() < 3) fail("/boundary/polygon", "expected at least 3 vertices");
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const auto xy = numbers<2>(poly[k], "/boundary/polygon/" + std::to_string(k));
      m.boundary.vertices.emplace_back(xy[0], xy[1]);
    }
    if (fi.size() != poly.size())
      fail("/boundary/file_index", "expected " + std::to_string(poly.size()) + " indices (one per polygon vertex)");
    for (std::size_t k = 0; k < fi.size(); ++k)
      m.boundary.file_index.push_back(
          static_cast<std::size_t>(integer(fi[k], "/boundary/file_index/" + std::to_string(k), 0, I64{1} << 53)));
    if (co.size() != 4) fail("/boundary/corners", "expected 4 polygon indices");
    for (std::size_t k = 0; k < 4; ++k)
      m.corners[k] = static_cast<std::size_t>(
          integer(co[k], "/boundary/corners/" + std::to_string(k), 0, static_cast<I64>(poly.size()) - 1));
    double area2 = 0.0;
    const auto& v = m.boundary.vertices;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const Eigen::Vector2d& a = v[k];
      const Eigen::Vector2d& c = v[(k + 1) % v.size()];
      area2 += a.x() * c.y() - a.y() * c.x();
    }
    if (!(area2 > 0.0)) fail("/boundary/polygon", "expected a counter-clockwise polygon (positive signed area)");
    return m;
  }

 private:
  std::string file_;
};

}  // namespace

std::string read_text_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError("cannot read '" + path + "': it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open '" + path + "' for reading: " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw IoError("cannot read '" + path + "'");
  return ss.str();
}

namespace {

// "[json.exception.parse_error.101] parse error at line 1, ..." -> "parse error at line 1, ..."
std::string strip_id(std::string what) {
  const auto close = what.find("] ");
  if (what.rfind("[json.exception", 0) == 0 && close != std::string::npos) what.erase(0, close + 2);
  return what;
}

}  // namespace

LoadedTSpline read_tspline_file(const std::string& path) { return parse_tspline_file(read_text_file(path), path); }

LoadedTSpline parse_tspline_file(const std::string& text, const std::string& path) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(path + ": /: invalid JSON at byte " + std::to_string(e.byte) + ": " + strip_id(e.what()));
  } catch (const json::exception& e) {  // e.g. a number too large for a double
    throw InputError(path + ": /: invalid JSON: " + strip_id(e.what()));
  }
  return tspline_from_json(doc, path);
}

LoadedTSpline tspline_from_json(const nlohmann::json& doc, const std::string& name) {
  const Reader r(name);
  r.header(doc);
  TSplineFileMeta meta = r.meta(doc);
  TMesh mesh = r.tmesh(doc);
  std::vector<Eigen::Vector2d> cps = r.control_points(doc, mesh);
  return LoadedTSpline{TSplineMap(std::move(mesh), std::move(cps)), std::move(meta)};
}

}  // namespace tspline::io

// Polygon input: plain "x y" text files and GeoJSON.
#include "tspline/io/polygon_reader.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "tspline/errors.h"

namespace tspline::io {
namespace {

using json = nlohmann::json;
using Ring = std::vector<Eigen::Vector2d>;

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n\f\v");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n\f\v");
  return s.substr(b, e - b + 1);
}

// Parses a whole token as a double; accepts a leading '+' (from_chars does not).
bool parse_double(std::string_view tok, double& out) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), out);
  return ec == std::errc() && ptr == tok.data() + tok.size();
}

Polygon finish(Ring ring, const std::string& source) {
  // An explicitly repeated closing vertex is not a vertex of its own.
  if (ring.size() >= 2 && ring.front() == ring.back()) ring.pop_back();
  if (ring.empty()) throw InputError(source + ": empty (no vertices)");
  Polygon p;
  p.vertices = std::move(ring);
  p.file_index.resize(p.vertices.size());
  for (std::size_t i = 0; i < p.file_index.size(); ++i) p.file_index[i] = i;
  return p;
}

// Vertex lines in file order; `ring_starts` (if given) receives the index of
// the first vertex of every ring, rings being separated by blank lines (a
// line holding only a comment does not separate).
Ring parse_text_vertices(const std::string& content, const std::string& source,
                         std::vector<std::size_t>* ring_starts = nullptr) {
  Ring ring;
  bool after_blank = true;
  std::size_t line_no = 0, pos = 0;
  while (pos <= content.size()) {
    std::size_t end = content.find('\n', pos);
    if (end == std::string::npos) end = content.size();
    std::string_view line(content.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (line_no == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // UTF-8 BOM
    if (trim(line).empty()) after_blank = true;
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    line = trim(line);
    if (line.empty()) continue;
    if (after_blank && ring_starts) ring_starts->push_back(ring.size());
    after_blank = false;
    // Two tokens separated by whitespace and/or one comma.
    std::vector<std::string_view> tok;
    int commas = 0;
    std::size_t i = 0;
    while (i < line.size()) {
      const char ch = line[i];
      if (ch == ' ' || ch == '\t' || ch == ',') {
        commas += ch == ',';
        ++i;
        continue;
      }
      const std::size_t j = line.find_first_of(" \t,", i);
      const std::size_t stop = j == std::string_view::npos ? line.size() : j;
      tok.push_back(line.substr(i, stop - i));
      i = stop;
    }
    const std::string where = source + ":" + std::to_string(line_no) + ": ";
    double x = 0, y = 0;
    if (tok.size() != 2 || commas > 1 || !parse_double(tok[0], x) || !parse_double(tok[1], y))
      throw InputError(where + "expected two numbers 'x y', got '" + std::string(line) + "'");
    if (!std::isfinite(x) || !std::isfinite(y)) throw InputError(where + "coordinate is not finite");
    ring.emplace_back(x, y);
  }
  return ring;
}

Polygon parse_text(const std::string& content, const std::string& source) {
  return finish(parse_text_vertices(content, source), source);
}

// ---- GeoJSON ---------------------------------------------------------------

struct Found {
  std::string path;  // JSON pointer of the polygon's "coordinates" array
  const json* coords;
};

double ring_area(const Ring& r) {
  double a = 0;
  for (std::size_t i = 0; i + 1 < r.size(); ++i)
    a += (r[i] - r[0]).x() * (r[i + 1] - r[0]).y() - (r[i] - r[0]).y() * (r[i + 1] - r[0]).x();
  return std::abs(0.5 * a);
}

Ring parse_ring(const json& ring, const std::string& path, const std::string& source) {
  if (!ring.is_array()) throw InputError(source + ": " + path + ": expected an array of positions");
  Ring out;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const json& pos = ring[i];
    const std::string here = source + ": " + path + "/" + std::to_string(i) + ": ";
    if (!pos.is_array() || pos.size() < 2 || !pos[0].is_number() || !pos[1].is_number())
      throw InputError(here + "expected a position [x, y], got " + pos.dump());
    const double x = pos[0].get<double>(), y = pos[1].get<double>();
    if (!std::isfinite(x) || !std::isfinite(y)) throw InputError(here + "coordinate is not finite");
    out.emplace_back(x, y);
  }
  return out;
}

// Collects the Polygon coordinate arrays of a GeoJSON object in file order.
void collect(const json& obj, const std::string& path, const std::string& source, std::vector<Found>& out) {
  const std::string at = path.empty() ? "/" : path;
  if (!obj.is_object() || !obj.contains("type") || !obj["type"].is_string())
    throw InputError(source + ": " + at + ": expected a GeoJSON object with a \"type\"");
  const std::string type = obj["type"].get<std::string>();
  auto member = [&](const char* name) -> const json& {
    if (!obj.contains(name)) throw InputError(source + ": " + at + ": " + type + " without \"" + name + "\"");
    return obj[name];
  };
  auto array_member = [&](const char* name) -> const json& {
    const json& m = member(name);
    if (!m.is_array()) throw InputError(source + ": " + path + "/" + name + ": expected an array");
    return m;
  };
  if (type == "Polygon") {
    array_member("coordinates");
    out.push_back({path + "/coordinates", &obj["coordinates"]});
  } else if (type == "MultiPolygon") {
    const json& polys = array_member("coordinates");
    for (std::size_t i = 0; i < polys.size(); ++i)
      out.push_back({path + "/coordinates/" + std::to_string(i), &polys[i]});
  } else if (type == "Feature") {
    const json& g = member("geometry");
    if (!g.is_null()) collect(g, path + "/geometry", source, out);
  } else if (type == "FeatureCollection") {
    const json& fs = array_member("features");
    for (std::size_t i = 0; i < fs.size(); ++i)
      collect(fs[i], path + "/features/" + std::to_string(i), source, out);
  } else if (type == "GeometryCollection") {
    const json& gs = array_member("geometries");
    for (std::size_t i = 0; i < gs.size(); ++i)
      collect(gs[i], path + "/geometries/" + std::to_string(i), source, out);
  }
  // Other geometry types (Point, LineString, ...) hold no polygon: skipped.
}

Polygon parse_geojson(const std::string& content, const std::string& source, const PolygonReadOptions& opt,
                      std::string* warnings) {
  json doc;
  try {
    doc = json::parse(content);
  } catch (const json::parse_error& e) {
    throw InputError(source + ": invalid JSON: " + e.what());
  } catch (const json::exception& e) {  // e.g. a number too large for a double (out_of_range.406)
    throw InputError(source + ": invalid JSON: " + e.what());
  }
  std::vector<Found> found;
  collect(doc, "", source, found);
  if (found.empty()) throw InputError(source + ": no Polygon or MultiPolygon in the GeoJSON");
  auto outer = [&](const Found& f) {
    if (!f.coords->is_array() || f.coords->empty())
      throw InputError(source + ": " + f.path + ": expected an array of rings");
    return parse_ring((*f.coords)[0], f.path + "/0", source);
  };
  std::size_t chosen = 0;
  std::string note;
  if (opt.polygon_index) {
    if (*opt.polygon_index >= found.size())
      throw InputError(source + ": polygon index " + std::to_string(*opt.polygon_index) +
                       " is out of range (" + std::to_string(found.size()) + " polygon(s) in the file)");
    chosen = *opt.polygon_index;
  } else if (found.size() > 1) {
    double best = -1;
    for (std::size_t i = 0; i < found.size(); ++i) {
      const double a = ring_area(outer(found[i]));
      if (a > best) best = a, chosen = i;
    }
    note = source + ": " + std::to_string(found.size()) + " polygons; using polygon " +
           std::to_string(chosen) + " (largest area)\n";
  }
  const Found& f = found[chosen];
  Ring ring = outer(f);
  if (f.coords->size() > 1)
    note += source + ": " + f.path + ": " + std::to_string(f.coords->size() - 1) + " hole(s) ignored\n";
  if (warnings) *warnings += note;
  return finish(std::move(ring), source);
}

}  // namespace

std::vector<Polygon> parse_text_rings(const std::string& content, const std::string& source_name) {
  std::vector<std::size_t> starts;
  const Ring all = parse_text_vertices(content, source_name, &starts);
  if (all.empty()) throw InputError(source_name + ": empty (no vertices)");
  std::vector<Polygon> rings;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::size_t end = k + 1 < starts.size() ? starts[k + 1] : all.size();
    Polygon p = finish(Ring(all.begin() + static_cast<long>(starts[k]), all.begin() + static_cast<long>(end)),
                       source_name + " ring " + std::to_string(k));
    rings.push_back(std::move(p));
  }
  return rings;
}

Polygon parse_polygon(const std::string& content, const std::string& source_name,
                      const PolygonReadOptions& options, std::string* warnings) {
  std::size_t first = content.find_first_not_of(" \t\r\n\f\v");
  if (first != std::string::npos && content.compare(first, 3, "\xEF\xBB\xBF") == 0)
    first = content.find_first_not_of(" \t\r\n\f\v", first + 3);
  if (first != std::string::npos && content[first] == '{')
    return parse_geojson(content, source_name, options, warnings);
  return parse_text(content, source_name);
}

namespace {

std::string read_whole_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError("cannot read '" + path + "': " + std::strerror(EISDIR));
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw IoError("cannot open '" + path + "': " + (err ? std::strerror(err) : "unknown error"));
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw IoError("cannot read '" + path + "': " + (errno ? std::strerror(errno) : "read error"));
  return ss.str();
}

}  // namespace

Polygon read_polygon(const std::string& path, const PolygonReadOptions& options, std::string* warnings) {
  return parse_polygon(read_whole_file(path), path, options, warnings);
}

std::vector<Polygon> read_text_rings(const std::string& path) { return parse_text_rings(read_whole_file(path), path); }

}  // namespace tspline::io

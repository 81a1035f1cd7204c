// Polygon input: plain "x y" text files (GeoJSON and GIS files: gis_reader, through GDAL).
#include "tspline/io/polygon_reader.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "tspline/errors.h"

namespace tspline::io {
namespace {

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

Polygon parse_polygon(const std::string& content, const std::string& source_name) {
  std::size_t first = content.find_first_not_of(" \t\r\n\f\v");
  if (first != std::string::npos && content.compare(first, 3, "\xEF\xBB\xBF") == 0)
    first = content.find_first_not_of(" \t\r\n\f\v", first + 3);
  if (first != std::string::npos && content[first] == '{')
    throw InputError(source_name + ": GeoJSON, not a text polygon: read it with read_domain (a .geojson or .json "
                     "file) or read_geojson_domain (GDAL), which keep its holes and project longitude/latitude");
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

Polygon read_polygon(const std::string& path) {
  return parse_polygon(read_whole_file(path), path);
}

std::vector<Polygon> read_text_rings(const std::string& path) { return parse_text_rings(read_whole_file(path), path); }

}  // namespace tspline::io

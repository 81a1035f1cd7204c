#include "tspline/io/msh_export.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include "tspline/spline/bezier_extraction.h"
#include "toolkit/io/atomic_file.h"

namespace tspline::io {

// Gmsh's MSH_QUA_16 ordering (reference square [-1,1]^2 mapped to [0,1]^2):
// corners, edge nodes edge by edge, then the interior quadrilateral.
const double kQua16Local[16][2] = {
    {0, 0},         {1, 0},         {1, 1},         {0, 1},                          // corners
    {1. / 3, 0},    {2. / 3, 0},                                                     // edge 0-1
    {1, 1. / 3},    {1, 2. / 3},                                                     // edge 1-2
    {2. / 3, 1},    {1. / 3, 1},                                                     // edge 2-3
    {0, 2. / 3},    {0, 1. / 3},                                                     // edge 3-0
    {1. / 3, 1. / 3}, {2. / 3, 1. / 3}, {2. / 3, 2. / 3}, {1. / 3, 2. / 3}};       // interior

namespace {

/// The parametric coordinate lo + (hi - lo) k / 3 of a node, exactly, as an
/// integer in units of 1 / (3 kRoot): element bounds are integer T-mesh
/// coordinates / kRoot, so a point that two elements compute in different ways
/// (the coarse element's 1/3 and a fine neighbour's 2/3 of its half) gets one key.
std::int64_t node_key(double lo, double hi, double local) {
  const std::int64_t k = static_cast<std::int64_t>(local * 3.0 + 0.5);
  const auto a = static_cast<std::int64_t>(std::llround(lo * static_cast<double>(TMesh::kRoot)));
  const auto b = static_cast<std::int64_t>(std::llround(hi * static_cast<double>(TMesh::kRoot)));
  return 3 * a + (b - a) * k;
}

double key_coordinate(std::int64_t key) { return static_cast<double>(key) / (3.0 * static_cast<double>(TMesh::kRoot)); }

}  // namespace

std::string msh_document(const TSplineMap& map, MshExportStats* stats) {
  const BezierExtraction extraction(map.basis());
  std::map<std::pair<std::int64_t, std::int64_t>, std::size_t> node_of;  // exact parametric position -> node tag
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<std::size_t, 16>> elements;
  elements.reserve(extraction.elements().size());
  for (const BezierElement& e : extraction.elements()) {
    std::array<std::size_t, 16> conn{};
    for (int k = 0; k < 16; ++k) {
      const std::pair<std::int64_t, std::int64_t> key(node_key(e.lo.x(), e.hi.x(), kQua16Local[k][0]),
                                                       node_key(e.lo.y(), e.hi.y(), kQua16Local[k][1]));
      auto [it, inserted] = node_of.emplace(key, nodes.size() + 1);
      if (inserted) nodes.push_back(map.point({key_coordinate(key.first), key_coordinate(key.second)}));
      conn[k] = it->second;
    }
    elements.push_back(conn);
  }
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const Eigen::Vector2d& p : nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::ostringstream out;
  out.precision(std::numeric_limits<double>::max_digits10);
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  out << "$PhysicalNames\n1\n2 1 \"domain\"\n$EndPhysicalNames\n";
  // Entities: no points, curves or volumes; surface 1 with physical tag 1 and
  // no bounding curves.
  out << "$Entities\n0 0 1 0\n1 " << lo.x() << ' ' << lo.y() << " 0 " << hi.x() << ' ' << hi.y() << " 0 1 1 0\n"
      << "$EndEntities\n";
  const std::size_t n = nodes.size(), m = elements.size();
  out << "$Nodes\n1 " << n << " 1 " << n << "\n2 1 0 " << n << '\n';
  for (std::size_t i = 1; i <= n; ++i) out << i << '\n';
  for (const Eigen::Vector2d& p : nodes) out << p.x() << ' ' << p.y() << " 0\n";
  out << "$EndNodes\n";
  out << "$Elements\n1 " << m << " 1 " << m << "\n2 1 36 " << m << '\n';
  for (std::size_t i = 0; i < m; ++i) {
    out << i + 1;
    for (std::size_t tag : elements[i]) out << ' ' << tag;
    out << '\n';
  }
  out << "$EndElements\n";
  if (stats) *stats = {m, n};
  return out.str();
}

MshExportStats write_msh_file(const std::string& path, const TSplineMap& map) {
  MshExportStats stats;
  const std::string text = msh_document(map, &stats);
  toolkit::io::write_text_atomic(path, text);
  return stats;
}

}  // namespace tspline::io

#include "tspline/io/msh_export.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <algorithm>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tspline/spline/bezier_extraction.h"
#include "toolkit/io/atomic_file.h"
#include "toolkit/errors.h"
#include "toolkit/union_find.h"

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

namespace {

using Key = std::pair<std::int64_t, std::int64_t>;  // exact parametric position, units 1 / (3 kRoot)
constexpr std::int64_t kSideKeys = 3 * static_cast<std::int64_t>(TMesh::kRoot);  // the key of u = 1

// Side s at chord parameter T (in key units): Bottom (T, 0), Right (1, T),
// Top (1 - T, 1), Left (0, 1 - T), as side_point_uv.
Key side_key(int side, std::int64_t t) {
  switch (side) {
    case 0: return {t, 0};
    case 1: return {kSideKeys, t};
    case 2: return {kSideKeys - t, kSideKeys};
    default: return {0, kSideKeys - t};
  }
}

// The chord parameter of a key on `side`, or -1 if the key is not on it.
std::int64_t side_param(int side, const Key& k) {
  switch (side) {
    case 0: return k.second == 0 ? k.first : -1;
    case 1: return k.first == kSideKeys ? k.second : -1;
    case 2: return k.second == kSideKeys ? kSideKeys - k.first : -1;
    default: return k.first == 0 ? kSideKeys - k.second : -1;
  }
}

struct PatchNodes {
  std::map<Key, std::size_t> index;             // key -> local node index
  std::vector<Key> keys;                          // local node -> key
  std::vector<std::array<std::size_t, 16>> elements;  // local node indices
};

PatchNodes patch_nodes(const TSplineMap& map) {
  PatchNodes n;
  const BezierExtraction extraction(map.basis());
  n.elements.reserve(extraction.elements().size());
  for (const BezierElement& e : extraction.elements()) {
    std::array<std::size_t, 16> conn{};
    for (int k = 0; k < 16; ++k) {
      const Key key(node_key(e.lo.x(), e.hi.x(), kQua16Local[k][0]), node_key(e.lo.y(), e.hi.y(), kQua16Local[k][1]));
      auto [it, inserted] = n.index.emplace(key, n.keys.size());
      if (inserted) n.keys.push_back(key);
      conn[k] = it->second;
    }
    n.elements.push_back(conn);
  }
  return n;
}

}  // namespace

std::string msh_document(const std::vector<const TSplineMap*>& maps, const std::vector<Interface>& interfaces,
                         MshExportStats* stats) {
  if (maps.empty()) throw toolkit::InputError("msh_document: no patches");
  const std::size_t P = maps.size();
  for (const Interface& f : interfaces)
    if (f.patch_a >= P || f.patch_b >= P || f.side_a < 0 || f.side_a > 3 || f.side_b < 0 || f.side_b > 3)
      throw toolkit::InputError("msh_document: an interface names a patch or side out of range");
  std::vector<PatchNodes> patches;
  patches.reserve(P);
  for (const TSplineMap* m : maps) patches.push_back(patch_nodes(*m));
  // Union-find over (patch, local node): nodes at corresponding positions of an
  // interface are one node (also where several patches meet at a point).
  std::vector<std::size_t> offset(P + 1, 0);
  for (std::size_t p = 0; p < P; ++p) offset[p + 1] = offset[p] + patches[p].keys.size();
  toolkit::UnionFind same_node(offset[P]);  // the root is the first occurrence
  for (const Interface& f : interfaces) {
    const PatchNodes& a = patches[f.patch_a];
    const PatchNodes& b = patches[f.patch_b];
    for (std::size_t i = 0; i < a.keys.size(); ++i) {
      const std::int64_t t = side_param(f.side_a, a.keys[i]);
      if (t < 0) continue;
      const auto it = b.index.find(side_key(f.side_b, kSideKeys - t));
      if (it == b.index.end()) continue;
      same_node.unite(offset[f.patch_a] + i, offset[f.patch_b] + it->second);
    }
  }
  // Node tags in order of first occurrence (patch by patch), each node on the
  // entity of its first patch.
  std::vector<std::size_t> tag(same_node.size(), 0);
  std::vector<std::vector<std::size_t>> block_tags(P);
  std::vector<std::vector<Eigen::Vector2d>> block_points(P);
  std::size_t n = 0;
  for (std::size_t p = 0; p < P; ++p)
    for (std::size_t i = 0; i < patches[p].keys.size(); ++i) {
      const std::size_t g = offset[p] + i, r = same_node.find(g);
      if (r != g) continue;
      tag[g] = ++n;
      const Key& k = patches[p].keys[i];
      block_tags[p].push_back(n);
      block_points[p].push_back(maps[p]->point({key_coordinate(k.first), key_coordinate(k.second)}));
    }
  for (std::size_t g = 0; g < same_node.size(); ++g) tag[g] = tag[same_node.find(g)];
  std::size_t m = 0;
  for (const PatchNodes& q : patches) m += q.elements.size();

  std::ostringstream out;
  out.precision(std::numeric_limits<double>::max_digits10);
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  if (P == 1) {
    out << "$PhysicalNames\n1\n2 1 \"domain\"\n$EndPhysicalNames\n";
  } else {
    out << "$PhysicalNames\n" << P + 1 << "\n2 1 \"domain\"\n";
    for (std::size_t p = 0; p < P; ++p) out << "2 " << p + 2 << " \"patch " << p << "\"\n";
    out << "$EndPhysicalNames\n";
  }
  // Entities: no points, curves or volumes; one surface per patch with its
  // physical tags and no bounding curves.
  out << "$Entities\n0 0 " << P << " 0\n";
  for (std::size_t p = 0; p < P; ++p) {
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d hi = -lo;
    for (std::size_t i = 0; i < patches[p].keys.size(); ++i) {
      const Eigen::Vector2d x = maps[p]->point(
          {key_coordinate(patches[p].keys[i].first), key_coordinate(patches[p].keys[i].second)});
      lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
    }
    out << p + 1 << ' ' << lo.x() << ' ' << lo.y() << " 0 " << hi.x() << ' ' << hi.y() << " 0 ";
    if (P == 1) out << "1 1 0\n";
    else out << "2 1 " << p + 2 << " 0\n";
  }
  out << "$EndEntities\n";
  std::size_t blocks = 0;
  for (const auto& b : block_tags) blocks += b.empty() ? 0 : 1;
  out << "$Nodes\n" << blocks << ' ' << n << " 1 " << n << '\n';
  for (std::size_t p = 0; p < P; ++p) {
    if (block_tags[p].empty()) continue;
    out << "2 " << p + 1 << " 0 " << block_tags[p].size() << '\n';
    for (std::size_t t : block_tags[p]) out << t << '\n';
    for (const Eigen::Vector2d& x : block_points[p]) out << x.x() << ' ' << x.y() << " 0\n";
  }
  out << "$EndNodes\n";
  out << "$Elements\n" << P << ' ' << m << " 1 " << m << '\n';
  std::size_t e = 0;
  for (std::size_t p = 0; p < P; ++p) {
    out << "2 " << p + 1 << " 36 " << patches[p].elements.size() << '\n';
    for (const auto& conn : patches[p].elements) {
      out << ++e;
      for (std::size_t local : conn) out << ' ' << tag[offset[p] + local];
      out << '\n';
    }
  }
  out << "$EndElements\n";
  if (stats) *stats = {m, n};
  return out.str();
}

std::string msh_document(const TSplineMap& map, MshExportStats* stats) { return msh_document({&map}, {}, stats); }

MshExportStats write_msh_file(const std::string& path, const std::vector<const TSplineMap*>& maps,
                              const std::vector<Interface>& interfaces) {
  MshExportStats stats;
  const std::string text = msh_document(maps, interfaces, &stats);
  toolkit::io::write_text_atomic(path, text);
  return stats;
}

MshExportStats write_msh_file(const std::string& path, const TSplineMap& map) {
  MshExportStats stats;
  const std::string text = msh_document(map, &stats);
  toolkit::io::write_text_atomic(path, text);
  return stats;
}

}  // namespace tspline::io

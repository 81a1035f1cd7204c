// Cubic hierarchical B-splines on a balanced quadtree T-mesh (see hierarchical_basis.h).
#include "tspline/analysis/hierarchical_basis.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "tspline/errors.h"

namespace tspline {

namespace {

using I64 = std::int64_t;
using U64 = std::uint64_t;

// Functions are keyed by (level, ix, iy) packed into 64 bits: iy in bits 0-29,
// ix in bits 30-58, level in bits 59-63; ix, iy <= 2^level + 2 < 2^29 for level <= kMaxBasisLevel.
constexpr int kMaxBasisLevel = 28;

U64 function_key(int level, I64 ix, I64 iy) {
  return (static_cast<U64>(level) << 59) | (static_cast<U64>(ix) << 30) | static_cast<U64>(iy);
}

// Quadtree nodes keyed by their index in the complete quadtree: (4^l - 1)/3 + i 2^l + j.
U64 node_key(int level, I64 i, I64 j) {
  return ((U64{1} << (2 * level)) - 1) / 3 + (static_cast<U64>(i) << level) + static_cast<U64>(j);
}

std::array<double, 5> level_knots(int level, I64 index) {
  const double h = std::ldexp(1.0, -level);  // exact: dyadic
  std::array<double, 5> k{};
  for (int m = 0; m < 5; ++m) k[m] = std::clamp(static_cast<double>(index - 3 + m) * h, 0.0, 1.0);
  return k;
}

}  // namespace

HierarchicalBasis::HierarchicalBasis(const TMesh& mesh) : mesh_(&mesh) {
  if (!mesh.has_topology()) throw toolkit::InternalError("HierarchicalBasis: the T-mesh has no topology");
  if (mesh.max_level() > kMaxBasisLevel)
    throw InputError("hierarchical basis: the T-mesh has cells of level " + std::to_string(mesh.max_level()) +
                     ", at most " + std::to_string(kMaxBasisLevel) + " are supported");

  // node_key -> is the node a leaf?
  std::unordered_map<U64, bool> nodes;
  nodes.reserve(mesh.nodes().size() * 2);
  for (const QuadNode& q : mesh.nodes()) nodes.emplace(node_key(q.level, q.i, q.j), q.is_leaf());

  // Active test (see header): all level-l cells of the support are quadtree
  // nodes, and at least one of them is a leaf. Memoized per candidate.
  std::unordered_map<U64, int> candidate;  // function_key -> id, or -1 if inactive
  candidate.reserve(mesh.num_cells() * 8);
  auto function_id = [&](int l, I64 ix, I64 iy) -> int {
    const U64 key = function_key(l, ix, iy);
    if (auto it = candidate.find(key); it != candidate.end()) return it->second;
    const I64 last = (I64{1} << l) - 1;
    bool all_nodes = true, any_leaf = false;
    for (I64 qx = std::max<I64>(0, ix - 3); all_nodes && qx <= std::min(last, ix); ++qx)
      for (I64 qy = std::max<I64>(0, iy - 3); qy <= std::min(last, iy); ++qy) {
        const auto it = nodes.find(node_key(l, qx, qy));
        if (it == nodes.end()) {
          all_nodes = false;
          break;
        }
        any_leaf = any_leaf || it->second;
      }
    int id = -1;
    if (all_nodes && any_leaf) {
      id = static_cast<int>(functions_.size());
      HierarchicalFunction f;
      f.level = l;
      f.ix = ix;
      f.iy = iy;
      f.knots_xi = level_knots(l, ix);
      f.knots_eta = level_knots(l, iy);
      const I64 n_last = (I64{1} << l) + 2;
      f.on_border = ix == 0 || iy == 0 || ix == n_last || iy == n_last;
      functions_.push_back(f);
    }
    candidate.emplace(key, id);
    return id;
  };

  // A level-l function is non-zero on the interior of a level-L cell (l <= L)
  // iff it is non-zero on the cell's level-l ancestor (a, b): ix in [a, a+3].
  // Functions of levels > L vanish on it (their support lies in Omega^{L+1}).
  const int nc = static_cast<int>(mesh.num_cells());
  cell_offset_.assign(static_cast<std::size_t>(nc) + 1, 0);
  std::vector<int> ids;
  for (int c = 0; c < nc; ++c) {
    const QuadNode& q = mesh.node(mesh.cell_node(c));
    ids.clear();
    for (int l = 0; l <= q.level; ++l) {
      const I64 a = q.i >> (q.level - l), b = q.j >> (q.level - l);
      for (I64 ix = a; ix <= a + 3; ++ix)
        for (I64 iy = b; iy <= b + 3; ++iy) {
          const int id = function_id(l, ix, iy);
          if (id >= 0) ids.push_back(id);
        }
    }
    std::sort(ids.begin(), ids.end());
    cell_ids_.insert(cell_ids_.end(), ids.begin(), ids.end());
    cell_offset_[c + 1] = cell_ids_.size();
  }
}

int HierarchicalBasis::locate(const Eigen::Vector2d& uv) const {
  if (!(uv.x() >= 0.0 && uv.x() <= 1.0 && uv.y() >= 0.0 && uv.y() <= 1.0))
    throw toolkit::InputError("HierarchicalBasis::locate: point outside [0,1]^2");
  auto cell_index = [](double t) {
    const I64 i = static_cast<I64>(std::floor(t * static_cast<double>(TMesh::kRoot)));
    return std::clamp<I64>(i, 0, TMesh::kRoot - 1);
  };
  return mesh_->cell_of_node(mesh_->leaf_at_doubled(2 * cell_index(uv.x()) + 1, 2 * cell_index(uv.y()) + 1));
}

void HierarchicalBasis::evaluate(int c, const Eigen::Vector2d& uv, BasisValues& out, int order) const {
  if (order < 0 || order > 2) throw toolkit::InputError("HierarchicalBasis::evaluate: order must be 0, 1 or 2");
  const std::span<const int> ids = functions_on_cell(c);
  const std::size_t n = ids.size();
  out.ids.assign(ids.begin(), ids.end());
  const bool d1 = order >= 1, d2 = order >= 2;
  out.R.resize(n);
  out.R_xi.resize(d1 ? n : 0);
  out.R_eta.resize(d1 ? n : 0);
  out.R_xixi.resize(d2 ? n : 0);
  out.R_xieta.resize(d2 ? n : 0);
  out.R_etaeta.resize(d2 ? n : 0);
  // The functions of level l on the cell have ix in [a, a+3] (a = the column of
  // the cell's level-l ancestor), so 4 + 4 univariate evaluations per level
  // serve all of them.
  const QuadNode& q = mesh_->node(mesh_->cell_node(c));
  struct Univariate {
    double v[4], d1[4], d2[4];
  };
  std::array<Univariate, kMaxBasisLevel + 1> ux, uy;
  std::array<bool, kMaxBasisLevel + 1> done{};
  for (std::size_t k = 0; k < n; ++k) {
    const HierarchicalFunction& f = functions_[ids[k]];
    const int l = f.level;
    const I64 a = q.i >> (q.level - l), b = q.j >> (q.level - l);
    if (!done[l]) {
      done[l] = true;
      for (int m = 0; m < 4; ++m) {
        ux[l].v[m] = cubic_bspline(level_knots(l, a + m), uv.x(), d1 ? &ux[l].d1[m] : nullptr,
                                   d2 ? &ux[l].d2[m] : nullptr);
        uy[l].v[m] = cubic_bspline(level_knots(l, b + m), uv.y(), d1 ? &uy[l].d1[m] : nullptr,
                                   d2 ? &uy[l].d2[m] : nullptr);
      }
    }
    const int mx = static_cast<int>(f.ix - a), my = static_cast<int>(f.iy - b);
    const double u = ux[l].v[mx], w = uy[l].v[my];
    out.R[k] = u * w;
    if (d1) {
      out.R_xi[k] = ux[l].d1[mx] * w;
      out.R_eta[k] = u * uy[l].d1[my];
    }
    if (d2) {
      out.R_xixi[k] = ux[l].d2[mx] * w;
      out.R_xieta[k] = ux[l].d1[mx] * uy[l].d1[my];
      out.R_etaeta[k] = u * uy[l].d2[my];
    }
  }
}

}  // namespace tspline

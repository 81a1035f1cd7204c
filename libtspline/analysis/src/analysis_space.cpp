// The glued analysis space of a map of 1..n patches (see analysis_space.h).
#include "toolkit/union_find.h"
#include "tspline/analysis/analysis_space.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>

#include "tspline/boundary/border_knots.h"
#include "tspline/boundary/boundary_map.h"
#include "tspline/errors.h"
#include "tspline/spline/bezier_extraction.h"

namespace tspline {

namespace {

// Index range of a level-l function along a side: [0, 2^l + 2].
std::int64_t last_index(int level) { return (std::int64_t{1} << level) + 2; }

using toolkit::UnionFind;

}  // namespace

std::int64_t side_index(const HierarchicalFunction& f, int side) {
  const std::int64_t n = last_index(f.level);
  switch (static_cast<Side>(side)) {
    case Side::Bottom: return f.iy == 0 ? f.ix : -1;
    case Side::Right: return f.ix == n ? f.iy : -1;
    case Side::Top: return f.iy == n ? n - f.ix : -1;
    case Side::Left: return f.ix == 0 ? n - f.iy : -1;
  }
  return -1;
}

std::size_t refine_conforming(std::vector<TMesh>& meshes, const std::vector<Interface>& interfaces,
                              const std::vector<std::vector<int>>& cells) {
  for (std::size_t p = 0; p < meshes.size(); ++p)
    if (!cells[p].empty()) meshes[p] = refine_cells(meshes[p], cells[p]);
  // Refining one side of a cut adds border knots there; the other side gets
  // them too (and balancing may add more, hence the loop).
  std::size_t propagated = 0;
  for (std::size_t splits = 1; splits > 0;) {
    splits = 0;
    for (const Interface& f : interfaces) {
      std::set<double> u;
      for (double t : border_params(meshes[f.patch_a], static_cast<Side>(f.side_a))) u.insert(t);
      for (double t : border_params(meshes[f.patch_b], static_cast<Side>(f.side_b))) u.insert(reversed_param(t));
      BorderParams a, b;
      a[f.side_a].assign(u.begin(), u.end());
      for (double t : u) b[f.side_b].push_back(reversed_param(t));
      splits += refine_to_border_params(meshes[f.patch_a], a, TMesh::kMaxLevel);
      splits += refine_to_border_params(meshes[f.patch_b], b, TMesh::kMaxLevel);
    }
    propagated += splits;
  }
  return propagated;
}

std::vector<TMesh> AnalysisGeometry::meshes() const {
  std::vector<TMesh> out;
  out.reserve(patches.size());
  for (const TSplineMap* m : patches) out.push_back(m->mesh());
  std::vector<QuadraturePoint> pieces;
  for (std::vector<std::vector<int>> crossed(patches.size());;) {
    std::size_t n = 0;
    for (std::size_t p = 0; p < patches.size(); ++p) {
      const TMesh& mesh = out[p];
      const TSplineBasis& basis = patches[p]->basis();
      crossed[p].clear();
      for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
        const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
        box_quadrature(lo, hi, 1, pieces, basis, basis.locate(0.5 * (lo + hi)));
        if (pieces.size() > 1) crossed[p].push_back(c);
      }
      n += crossed[p].size();
    }
    if (n == 0) return out;
    refine_conforming(out, interfaces, crossed);
  }
}

// ------------------------------------------------------------------ PatchSpace

PatchSpace::PatchSpace(const TSplineMap& map, TMesh analysis_mesh)
    : mesh_(std::make_unique<TMesh>(std::move(analysis_mesh))) {
  if (!mesh_->has_topology()) throw InputError("analysis T-mesh: topology not built");
  basis_ = std::make_unique<HierarchicalBasis>(*mesh_);
  const TMesh& gm = map.mesh();
  geometry_cell_.resize(mesh_->num_cells());
  for (int c = 0; c < static_cast<int>(mesh_->num_cells()); ++c) {
    const QuadNode& q = mesh_->node(mesh_->cell_node(c));
    const IPoint lo = TMesh::node_min(q), hi = TMesh::node_max(q);
    const Eigen::Vector2d centre = 0.5 * (mesh_->cell_min(c) + mesh_->cell_max(c));
    const int g = map.basis().locate(centre);
    bool inside = g >= 0;
    if (inside) {
      const QuadNode& gq = gm.node(gm.cell_node(g));
      const IPoint glo = TMesh::node_min(gq), ghi = TMesh::node_max(gq);
      inside = glo.x <= lo.x && glo.y <= lo.y && hi.x <= ghi.x && hi.y <= ghi.y;
    }
    if (!inside)
      throw InputError("analysis T-mesh is not a refinement of the geometry T-mesh (cell " + std::to_string(c) + ")");
    geometry_cell_[c] = g;
  }
}

// ------------------------------------------------------------------ AnalysisSpace

namespace {

/// A patch's functions that do not vanish on its border: (function, level,
/// tangential index per side, -1 where it vanishes).
struct BorderFunction {
  int a = 0, level = 0;
  std::array<std::int64_t, 4> k{-1, -1, -1, -1};
};

std::vector<BorderFunction> border_functions(const HierarchicalBasis& b) {
  std::vector<BorderFunction> out;
  for (int a = 0; a < static_cast<int>(b.size()); ++a) {
    const HierarchicalFunction& f = b.function(a);
    if (!f.on_border) continue;
    BorderFunction bf;
    bf.a = a;
    bf.level = f.level;
    for (int side = 0; side < 4; ++side) bf.k[side] = side_index(f, side);
    out.push_back(bf);
  }
  return out;
}

/// Per patch, the patches sharing a side or a corner (a layout node) with it,
/// itself included: through the interfaces, corner side_a of patch a is corner
/// side_b + 1 of patch b, and corner side_a + 1 of a is corner side_b of b.
std::vector<std::vector<std::size_t>> patch_neighbours(std::size_t P, const std::vector<Interface>& interfaces) {
  UnionFind corners(4 * P);
  for (const Interface& f : interfaces) {
    corners.unite(static_cast<int>(4 * f.patch_a + f.side_a), static_cast<int>(4 * f.patch_b + (f.side_b + 1) % 4));
    corners.unite(static_cast<int>(4 * f.patch_a + (f.side_a + 1) % 4), static_cast<int>(4 * f.patch_b + f.side_b));
  }
  std::map<std::size_t, std::vector<std::size_t>> at_node;
  for (std::size_t p = 0; p < P; ++p)
    for (int k = 0; k < 4; ++k) at_node[corners.find(static_cast<int>(4 * p + k))].push_back(p);
  std::vector<std::vector<std::size_t>> out(P);
  for (const auto& [node, patches] : at_node)
    for (std::size_t p : patches) out[p].insert(out[p].end(), patches.begin(), patches.end());
  for (auto& n : out) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return out;
}

}  // namespace

AnalysisSpace::AnalysisSpace(const TSplineMap& map, TMesh analysis_mesh)
    : AnalysisSpace(AnalysisGeometry(map), [&] {
        std::vector<TMesh> m;
        m.push_back(std::move(analysis_mesh));
        return m;
      }()) {}

AnalysisSpace::AnalysisSpace(AnalysisGeometry geometry, std::vector<TMesh> meshes, int rank, int processes)
    : geometry_(std::move(geometry)), rank_(rank), processes_(processes) {
  const std::size_t P = geometry_.size();
  if (P == 0) throw InputError("analysis space: the map has no patch");
  if (meshes.size() != P)
    throw InputError("analysis space: " + std::to_string(meshes.size()) + " analysis meshes for " +
                     std::to_string(P) + " patches");
  if (processes < 1 || rank < 0 || rank >= processes)
    throw InputError("analysis space: process " + std::to_string(rank) + " of " + std::to_string(processes));
  for (const Interface& f : geometry_.interfaces)
    if (f.patch_a >= P || f.patch_b >= P || f.side_a < 0 || f.side_a > 3 || f.side_b < 0 || f.side_b > 3)
      throw InputError("analysis space: interface along cut " + std::to_string(f.cut) + " names a patch or side "
                       "that does not exist");
  cell_offset_.assign(P + 1, 0);
  for (std::size_t p = 0; p < P; ++p) cell_offset_[p + 1] = cell_offset_[p] + meshes[p].num_cells();

  // The patches held: those of this process's block of cells and their neighbours.
  std::vector<char> held(P, 0);
  {
    const auto [first, last] = block(rank_);
    const std::vector<std::vector<std::size_t>> neighbours = patch_neighbours(P, geometry_.interfaces);
    for (std::size_t p = 0; p < P; ++p)
      if (cell_offset_[p] < last && first < cell_offset_[p + 1])
        for (std::size_t q : neighbours[p]) held[q] = 1;
  }
  // Every patch's function count and border functions; the spaces held kept.
  patches_.resize(P);
  meshes_.resize(P);
  std::vector<std::size_t> offset(P + 1, 0);
  std::vector<std::vector<BorderFunction>> border;
  border.resize(P);
  for (std::size_t p = 0; p < P; ++p) {
    std::shared_ptr<const PatchSpace> sp;
    if (held[p]) {
      sp = std::make_shared<const PatchSpace>(geometry_.patch(p), std::move(meshes[p]));
      patches_[p] = sp;
    } else {
      meshes_[p] = std::move(meshes[p]);
      sp = std::make_shared<const PatchSpace>(geometry_.patch(p), meshes_[p]);  // for its border functions only
    }
    offset[p + 1] = offset[p] + sp->num_functions();
    border[p] = border_functions(sp->basis());
  }

  // Gluing across the interfaces: the border functions of side_b keyed by
  // (level, tangential index), each function of side_a matched to its mirror.
  interface_side_.assign(P, {0, 0, 0, 0});
  UnionFind uf(offset[P]);
  for (const Interface& f : geometry_.interfaces) {
    interface_side_[f.patch_a][f.side_a] = interface_side_[f.patch_b][f.side_b] = 1;
    std::map<std::pair<int, std::int64_t>, int> on_b;
    for (const BorderFunction& h : border[f.patch_b])
      if (h.k[f.side_b] >= 0) on_b[{h.level, h.k[f.side_b]}] = h.a;
    std::size_t matched = 0;
    for (const BorderFunction& h : border[f.patch_a]) {
      const std::int64_t k = h.k[f.side_a];
      if (k < 0) continue;
      const auto it = on_b.find({h.level, last_index(h.level) - k});
      if (it == on_b.end())
        throw NumericalError("interface along cut " + std::to_string(f.cut) + ": patch " + std::to_string(f.patch_a) +
                             " has a border function with no partner in patch " + std::to_string(f.patch_b) +
                             " (the analysis spaces are not conforming there)");
      uf.unite(static_cast<int>(offset[f.patch_a]) + h.a, static_cast<int>(offset[f.patch_b]) + it->second);
      ++matched;
    }
    if (matched != on_b.size())
      throw NumericalError("interface along cut " + std::to_string(f.cut) + ": the two sides have " +
                           std::to_string(matched) + " and " + std::to_string(on_b.size()) + " border functions");
    glued_pairs_ += matched;
  }

  // Numbering in patch order; Dirichlet: non-zero on a side that is not an interface.
  std::vector<int> root_id(offset[P], -1);
  dofs_.resize(P);
  int n = 0;
  for (std::size_t p = 0; p < P; ++p) {
    dofs_[p].resize(offset[p + 1] - offset[p]);
    for (std::size_t a = 0; a < dofs_[p].size(); ++a) {
      const std::size_t r = uf.find(offset[p] + a);
      if (root_id[r] < 0) root_id[r] = n++;
      dofs_[p][a] = root_id[r];
    }
  }
  num_dofs_ = static_cast<std::size_t>(n);
  dirichlet_.assign(num_dofs_, 0);
  for (std::size_t p = 0; p < P; ++p)
    for (const BorderFunction& h : border[p])
      for (int side = 0; side < 4; ++side)
        if (!interface_side_[p][side] && h.k[side] >= 0) dirichlet_[dofs_[p][h.a]] = 1;
}

std::shared_ptr<const AnalysisSpace> AnalysisSpace::completed() const {
  auto out = std::shared_ptr<AnalysisSpace>(new AnalysisSpace());
  *out = *this;  // copies the numbering, shares the spaces held
  for (std::size_t p = 0; p < patches_.size(); ++p)
    if (!out->patches_[p]) {
      out->patches_[p] = std::make_shared<const PatchSpace>(map(p), std::move(out->meshes_[p]));
      out->meshes_[p] = TMesh();
    }
  return out;
}

bool AnalysisSpace::holds_all() const {
  return std::all_of(patches_.begin(), patches_.end(), [](const auto& p) { return p != nullptr; });
}

const PatchSpace& AnalysisSpace::patch(std::size_t p) const {
  if (!patches_[p])
    throw toolkit::InternalError("analysis space: patch " + std::to_string(p) + " is not held by process " +
                           std::to_string(rank_));
  return *patches_[p];
}

std::shared_ptr<const PatchSpace> AnalysisSpace::patch_space(std::size_t p) const {
  return patches_[p] ? patches_[p] : std::make_shared<const PatchSpace>(map(p), meshes_[p]);
}

std::pair<std::size_t, std::size_t> AnalysisSpace::block(int r) const {
  const std::size_t nc = num_cells(), Pr = static_cast<std::size_t>(processes_);
  const auto start = [&](std::size_t q) {
    return static_cast<std::size_t>(static_cast<std::uint64_t>(nc) * q / Pr);
  };
  return {start(static_cast<std::size_t>(r)), start(static_cast<std::size_t>(r) + 1)};
}

std::pair<std::size_t, int> AnalysisSpace::cell(std::size_t gc) const {
  const auto it = std::upper_bound(cell_offset_.begin(), cell_offset_.end(), gc);
  const std::size_t p = static_cast<std::size_t>(it - cell_offset_.begin()) - 1;
  return {p, static_cast<int>(gc - cell_offset_[p])};
}

void AnalysisSpace::cell_dofs(std::size_t gc, std::vector<int>& out) const {
  const auto [p, c] = cell(gc);
  out.clear();
  for (int a : patch(p).basis().functions_on_cell(c)) out.push_back(dofs_[p][a]);
}

}  // namespace tspline

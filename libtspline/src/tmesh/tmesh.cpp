#include "tspline/tmesh/tmesh.h"

#include <algorithm>
#include <deque>
#include <sstream>
#include <stdexcept>

#include "tspline/errors.h"

namespace tspline {

TMesh::TMesh(int initial_level) {
  if (initial_level < 0 || initial_level > 12) {
    throw InputError("initial level must be in [0, 12], got " + std::to_string(initial_level));
  }
  nodes_.push_back(QuadNode{});
  // Breadth-first uniform refinement.
  std::vector<int> frontier{0};
  for (int l = 0; l < initial_level; ++l) {
    std::vector<int> next;
    next.reserve(frontier.size() * 4);
    for (int n : frontier) {
      const int c = refine(n);
      for (int k = 0; k < 4; ++k) next.push_back(c + k);
    }
    frontier.swap(next);
  }
}

int TMesh::refine(int n) {
  if (!nodes_.at(n).is_leaf()) throw toolkit::InternalError("TMesh::refine: node is not a leaf");
  if (nodes_[n].level >= kMaxLevel) throw toolkit::InternalError("TMesh::refine: maximum level reached");
  topology_valid_ = false;
  const int first = static_cast<int>(nodes_.size());
  const QuadNode parent = nodes_[n];
  for (int k = 0; k < 4; ++k) {
    QuadNode c;
    c.parent = n;
    c.level = parent.level + 1;
    c.i = 2 * parent.i + (k & 1);
    c.j = 2 * parent.j + (k >> 1);
    nodes_.push_back(c);
  }
  nodes_[n].first_child = first;
  return first;
}

int TMesh::leaf_at_doubled(std::int64_t px, std::int64_t py) const {
  if (px <= 0 || py <= 0 || px >= 2 * kRoot || py >= 2 * kRoot) return -1;
  int n = 0;
  while (!nodes_[n].is_leaf()) {
    const QuadNode& q = nodes_[n];
    const std::int64_t size = node_size(q);
    const std::int64_t mid2x = 2 * q.i * size + size;  // doubled midpoint
    const std::int64_t mid2y = 2 * q.j * size + size;
    n = q.first_child + (px > mid2x ? 1 : 0) + (py > mid2y ? 2 : 0);
  }
  return n;
}

// Leaf across edge e, sampled just outside the midpoint of the edge. If that
// leaf is at least as large as q it contains the whole edge.
int TMesh::neighbour_leaf(const QuadNode& q, CellEdge e) const {
  const IPoint lo = node_min(q), hi = node_max(q);
  const std::int64_t mx = lo.x + hi.x, my = lo.y + hi.y;  // doubled midpoints
  switch (e) {
    case CellEdge::Bottom: return leaf_at_doubled(mx, 2 * lo.y - 1);
    case CellEdge::Right: return leaf_at_doubled(2 * hi.x + 1, my);
    case CellEdge::Top: return leaf_at_doubled(mx, 2 * hi.y + 1);
    case CellEdge::Left: return leaf_at_doubled(2 * lo.x - 1, my);
  }
  return -1;
}

std::size_t TMesh::balance() {
  std::deque<int> queue;
  for (int n = 0; n < static_cast<int>(nodes_.size()); ++n)
    if (nodes_[n].is_leaf()) queue.push_back(n);
  std::size_t splits = 0;
  while (!queue.empty()) {
    const int n = queue.front();
    queue.pop_front();
    if (!nodes_[n].is_leaf()) continue;
    for (int e = 0; e < 4; ++e) {
      const int nb = neighbour_leaf(nodes_[n], static_cast<CellEdge>(e));
      if (nb < 0 || nodes_[nb].level >= nodes_[n].level - 1) continue;
      const int c = refine(nb);
      ++splits;
      for (int k = 0; k < 4; ++k) queue.push_back(c + k);
      queue.push_back(n);  // the new neighbour may still be too coarse
      break;
    }
  }
  if (splits > 0) topology_valid_ = false;
  return splits;
}

int TMesh::max_level() const {
  int m = 0;
  for (const QuadNode& q : nodes_)
    if (q.is_leaf()) m = std::max(m, q.level);
  return m;
}

void TMesh::build_topology() {
  cell_node_.clear();
  node_cell_.assign(nodes_.size(), -1);
  // Depth-first (Morton) order of the leaves: neighbouring cells get close numbers.
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    if (nodes_[n].is_leaf()) {
      node_cell_[n] = static_cast<int>(cell_node_.size());
      cell_node_.push_back(n);
    } else {
      for (int k = 3; k >= 0; --k) stack.push_back(nodes_[n].first_child + k);
    }
  }
  const std::size_t nc = cell_node_.size();
  vertex_lookup_.clear();
  vertex_lookup_.reserve(nc * 2 + 16);
  vertex_ipos_.clear();
  cell_corners_.assign(nc, {-1, -1, -1, -1});
  auto vertex_id = [&](const IPoint& p) {
    auto [it, inserted] = vertex_lookup_.try_emplace(key(p), static_cast<int>(vertex_ipos_.size()));
    if (inserted) vertex_ipos_.push_back(p);
    return it->second;
  };
  for (std::size_t c = 0; c < nc; ++c) {
    const QuadNode& q = nodes_[cell_node_[c]];
    const IPoint lo = node_min(q), hi = node_max(q);
    cell_corners_[c] = {vertex_id(lo), vertex_id({hi.x, lo.y}), vertex_id(hi), vertex_id({lo.x, hi.y})};
  }
  vertex_hanging_cell_.assign(vertex_ipos_.size(), -1);
  cell_mid_.assign(nc, {-1, -1, -1, -1});
  for (std::size_t c = 0; c < nc; ++c) {
    const QuadNode& q = nodes_[cell_node_[c]];
    if (q.level >= kMaxLevel) continue;
    const IPoint lo = node_min(q), hi = node_max(q);
    const std::int64_t h = node_size(q) / 2;
    const IPoint mids[4] = {{lo.x + h, lo.y}, {hi.x, lo.y + h}, {lo.x + h, hi.y}, {lo.x, lo.y + h}};
    for (int e = 0; e < 4; ++e) {
      const int v = find_vertex(mids[e]);
      if (v < 0) continue;
      // A vertex at the quarter point would mean two hanging vertices on one edge.
      const IPoint quarter = (e % 2 == 0) ? IPoint{lo.x + h / 2, mids[e].y} : IPoint{mids[e].x, lo.y + h / 2};
      const IPoint quarter2 = (e % 2 == 0) ? IPoint{hi.x - h / 2, mids[e].y} : IPoint{mids[e].x, hi.y - h / 2};
      if (h >= 2 && (find_vertex(quarter) >= 0 || find_vertex(quarter2) >= 0))
        throw toolkit::InternalError("TMesh::build_topology: the tree is not 2:1 balanced");
      cell_mid_[c][e] = v;
      vertex_hanging_cell_[v] = static_cast<int>(c);
    }
  }
  topology_valid_ = true;
}

int TMesh::find_vertex(const IPoint& p) const {
  auto it = vertex_lookup_.find(key(p));
  return it == vertex_lookup_.end() ? -1 : it->second;
}

std::vector<int> TMesh::cell_polygon(int c) const {
  std::vector<int> poly;
  poly.reserve(8);
  for (int e = 0; e < 4; ++e) {
    poly.push_back(cell_corners_[c][e]);
    if (cell_mid_[c][e] >= 0) poly.push_back(cell_mid_[c][e]);
  }
  return poly;
}

Eigen::Vector2d TMesh::cell_min(int c) const {
  const IPoint p = node_min(nodes_[cell_node_[c]]);
  return {static_cast<double>(p.x) / kRoot, static_cast<double>(p.y) / kRoot};
}
Eigen::Vector2d TMesh::cell_max(int c) const {
  const IPoint p = node_max(nodes_[cell_node_[c]]);
  return {static_cast<double>(p.x) / kRoot, static_cast<double>(p.y) / kRoot};
}
double TMesh::cell_size(int c) const {
  return static_cast<double>(node_size(nodes_[cell_node_[c]])) / kRoot;
}

Eigen::Vector2d TMesh::vertex_param(int v) const {
  return {static_cast<double>(vertex_ipos_[v].x) / kRoot, static_cast<double>(vertex_ipos_[v].y) / kRoot};
}

bool TMesh::vertex_on_boundary(int v) const {
  const IPoint& p = vertex_ipos_[v];
  return p.x == 0 || p.y == 0 || p.x == kRoot || p.y == kRoot;
}

std::array<int, 4> TMesh::cells_around(int v) const {
  const IPoint& p = vertex_ipos_[v];
  const std::int64_t x = 2 * p.x, y = 2 * p.y;
  std::array<int, 4> out;
  const int leaves[4] = {leaf_at_doubled(x - 1, y - 1), leaf_at_doubled(x + 1, y - 1),
                         leaf_at_doubled(x + 1, y + 1), leaf_at_doubled(x - 1, y + 1)};
  for (int k = 0; k < 4; ++k) out[k] = leaves[k] < 0 ? -1 : node_cell_[leaves[k]];
  return out;
}

std::size_t TMesh::num_hanging_vertices() const {
  return static_cast<std::size_t>(
      std::count_if(vertex_hanging_cell_.begin(), vertex_hanging_cell_.end(), [](int c) { return c >= 0; }));
}

std::string TMesh::check_invariants() const {
  if (!topology_valid_) return "topology not built";
  std::ostringstream err;
  // 1. Tiling: leaf areas sum to the unit square (exact integer arithmetic in
  //    units of the finest cell), and leaves are disjoint because they are the
  //    leaves of a quadtree (each point descends to exactly one leaf).
  const int lmax = max_level();
  std::uint64_t area = 0;  // in units of the finest cell: at most 4^30
  for (int n : cell_node_) {
    const int d = lmax - nodes_[n].level;
    area += std::uint64_t{1} << (2 * d);
  }
  if (area != (std::uint64_t{1} << (2 * lmax))) err << "cells do not tile [0,1]^2; ";
  // 2. 2:1 balance across edges.
  for (std::size_t c = 0; c < cell_node_.size(); ++c) {
    const QuadNode& q = nodes_[cell_node_[c]];
    for (int e = 0; e < 4; ++e) {
      const int nb = neighbour_leaf(q, static_cast<CellEdge>(e));
      if (nb >= 0 && nodes_[nb].level < q.level - 1) {
        err << "cells " << c << " and " << node_cell_[nb] << " violate 2:1 balance; ";
        return err.str();
      }
    }
  }
  // 3. Hanging vertices: midpoint of exactly one larger cell's edge, corner of the
  //    two cells on the other side, which have half its size.
  for (std::size_t v = 0; v < vertex_ipos_.size(); ++v) {
    const std::array<int, 4> around = cells_around(static_cast<int>(v));
    int repeated = 0;
    for (int k = 0; k < 4; ++k)
      if (around[k] >= 0 && around[k] == around[(k + 1) % 4]) ++repeated;
    const int hc = vertex_hanging_cell_[v];
    if ((hc >= 0) != (repeated == 1) || repeated > 1) {
      err << "vertex " << v << " hanging status inconsistent; ";
      return err.str();
    }
    if (hc < 0) continue;
    for (int k = 0; k < 4; ++k) {
      const int c = around[k];
      if (c < 0 || c == hc) continue;
      if (cell_level(c) != cell_level(hc) + 1) {
        err << "hanging vertex " << v << ": cell " << c << " is not half the size of T-junction cell " << hc
            << "; ";
        return err.str();
      }
    }
  }
  return err.str();
}

TMesh refine_cells(const TMesh& mesh, const std::vector<int>& cells) {
  TMesh out = mesh;
  for (int c : cells) {
    const int n = mesh.cell_node(c);  // node ids stay valid: refine() appends children
    if (out.node(n).is_leaf()) out.refine(n);
  }
  out.balance();
  out.build_topology();
  return out;
}

}  // namespace tspline

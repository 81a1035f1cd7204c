#pragma once
// Balanced quadtree T-mesh on the parametric domain [0,1]^2 (Brovka 2013 Sect. 2-3).
//
// Topology is exact: every vertex and cell corner has integer (dyadic)
// coordinates in [0, kRoot], kRoot = 2^kMaxLevel, and the parametric point is
// coordinate / kRoot. Doubles are never compared for vertex identity.
//
// Life cycle: build the tree (uniform start, refine(), balance()), then call
// build_topology() to number cells and vertices. Mutating the tree invalidates
// the numbering until build_topology() is called again.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace tspline {

struct IPoint {
  std::int64_t x = 0;
  std::int64_t y = 0;
  friend bool operator==(const IPoint&, const IPoint&) = default;
};

/// Twice the signed area of the triangle (a, b, c), exact: coordinates are at most 2^30,
/// so each product is below 2^61.
inline std::int64_t orient_exact(const IPoint& a, const IPoint& b, const IPoint& c) {
  return static_cast<std::int64_t>(b.x - a.x) * (c.y - a.y) - static_cast<std::int64_t>(b.y - a.y) * (c.x - a.x);
}

/// A quadtree node; leaves are the T-mesh cells. Children are stored
/// consecutively (SW, SE, NW, NE) starting at first_child.
struct QuadNode {
  std::int32_t first_child = -1;
  std::int32_t parent = -1;
  std::int32_t level = 0;
  std::int64_t i = 0;  ///< column at its level: x-range [i, i+1] * size
  std::int64_t j = 0;  ///< row at its level
  bool is_leaf() const { return first_child < 0; }
};

/// Edge numbering of a cell: bottom, right, top, left (counter-clockwise).
enum class CellEdge { Bottom = 0, Right = 1, Top = 2, Left = 3 };

class TMesh {
 public:
  static constexpr int kMaxLevel = 30;
  static constexpr std::int64_t kRoot = std::int64_t{1} << kMaxLevel;

  /// Uniform mesh of 2^level x 2^level cells. \throw InputError if level is not in [0, 12].
  explicit TMesh(int initial_level = 0);

  // ---------------------------------------------------------------- tree
  const std::vector<QuadNode>& nodes() const { return nodes_; }
  const QuadNode& node(int n) const { return nodes_[n]; }
  static std::int64_t node_size(const QuadNode& q) { return kRoot >> q.level; }
  /// Lower-left and upper-right integer corners of a node.
  static IPoint node_min(const QuadNode& q) { return {q.i * node_size(q), q.j * node_size(q)}; }
  static IPoint node_max(const QuadNode& q) { return {(q.i + 1) * node_size(q), (q.j + 1) * node_size(q)}; }

  /// Splits a leaf into four. Returns the index of its first child.
  /// \throw InternalError if n is not a leaf or is at kMaxLevel.
  int refine(int n);
  /// Refines until no two edge-adjacent leaves differ by more than one level
  /// (2:1 balance: at most one hanging vertex per cell edge). Returns the number of splits.
  std::size_t balance();
  /// Leaf containing the point given in DOUBLED integer coordinates (2x, 2y);
  /// the point must not lie on a cell line (use odd doubled coordinates).
  /// Returns -1 outside [0,1]^2.
  int leaf_at_doubled(std::int64_t px, std::int64_t py) const;
  /// Maximum leaf level.
  int max_level() const;

  // ---------------------------------------------------------------- topology
  /// Numbers cells (leaves, in depth-first = Morton order) and vertices.
  /// \pre the tree is balanced (checked: throws InternalError otherwise).
  void build_topology();
  bool has_topology() const { return topology_valid_; }

  std::size_t num_cells() const { return cell_node_.size(); }
  std::size_t num_vertices() const { return vertex_ipos_.size(); }

  int cell_node(int c) const { return cell_node_[c]; }
  int cell_of_node(int n) const { return node_cell_[n]; }
  int cell_level(int c) const { return nodes_[cell_node_[c]].level; }
  /// Corner vertex ids, counter-clockwise from the lower-left corner.
  const std::array<int, 4>& cell_corners(int c) const { return cell_corners_[c]; }
  /// Hanging vertex at the midpoint of each edge (bottom, right, top, left), or -1.
  const std::array<int, 4>& cell_edge_midpoints(int c) const { return cell_mid_[c]; }
  /// The cell as a counter-clockwise polygon including its hanging vertices.
  std::vector<int> cell_polygon(int c) const;
  /// Parametric corners of the cell.
  Eigen::Vector2d cell_min(int c) const;
  Eigen::Vector2d cell_max(int c) const;
  /// Parametric edge length of the cell.
  double cell_size(int c) const;

  const IPoint& vertex_ipos(int v) const { return vertex_ipos_[v]; }
  Eigen::Vector2d vertex_param(int v) const;
  bool vertex_on_boundary(int v) const;
  /// The cell in whose edge interior v lies (v is a T-junction), or -1 if v is regular.
  int vertex_hanging_cell(int v) const { return vertex_hanging_cell_[v]; }
  bool vertex_is_hanging(int v) const { return vertex_hanging_cell_[v] >= 0; }
  /// Cells around v in the quadrants SW, SE, NE, NW (-1 outside [0,1]^2). For a
  /// hanging vertex the T-junction cell appears in two adjacent quadrants.
  std::array<int, 4> cells_around(int v) const;
  /// Vertex id at an integer point, or -1.
  int find_vertex(const IPoint& p) const;
  std::size_t num_hanging_vertices() const;

  /// Checks the invariants (cells tile [0,1]^2 exactly, 2:1 balance, every
  /// hanging vertex is the midpoint of exactly one larger cell's edge and a corner
  /// of the two cells on the other side). Returns "" if all hold, else a description.
  std::string check_invariants() const;

 private:
  static std::uint64_t key(const IPoint& p) {
    return static_cast<std::uint64_t>(p.x) * static_cast<std::uint64_t>(kRoot + 1) +
           static_cast<std::uint64_t>(p.y);
  }
  int neighbour_leaf(const QuadNode& q, CellEdge e) const;

  std::vector<QuadNode> nodes_;
  bool topology_valid_ = false;
  std::vector<int> cell_node_;
  std::vector<int> node_cell_;
  std::vector<std::array<int, 4>> cell_corners_;
  std::vector<std::array<int, 4>> cell_mid_;
  std::vector<IPoint> vertex_ipos_;
  std::vector<int> vertex_hanging_cell_;
  std::unordered_map<std::uint64_t, int> vertex_lookup_;
};

/// The one refine-and-rebalance step of every adaptive loop (the front's repair,
/// the boundary-curve and adaptive rounds of the map, the Poisson estimator):
/// a copy of `mesh` with the given cells (numbering of `mesh`) split into four,
/// re-balanced 2:1 and its topology rebuilt. Repeated cells are split once.
/// \pre mesh has its topology; \throw InternalError for a cell at kMaxLevel
/// (callers filter by their own maximum level first).
TMesh refine_cells(const TMesh& mesh, const std::vector<int>& cells);

}  // namespace tspline

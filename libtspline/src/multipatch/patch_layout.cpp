// Patches of a domain cut by polylines: the faces of the plane graph of rings
// and cuts, found by the usual half-edge walk (at each vertex turn to the
// first outgoing edge clockwise from the one we came along).
#include "tspline/multipatch/patch_layout.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "tspline/boundary/plane.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/errors.h"

namespace tspline {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using CPoint = K::Point_2;
using CSegment = K::Segment_2;

const Polygon& ring(const Domain& d, std::size_t r) { return r == 0 ? d.outer : d.holes[r - 1]; }
std::size_t ring_count(const Domain& d) { return d.holes.size() + 1; }

double diameter(const Domain& d) { return bounding_box_diagonal(d.outer); }

double snap_tolerance(const Domain& d) { return 1e-9 * diameter(d); }

std::string fmt(const Eigen::Vector2d& p) {
  std::ostringstream s;
  s.precision(10);
  s << '(' << p.x() << ", " << p.y() << ')';
  return s.str();
}

// Closest point of segment [a, b] to p, as the parameter s in [0, 1].
double project(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double l2 = ab.squaredNorm();
  return l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
}

struct RingHit {
  std::size_t ring = 0, edge = 0;
  double s = 0.0, distance = std::numeric_limits<double>::infinity();
};

// The ring edges of a domain on a uniform grid, for the queries that a scan
// of every edge per cut made quadratic (Newfoundland: 16,000 cuts and 3,100
// ring edges per patch layout): the closest ring point, and the edges near a
// cut segment. Edge ids run ring by ring, edge by edge, and both queries give
// what a scan in that order gives.
class RingEdgeGrid {
 public:
  explicit RingEdgeGrid(const Domain& d) : d_(d) {
    std::size_t edges = 0;
    Eigen::Vector2d hi = d.outer.vertices.front();
    lo_ = hi;
    for (std::size_t r = 0; r < ring_count(d); ++r)
      for (const auto& v : ring(d, r).vertices) lo_ = lo_.cwiseMin(v), hi = hi.cwiseMax(v), ++edges;
    // About one edge per cell.
    const Eigen::Vector2d extent = hi - lo_;
    const double side = std::max(extent.x(), extent.y());
    const double per_side = std::clamp(std::ceil(std::sqrt(static_cast<double>(edges))), 1.0, 2048.0);
    cell_ = side > 0.0 ? side / per_side : 1.0;
    nx_ = std::max(1, static_cast<int>(std::ceil(extent.x() / cell_)));
    ny_ = std::max(1, static_cast<int>(std::ceil(extent.y() / cell_)));
    // Each edge in every cell its bounding box (a little widened) meets, so
    // that the closest point of an edge lies in a cell that holds the edge.
    std::vector<std::pair<int, int>> in_cell;  // (cell, edge)
    for (std::size_t r = 0; r < ring_count(d); ++r) {
      const auto& v = ring(d, r).vertices;
      for (std::size_t i = 0; i < v.size(); ++i) {
        const Eigen::Vector2d a = v[i], b = v[(i + 1) % v.size()];
        const int e = static_cast<int>(edge_ring_.size());
        edge_ring_.push_back(r), edge_index_.push_back(i);
        const auto [i0, j0, i1, j1] = cells_meeting(a.cwiseMin(b), a.cwiseMax(b));
        for (int j = j0; j <= j1; ++j)
          for (int k = i0; k <= i1; ++k) in_cell.push_back({k + nx_ * j, e});
      }
    }
    std::sort(in_cell.begin(), in_cell.end());
    first_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
    for (const auto& [c, e] : in_cell) ++first_[static_cast<std::size_t>(c) + 1], edges_.push_back(e);
    for (std::size_t c = 1; c < first_.size(); ++c) first_[c] += first_[c - 1];
    seen_.assign(edge_ring_.size(), 0);
  }

  std::size_t ring_of(int e) const { return edge_ring_[e]; }
  std::size_t index_of(int e) const { return edge_index_[e]; }

  // The edges whose bounding boxes may meet the box [lo, hi] (every one that
  // does, and others near), in id order, each once.
  void edges_near(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, std::vector<int>& out) const {
    out.clear();
    const auto [i0, j0, i1, j1] = cells_meeting(lo, hi);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const std::size_t c = static_cast<std::size_t>(i + nx_ * j);
        out.insert(out.end(), edges_.begin() + static_cast<std::ptrdiff_t>(first_[c]),
                   edges_.begin() + static_cast<std::ptrdiff_t>(first_[c + 1]));
      }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  // The closest point of the rings to p: the first edge at the least
  // distance, searched outwards from p's cell. (Not thread-safe: the search
  // marks the edges it has measured.)
  RingHit closest(const Eigen::Vector2d& p) {
    RingHit best;
    if (!p.allFinite()) return best;  // (no distance is less than infinity: as a scan finds)
    ++stamp_;
    const auto [ci, cj] = cell_of(p);
    for (int k = 0;; ++k) {
      const int i0 = std::max(0, ci - k), i1 = std::min(nx_ - 1, ci + k);
      const int j0 = std::max(0, cj - k), j1 = std::min(ny_ - 1, cj + k);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          // Only the cells on the square's border are new.
          if (k > 0 && j != cj - k && j != cj + k && i != ci - k && i != ci + k) continue;
          measure(i + nx_ * j, p, best);
        }
      // Every edge not measured has its closest point in a cell outside the
      // square: at least `beyond` from p (with a margin for the rounding of cells).
      double beyond = std::numeric_limits<double>::infinity();
      if (i0 > 0) beyond = std::min(beyond, p.x() - (lo_.x() + i0 * cell_));
      if (i1 < nx_ - 1) beyond = std::min(beyond, lo_.x() + (i1 + 1) * cell_ - p.x());
      if (j0 > 0) beyond = std::min(beyond, p.y() - (lo_.y() + j0 * cell_));
      if (j1 < ny_ - 1) beyond = std::min(beyond, lo_.y() + (j1 + 1) * cell_ - p.y());
      if (!std::isfinite(beyond) || best.distance < beyond - 1e-6 * cell_) return best;
    }
  }

 private:
  std::pair<int, int> cell_of(const Eigen::Vector2d& p) const {
    auto index = [&](double x, double lo, int n) {
      const double c = std::floor((x - lo) / cell_);
      return c < 0.0 ? 0 : c >= n - 1 ? n - 1 : static_cast<int>(c);
    };
    return {index(p.x(), lo_.x(), nx_), index(p.y(), lo_.y(), ny_)};
  }

  // The cells (i0, j0, i1, j1) that the box [lo, hi] meets, widened a little
  // against the rounding of cell_of.
  std::array<int, 4> cells_meeting(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
    const Eigen::Vector2d pad = Eigen::Vector2d::Constant(1e-9 * cell_);
    const auto [i0, j0] = cell_of(lo - pad);
    const auto [i1, j1] = cell_of(hi + pad);
    return {i0, j0, i1, j1};
  }

  // The edges of cell c not measured yet; the first in ring and edge order of equals wins.
  void measure(int c, const Eigen::Vector2d& p, RingHit& best) {
    for (std::size_t k = first_[static_cast<std::size_t>(c)]; k < first_[static_cast<std::size_t>(c) + 1];
         ++k) {
      const int e = edges_[k];
      if (seen_[e] == stamp_) continue;
      seen_[e] = stamp_;
      const std::size_t r = edge_ring_[e], i = edge_index_[e];
      const auto& v = ring(d_, r).vertices;
      const Eigen::Vector2d &a = v[i], &b = v[(i + 1) % v.size()];
      const double s = project(p, a, b);
      const double dist = (a + s * (b - a) - p).norm();
      if (dist < best.distance ||
          (dist == best.distance && std::pair(r, i) < std::pair(best.ring, best.edge)))
        best = {r, i, s, dist};
    }
  }

  const Domain& d_;
  Eigen::Vector2d lo_;
  double cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
  std::vector<std::size_t> first_;  // cell c's edges: edges_[first_[c] .. first_[c + 1])
  std::vector<int> edges_;
  std::vector<std::size_t> edge_ring_, edge_index_;
  std::vector<unsigned> seen_;
  unsigned stamp_ = 0;
};

CPoint cpoint(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }

// The plane graph of rings and cuts.
struct Graph {
  std::vector<Eigen::Vector2d> points;
  std::vector<char> is_node;
  struct HalfEdge {
    int from, to, cut;
  };
  std::vector<HalfEdge> half_edges;
  std::vector<std::vector<int>> outgoing;
};

// The building of a Graph: ring vertices first (ring r, vertex i ->
// ring_first_[r] + i), then the cuts' ends and inner points, then the half-edges.
class GraphBuilder {
 public:
  explicit GraphBuilder(const Domain& d) : d_(d), tol_(snap_tolerance(d)), ring_edges_(d) {
    for (std::size_t r = 0; r < ring_count(d); ++r) {
      ring_first_.push_back(g_.points.size());
      for (const auto& v : ring(d, r).vertices) g_.points.push_back(v);
    }
    g_.is_node.assign(g_.points.size(), 0);
  }

  Graph build(const std::vector<Cut>& cuts, const std::vector<Eigen::Vector2d>& ring_corners) {
    for (const Eigen::Vector2d& p : ring_corners) end_id(p);
    std::vector<std::vector<int>> cut_ids(cuts.size());
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      cut_ids[c].push_back(end_id(cuts[c].front()));
      for (std::size_t k = 1; k + 1 < cuts[c].size(); ++k) cut_ids[c].push_back(new_point(cuts[c][k]));
      cut_ids[c].push_back(end_id(cuts[c].back()));
    }
    add_ring_edges();
    for (std::size_t c = 0; c < cuts.size(); ++c)
      for (std::size_t k = 0; k + 1 < cut_ids[c].size(); ++k) {
        add(cut_ids[c][k], cut_ids[c][k + 1], static_cast<int>(c));
        add(cut_ids[c][k + 1], cut_ids[c][k], static_cast<int>(c));
      }
    g_.outgoing.assign(g_.points.size(), {});
    for (std::size_t h = 0; h < g_.half_edges.size(); ++h)
      g_.outgoing[g_.half_edges[h].from].push_back(static_cast<int>(h));
    return std::move(g_);
  }

 private:
  using Cell = std::pair<long long, long long>;
  Cell cell_of(const Eigen::Vector2d& p) const {
    return {static_cast<long long>(std::floor(p.x() / tol_)), static_cast<long long>(std::floor(p.y() / tol_))};
  }
  int new_point(const Eigen::Vector2d& p) {
    g_.points.push_back(p);
    g_.is_node.push_back(0);
    return static_cast<int>(g_.points.size()) - 1;
  }
  void add(int a, int b, int cut) { g_.half_edges.push_back({a, b, cut}); }

  // A cut end (or a given ring corner): an end found before within tol, a
  // ring vertex, a new vertex on a ring edge, or a new node inside the domain
  // where cuts meet (the first of them to arrive there).
  int end_id(const Eigen::Vector2d& p) {
    const auto [ci, cj] = cell_of(p);
    for (long long i = ci - 1; i <= ci + 1; ++i)
      for (long long j = cj - 1; j <= cj + 1; ++j) {
        auto it = ends_.find({i, j});
        if (it == ends_.end()) continue;
        for (int e : it->second)
          if ((g_.points[e] - p).norm() <= tol_) return e;
      }
    const RingHit h = ring_edges_.closest(p);
    const auto& v = ring(d_, h.ring).vertices;
    const Eigen::Vector2d a = v[h.edge], b = v[(h.edge + 1) % v.size()];
    int id;
    if (h.distance > tol_) {
      id = new_point(p);
    } else if ((a - p).norm() <= tol_) {
      id = static_cast<int>(ring_first_[h.ring] + h.edge);
    } else if ((b - p).norm() <= tol_) {
      id = static_cast<int>(ring_first_[h.ring] + (h.edge + 1) % v.size());
    } else {
      id = new_point(a + h.s * (b - a));
      inserted_[{h.ring, h.edge}].push_back({h.s, id});
    }
    g_.is_node[id] = 1;
    ends_[cell_of(p)].push_back(id);
    return id;
  }

  // Each ring's edges, split at the cut ends inserted on them. The domain lies
  // left of the outer ring (CCW) and right of each hole (CCW): holes are
  // walked backwards.
  void add_ring_edges() {
    for (std::size_t r = 0; r < ring_count(d_); ++r) {
      const std::size_t n = ring(d_, r).vertices.size();
      std::vector<int> seq;
      for (std::size_t i = 0; i < n; ++i) {
        seq.push_back(static_cast<int>(ring_first_[r] + i));
        auto it = inserted_.find({r, i});
        if (it == inserted_.end()) continue;
        auto on_edge = it->second;
        std::sort(on_edge.begin(), on_edge.end());
        for (const auto& [s, id] : on_edge) seq.push_back(id);
      }
      for (std::size_t i = 0; i < seq.size(); ++i) {
        const int a = seq[i], b = seq[(i + 1) % seq.size()];
        if (r == 0)
          add(a, b, -1);
        else
          add(b, a, -1);
      }
    }
  }

  const Domain& d_;
  const double tol_;
  RingEdgeGrid ring_edges_;
  Graph g_;
  std::vector<std::size_t> ring_first_;
  // Vertices inserted on ring edges: (ring, edge) -> (edge parameter, id).
  std::map<std::pair<std::size_t, std::size_t>, std::vector<std::pair<double, int>>> inserted_;
  // Ends found so far, by a grid of cells of size tol (a match lies in one of the 3 x 3 cells around).
  std::map<Cell, std::vector<int>> ends_;
};

Graph build_graph(const Domain& d, const std::vector<Cut>& cuts, const std::vector<Eigen::Vector2d>& ring_corners) {
  return GraphBuilder(d).build(cuts, ring_corners);
}

double angle_of(const Eigen::Vector2d& v) { return std::atan2(v.y(), v.x()); }

// The outgoing half-edge at the end of h that is first clockwise from the reverse of h.
int next_half_edge(const Graph& g, int h) {
  const auto& e = g.half_edges[h];
  const Eigen::Vector2d v = g.points[e.to];
  const double ref = angle_of(g.points[e.from] - v);
  int best = -1;
  double best_cw = 0.0;
  for (int o : g.outgoing[e.to]) {
    double cw = ref - angle_of(g.points[g.half_edges[o].to] - v);
    while (cw <= 1e-15) cw += 2.0 * std::numbers::pi;
    while (cw > 2.0 * std::numbers::pi) cw -= 2.0 * std::numbers::pi;
    if (best < 0 || cw < best_cw) best = o, best_cw = cw;
  }
  return best;
}

// Faces with their vertex ids (for the simplicity check).
std::vector<std::pair<LayoutFace, std::vector<int>>> faces_with_ids(const Domain& d, const std::vector<Cut>& cuts,
                                                                    const std::vector<Eigen::Vector2d>& ring_corners) {
  const Graph g = build_graph(d, cuts, ring_corners);
  std::vector<char> seen(g.half_edges.size(), 0);
  std::vector<std::pair<LayoutFace, std::vector<int>>> out;
  for (std::size_t h0 = 0; h0 < g.half_edges.size(); ++h0) {
    if (seen[h0]) continue;
    LayoutFace f;
    std::vector<int> ids;
    for (int h = static_cast<int>(h0); !seen[h]; h = next_half_edge(g, h)) {
      seen[h] = 1;
      const auto& e = g.half_edges[h];
      f.points.push_back(g.points[e.from]);
      f.is_node.push_back(g.is_node[e.from]);
      f.edge_cut.push_back(e.cut);
      ids.push_back(e.from);
      if (f.points.size() > g.half_edges.size()) break;  // cannot happen on a plane graph
    }
    out.push_back({std::move(f), std::move(ids)});
  }
  return out;
}


// Interior angle (radians) of a CCW polygon at vertex i.
double inner_angle(const std::vector<Eigen::Vector2d>& p, std::size_t i) {
  const std::size_t n = p.size();
  return ccw_angle(p[(i + 1) % n] - p[i], p[(i + n - 1) % n] - p[i]);
}

std::string face_name(const LayoutFace& f) {
  std::set<int> cuts;
  for (int c : f.edge_cut)
    if (c >= 0) cuts.insert(c + 1);
  std::ostringstream s;
  s << "the patch near " << fmt(f.points.front());
  if (!cuts.empty()) {
    s << " (bounded by cut" << (cuts.size() > 1 ? "s" : "");
    for (auto it = cuts.begin(); it != cuts.end(); ++it) s << (it == cuts.begin() ? " " : ", ") << *it;
    s << ")";
  }
  return s.str();
}

}  // namespace

std::size_t LayoutFace::nodes() const { return static_cast<std::size_t>(std::count(is_node.begin(), is_node.end(), 1)); }

std::vector<LayoutFace> layout_faces(const Domain& domain, const std::vector<Cut>& cuts,
                                     const std::vector<Eigen::Vector2d>& ring_corners) {
  std::vector<LayoutFace> out;
  for (auto& [f, ids] : faces_with_ids(domain, cuts, ring_corners)) out.push_back(std::move(f));
  return out;
}

namespace {

// Each cut: two or more finite points, none repeated, each end on a ring or at
// an end of another cut, and its first segment inside the domain.
void check_cut_points(const Domain& d, const std::vector<Cut>& cuts, double tol, RingEdgeGrid& ring_edges) {
  // The cuts' ends by cells of size tol (a match lies in one of the 3 x 3 cells around a point).
  auto end_cell = [&](const Eigen::Vector2d& p) {
    return std::pair<long long, long long>(static_cast<long long>(std::floor(p.x() / tol)),
                                           static_cast<long long>(std::floor(p.y() / tol)));
  };
  std::map<std::pair<long long, long long>, std::vector<std::pair<std::size_t, Eigen::Vector2d>>> end_cells;
  for (std::size_t c = 0; c < cuts.size(); ++c)
    if (!cuts[c].empty() && cuts[c].front().allFinite() && cuts[c].back().allFinite()) {
      end_cells[end_cell(cuts[c].front())].push_back({c, cuts[c].front()});
      end_cells[end_cell(cuts[c].back())].push_back({c, cuts[c].back()});
    }
  for (std::size_t c = 0; c < cuts.size(); ++c) {
    const std::string name = "cut " + std::to_string(c + 1);
    if (cuts[c].size() < 2) throw InputError(name + " has fewer than two points");
    for (const auto& p : cuts[c])
      if (!p.allFinite()) throw InputError(name + " has a non-finite coordinate");
    for (std::size_t k = 0; k + 1 < cuts[c].size(); ++k)
      if ((cuts[c][k + 1] - cuts[c][k]).norm() <= tol)
        throw InputError(name + " repeats its point " + fmt(cuts[c][k]));
    for (const Eigen::Vector2d& end : {cuts[c].front(), cuts[c].back()}) {
      bool at_cut_end = false;
      const auto [ci, cj] = end_cell(end);
      for (long long i = ci - 1; i <= ci + 1 && !at_cut_end; ++i)
        for (long long j = cj - 1; j <= cj + 1 && !at_cut_end; ++j) {
          auto it = end_cells.find({i, j});
          if (it == end_cells.end()) continue;
          for (const auto& [o, p] : it->second)
            if (o != c && (p - end).norm() <= tol) at_cut_end = true;
        }
      if (!at_cut_end && ring_edges.closest(end).distance > tol)
        throw InputError(name + ": its end " + fmt(end) + " lies neither on a ring nor at an end of another cut");
    }
    if (!domain_contains(d, 0.5 * (cuts[c][0] + cuts[c][1])))
      throw InputError(name + " runs outside the domain near " + fmt(0.5 * (cuts[c][0] + cuts[c][1])));
  }
}

void check_cuts_against_rings(const Domain& d, const std::vector<Cut>& cuts, double tol,
                              const RingEdgeGrid& ring_edges) {
  // Cut segments against ring edges: they may meet only at the cut's own ends.
  auto near_end = [&](const Cut& cut, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    for (const Eigen::Vector2d& e : {cut.front(), cut.back()})
      if ((a + project(e, a, b) * (b - a) - e).norm() <= tol) return true;
    return false;
  };
  // (The ring edges near each segment, in ring and edge order: the first
  // crossing found is the one a scan of every edge finds.)
  std::vector<int> near;
  for (std::size_t c = 0; c < cuts.size(); ++c) {
    for (std::size_t k = 0; k + 1 < cuts[c].size(); ++k) {
      const CSegment s(cpoint(cuts[c][k]), cpoint(cuts[c][k + 1]));
      const auto box = s.bbox();
      ring_edges.edges_near(cuts[c][k].cwiseMin(cuts[c][k + 1]), cuts[c][k].cwiseMax(cuts[c][k + 1]), near);
      for (const int e : near) {
        const std::size_t r = ring_edges.ring_of(e), i = ring_edges.index_of(e);
        {
          const auto& v = ring(d, r).vertices;
          const Eigen::Vector2d a = v[i], b = v[(i + 1) % v.size()];
          const CSegment t(cpoint(a), cpoint(b));
          if (!CGAL::do_overlap(box, t.bbox()) || !CGAL::do_intersect(s, t)) continue;
          const bool end_segment = k == 0 || k + 2 == cuts[c].size();
          // Allowed: the cut's end lies on this edge and the cut leaves it into the domain.
          if (end_segment && near_end(cuts[c], a, b)) {
            const Eigen::Vector2d other = (cuts[c].front() - a).norm() + (cuts[c].front() - b).norm() <=
                                                  (cuts[c].back() - a).norm() + (cuts[c].back() - b).norm()
                                              ? cuts[c][k + 1]
                                              : cuts[c][k];
            if (CGAL::orientation(t.source(), t.target(), cpoint(other)) != CGAL::COLLINEAR) continue;
          }
          const Polygon& p = ring(d, r);
          throw InputError("cut " + std::to_string(c + 1) + " crosses " + ring_name(r) + " (edge " +
                           std::to_string(p.file_index[i]) + "-" + std::to_string(p.file_index[(i + 1) % v.size()]) +
                           ") near " + fmt(0.5 * (a + b)) + " away from the cut's ends");
        }
      }
    }
  }
}

void check_cuts_against_cuts(const std::vector<Cut>& cuts, double tol) {
  // Cuts against cuts (and a cut against itself): they may share ends only.
  // Segments swept in order of their smallest x, each tested against the
  // active ones whose boxes overlap its own.
  struct Seg {
    std::size_t c, k;
    CGAL::Bbox_2 box;
  };
  std::vector<Seg> segs;
  for (std::size_t c = 0; c < cuts.size(); ++c)
    for (std::size_t k = 0; k + 1 < cuts[c].size(); ++k)
      segs.push_back({c, k, CSegment(cpoint(cuts[c][k]), cpoint(cuts[c][k + 1])).bbox()});
  std::sort(segs.begin(), segs.end(), [](const Seg& a, const Seg& b) { return a.box.xmin() < b.box.xmin(); });
  std::vector<std::size_t> active;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    std::erase_if(active, [&](std::size_t j) { return segs[j].box.xmax() < segs[i].box.xmin() - tol; });
    for (std::size_t j : active) {
      const Seg &x = segs[i], &y = segs[j];
      if (!CGAL::do_overlap(x.box + CGAL::Bbox_2(x.box.xmin() - tol, x.box.ymin() - tol, x.box.xmax() + tol,
                                                  x.box.ymax() + tol), y.box))
        continue;
      // Order as the old double loop did: (c, k) before (o, l).
      const bool first = x.c < y.c || (x.c == y.c && x.k < y.k);
      const std::size_t c = first ? x.c : y.c, k = first ? x.k : y.k, o = first ? y.c : x.c, l = first ? y.k : x.k;
      const CSegment s(cpoint(cuts[c][k]), cpoint(cuts[c][k + 1]));
      const CSegment t(cpoint(cuts[o][l]), cpoint(cuts[o][l + 1]));
      if (!CGAL::do_intersect(s, t)) continue;
      // Shared points allowed: consecutive segments of one cut, and common ends of two cuts.
      std::vector<Eigen::Vector2d> shared;
      if (o == c && l == k + 1) shared.push_back(cuts[c][k + 1]);
      if (o != c && k == 0) shared.push_back(cuts[c].front());
      if (o != c && k + 2 == cuts[c].size()) shared.push_back(cuts[c].back());
      bool allowed = false;
      for (const auto& e : shared) {
        const auto hit = CGAL::intersection(s, t);
        const CPoint* q = hit ? boost::get<CPoint>(&*hit) : nullptr;
        if (q && (Eigen::Vector2d(q->x(), q->y()) - e).norm() <= tol) allowed = true;
      }
      if (allowed) continue;
      const Eigen::Vector2d at = 0.5 * (cuts[c][k] + cuts[c][k + 1]);
      if (o == c) throw InputError("cut " + std::to_string(c + 1) + " crosses itself near " + fmt(at));
      throw InputError("cuts " + std::to_string(c + 1) + " and " + std::to_string(o + 1) + " cross near " + fmt(at) +
                       " (cuts may meet only at their ends)");
    }
    active.push_back(i);
  }
}

}  // namespace

void validate_cuts(const Domain& d, const std::vector<Cut>& cuts) {
  const double tol = snap_tolerance(d);
  RingEdgeGrid ring_edges(d);
  check_cut_points(d, cuts, tol, ring_edges);
  check_cuts_against_rings(d, cuts, tol, ring_edges);
  check_cuts_against_cuts(cuts, tol);
}

namespace {

// The patch of face f of the layout (ids: its vertices in the graph, for the
// simplicity check): its cut ends are its corners, completed to four by its
// sharpest convex ring vertices.
Patch patch_of_face(const LayoutFace& f, const std::vector<int>& ids) {
  const std::size_t n = f.points.size();
  double area2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) area2 += cross(f.points[i], f.points[(i + 1) % n]);
  if (!(area2 > 0.0))
    throw InputError("a ring near " + fmt(f.points.front()) +
                     " is not connected to the others by cuts: every hole needs at least two cuts");
  std::vector<int> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw InputError(face_name(f) + " is not simply connected or touches itself: every hole needs at least "
                                    "two cuts, and cuts must split the domain into simple four-sided patches");
  std::vector<std::size_t> corners;
  for (std::size_t i = 0; i < n; ++i)
    if (f.is_node[i]) corners.push_back(i);
  if (corners.size() > 4)
    throw InputError(face_name(f) + " has " + std::to_string(corners.size()) +
                     " cut ends on its boundary; a four-sided patch can have at most four (its corners)");
  // Missing corners: the sharpest convex ring vertices.
  if (corners.size() < 4) {
    std::vector<std::pair<double, std::size_t>> cand;
    for (std::size_t i = 0; i < n; ++i)
      if (!f.is_node[i]) cand.push_back({inner_angle(f.points, i), i});
    std::sort(cand.begin(), cand.end());
    for (const auto& [angle, i] : cand) {
      if (corners.size() == 4 || angle >= std::numbers::pi * (1.0 - 1e-9)) break;
      corners.push_back(i);
    }
    if (corners.size() < 4)
      throw InputError(face_name(f) + " has only " + std::to_string(corners.size()) +
                       " corners (cut ends and convex vertices): add cuts");
    std::sort(corners.begin(), corners.end());
  }
  Patch p;
  p.polygon.vertices = f.points;
  p.polygon.file_index.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.polygon.file_index[i] = i;
  for (int k = 0; k < 4; ++k) {
    p.corners[k] = corners[k];
    // Side k is a cut if its first edge is one (every cut end is a corner).
    p.side_cut[k] = f.edge_cut[corners[k]];
  }
  return p;
}

// One interface per cut: the two patch sides it is.
std::vector<Interface> interfaces_of(const std::vector<Patch>& patches, std::size_t cuts) {
  std::vector<std::vector<std::pair<std::size_t, int>>> sides_of(cuts);
  for (std::size_t q = 0; q < patches.size(); ++q)
    for (int k = 0; k < 4; ++k)
      if (patches[q].side_cut[k] >= 0) sides_of[patches[q].side_cut[k]].push_back({q, k});
  std::vector<Interface> out;
  for (std::size_t c = 0; c < cuts; ++c) {
    const auto& sides = sides_of[c];
    if (sides.size() != 2) throw InputError("cut " + std::to_string(c + 1) + " is not the side of two patches");
    out.push_back({c, sides[0].first, sides[1].first, sides[0].second, sides[1].second});
  }
  return out;
}

}  // namespace

PatchLayout build_patch_layout(const Domain& d, std::vector<Cut> cuts, const std::vector<Eigen::Vector2d>& ring_corners) {
  validate_cuts(d, cuts);
  RingEdgeGrid ring_edges(d);
  for (const Eigen::Vector2d& p : ring_corners)
    if (!p.allFinite() || ring_edges.closest(p).distance > snap_tolerance(d))
      throw InputError("the patch corner " + fmt(p) + " does not lie on a ring");
  PatchLayout L;
  L.cuts = std::move(cuts);
  for (auto& [f, ids] : faces_with_ids(d, L.cuts, ring_corners)) L.patches.push_back(patch_of_face(f, ids));
  L.interfaces = interfaces_of(L.patches, L.cuts.size());
  return L;
}

}  // namespace tspline

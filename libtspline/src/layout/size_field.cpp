#include "tspline/layout/size_field.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <list>

#include "tspline/layout/ring_nodes.h"

namespace tspline {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct SampleInfo {
  int ring = -1;
  double arc = 0.0;
  int sample = -1;
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<SampleInfo, K>;
using Fbb = CGAL::Triangulation_face_base_with_info_2<int, K>;  // nesting level
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbb>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

// Nesting level of every face: 0 outside, +1 across each constraint (the
// faces of odd level are inside the domain). The breadth-first walk of CGAL's
// polygon-with-holes examples.
void mark_levels(CDT& cdt) {
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
  std::list<std::pair<CDT::Face_handle, int>> border = {{cdt.infinite_face(), 0}};
  while (!border.empty()) {
    auto [start, level] = border.front();
    border.pop_front();
    if (start->info() != -1) continue;
    std::list<CDT::Face_handle> queue = {start};
    start->info() = level;
    while (!queue.empty()) {
      CDT::Face_handle f = queue.front();
      queue.pop_front();
      for (int i = 0; i < 3; ++i) {
        CDT::Face_handle n = f->neighbor(i);
        if (n->info() != -1) continue;
        if (cdt.is_constrained({f, i})) border.push_back({n, level + 1});
        else {
          n->info() = level;
          queue.push_back(n);
        }
      }
    }
  }
}

// Samples of the rings: the vertices, and points on long edges so that no gap
// exceeds `spacing`; inserted in `cdt` with the rings as constraints.
struct RingSamples {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> ring_length;
};

RingSamples sample_rings(const Domain& d, double spacing, CDT& cdt) {
  std::vector<const Polygon*> rings = {&d.outer};
  for (const Polygon& h : d.holes) rings.push_back(&h);
  RingSamples out;
  for (std::size_t r = 0; r < rings.size(); ++r) {
    const RingCurve ring(rings[r]->vertices);
    out.ring_length.push_back(ring.length());
    std::vector<CDT::Vertex_handle> handles;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Eigen::Vector2d a = ring.vertex(i), b = ring.vertex(i + 1);
      const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
      for (int k = 0; k < pieces; ++k) {
        const double t = static_cast<double>(k) / pieces;
        const Eigen::Vector2d p = a + t * (b - a);
        CDT::Vertex_handle vh = cdt.insert(K::Point_2(p.x(), p.y()));
        if (vh->info().sample < 0) {
          vh->info() = {static_cast<int>(r), ring.arc(i) + t * (b - a).norm(), static_cast<int>(out.points.size())};
          out.points.push_back(p);
        }
        handles.push_back(vh);
      }
    }
    for (std::size_t k = 0; k < handles.size(); ++k)
      if (handles[k] != handles[(k + 1) % handles.size()])
        cdt.insert_constraint(handles[k], handles[(k + 1) % handles.size()]);
  }
  return out;
}

// The local width at each sample: its shortest edge inside the domain to a
// sample "across" (on another ring, or on its own ring more than across_ratio
// times the edge's length away along the ring); infinite where none is.
struct LocalWidths {
  std::vector<double> width;
  std::vector<char> between_rings;  // the width is a gap to another ring
};

LocalWidths local_widths(const CDT& cdt, const RingSamples& samples, double across_ratio) {
  LocalWidths w{std::vector<double>(samples.points.size(), std::numeric_limits<double>::infinity()),
                std::vector<char>(samples.points.size(), 0)};
  for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e) {
    CDT::Face_handle f = e->first, g = f->neighbor(e->second);
    const bool inside = (f->info() % 2 == 1 && !cdt.is_infinite(f)) || (g->info() % 2 == 1 && !cdt.is_infinite(g));
    if (!inside || cdt.is_constrained(*e)) continue;
    const SampleInfo a = f->vertex(CDT::cw(e->second))->info(), b = f->vertex(CDT::ccw(e->second))->info();
    if (a.sample < 0 || b.sample < 0) continue;
    const double dist = (samples.points[a.sample] - samples.points[b.sample]).norm();
    bool across = a.ring != b.ring;
    if (!across) {
      const double L = samples.ring_length[a.ring];
      double arc = std::abs(a.arc - b.arc);
      arc = std::min(arc, L - arc);
      across = arc > across_ratio * dist;
    }
    if (!across) continue;
    for (const int k : {a.sample, b.sample})
      if (dist < w.width[k]) w.width[k] = dist, w.between_rings[k] = a.ring != b.ring;
  }
  return w;
}

// Grading of a grid of node values: two chamfer passes make
// h(node) <= h(neighbour) + g |node - neighbour| over the 8 neighbours.
template <class At>
void chamfer(At& at, int nx, int ny, double g, double cell) {
  const double a1 = g * cell, a2 = g * cell * std::sqrt(2.0);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      double& v = at(i, j);
      if (i > 0) v = std::min(v, at(i - 1, j) + a1);
      if (j > 0) {
        v = std::min(v, at(i, j - 1) + a1);
        if (i > 0) v = std::min(v, at(i - 1, j - 1) + a2);
        if (i < nx) v = std::min(v, at(i + 1, j - 1) + a2);
      }
    }
  for (int j = ny; j >= 0; --j)
    for (int i = nx; i >= 0; --i) {
      double& v = at(i, j);
      if (i < nx) v = std::min(v, at(i + 1, j) + a1);
      if (j < ny) {
        v = std::min(v, at(i, j + 1) + a1);
        if (i < nx) v = std::min(v, at(i + 1, j + 1) + a2);
        if (i > 0) v = std::min(v, at(i - 1, j + 1) + a2);
      }
    }
}

}  // namespace

SizeField::SizeField(const Domain& d, const SizeFieldOptions& o) {
  Eigen::Vector2d lo = d.outer.vertices.front(), hi = lo;
  for (const auto& v : d.outer.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double diag = (hi - lo).norm();
  max_size_ = o.max_size > 0.0 ? o.max_size : 0.125 * diag;
  min_size_ = std::min(o.min_size, max_size_);
  CDT cdt;
  const RingSamples samples = sample_rings(d, diag / 400.0, cdt);
  mark_levels(cdt);
  const LocalWidths w = local_widths(cdt, samples, o.across_ratio);
  min_width_ = std::numeric_limits<double>::infinity();
  for (double x : w.width) min_width_ = std::min(min_width_, x);

  // Background grid over the bounding box, one cell of margin.
  const int n = std::max(o.grid_cells, 8);
  cell_ = std::max((hi - lo).maxCoeff(), 1e-300) / n;
  lo_ = lo - Eigen::Vector2d::Constant(cell_);
  nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell_)) + 2;
  ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell_)) + 2;
  h_.assign(static_cast<std::size_t>(nx_ + 1) * (ny_ + 1), max_size_);
  auto at = [&](int i, int j) -> double& { return h_[static_cast<std::size_t>(j) * (nx_ + 1) + i]; };
  for (std::size_t s = 0; s < samples.points.size(); ++s) {
    if (!std::isfinite(w.width[s])) continue;
    // A gap between two rings is always resolved (two islands must not share a
    // patch side); min_size only spares the narrow places of one ring.
    const double floor = w.between_rings[s] ? 0.0 : min_size_;
    const double v = std::clamp(o.factor * w.width[s], floor, max_size_);
    const Eigen::Vector2d& x = samples.points[s];
    const int i = std::clamp(static_cast<int>((x.x() - lo_.x()) / cell_), 0, nx_ - 1);
    const int j = std::clamp(static_cast<int>((x.y() - lo_.y()) / cell_), 0, ny_ - 1);
    for (int di = 0; di <= 1; ++di)
      for (int dj = 0; dj <= 1; ++dj) {
        const Eigen::Vector2d node = lo_ + cell_ * Eigen::Vector2d(i + di, j + dj);
        at(i + di, j + dj) = std::min(at(i + di, j + dj), v + o.grading * (node - x).norm());
      }
  }
  chamfer(at, nx_, ny_, o.grading, cell_);
}

double SizeField::operator()(const Eigen::Vector2d& x) const {
  const Eigen::Vector2d q = (x - lo_) / cell_;
  const double fx = std::clamp(q.x(), 0.0, static_cast<double>(nx_) - 1e-9);
  const double fy = std::clamp(q.y(), 0.0, static_cast<double>(ny_) - 1e-9);
  const int i = static_cast<int>(fx), j = static_cast<int>(fy);
  const double s = fx - i, t = fy - j;
  auto at = [&](int a, int b) { return h_[static_cast<std::size_t>(b) * (nx_ + 1) + a]; };
  const double v = (1 - s) * (1 - t) * at(i, j) + s * (1 - t) * at(i + 1, j) + (1 - s) * t * at(i, j + 1) +
                   s * t * at(i + 1, j + 1);
  return std::min(v, max_size_);
}

}  // namespace tspline

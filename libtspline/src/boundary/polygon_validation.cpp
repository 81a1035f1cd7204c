// Validation of input polygons with CGAL's exact predicates (Epick: inexact
// constructions, but orientation / do_intersect / collinearity are exact).
#include "tspline/boundary/polygon_validation.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "tspline/errors.h"
#include "tspline/boundary/plane.h"

namespace tspline {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_2;
using Segment = K::Segment_2;
// One box per edge; the info is the edge index i (edge i joins vertex i and i+1 mod n).
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 2, std::size_t>;

std::string fmt_point(double x, double y) {
  std::ostringstream os;
  os.precision(10);
  os << '(' << x << ", " << y << ')';
  return os.str();
}

struct Crossing {
  std::size_t e1 = 0, e2 = 0;  // e1 < e2, polygon (not file) edge indices
  Point where;
  bool overlap = false;  // collinear overlap rather than a proper crossing/touch
};

// Exact test of two polygon edges found by the box filter. Adjacent edges must
// only share their common vertex: they conflict iff the three points are collinear
// and the shared vertex is not between the two others (the edges fold back).
// Non-adjacent edges must not meet at all.
bool edges_conflict(const std::vector<Point>& pts, std::size_t i, std::size_t j, Crossing& out) {
  const std::size_t n = pts.size();
  if (i > j) std::swap(i, j);
  out.e1 = i;
  out.e2 = j;
  const bool j_follows_i = (j == i + 1);
  const bool i_follows_j = (i == 0 && j == n - 1);
  if (j_follows_i || i_follows_j) {
    // Shared vertex b; the other ends a (before b) and c (after b).
    const std::size_t b = j_follows_i ? j : 0;
    const Point& a = pts[(b + n - 1) % n];
    const Point& c = pts[(b + 1) % n];
    if (CGAL::collinear(a, pts[b], c) && !CGAL::collinear_are_ordered_along_line(a, pts[b], c)) {
      out.overlap = true;
      // The overlap runs from b to whichever of a, c is closer to b.
      out.where = CGAL::has_smaller_distance_to_point(pts[b], a, c) ? a : c;
      return true;
    }
    return false;
  }
  const Segment s1(pts[i], pts[(i + 1) % n]);
  const Segment s2(pts[j], pts[(j + 1) % n]);
  if (!CGAL::do_intersect(s1, s2)) return false;
  // The location is only for the message, so an inexact construction is fine.
  const Point &a = s1.source(), &b = s1.target(), &c = s2.source(), &d = s2.target();
  if (CGAL::collinear(a, b, c) && CGAL::collinear(a, b, d)) {
    out.overlap = true;  // collinear segments that meet: report an end lying on the other
    out.where = s1.has_on(c) ? c : s1.has_on(d) ? d : a;
  } else {
    // Solve a + t (b - a) = c + u (d - c) for t by Cramer's rule.
    const double rx = b.x() - a.x(), ry = b.y() - a.y(), sx = d.x() - c.x(), sy = d.y() - c.y();
    const double den = rx * sy - ry * sx;
    const double t = den != 0.0 ? ((c.x() - a.x()) * sy - (c.y() - a.y()) * sx) / den : 0.0;
    out.where = Point(a.x() + t * rx, a.y() + t * ry);
  }
  return true;
}

}  // namespace

void check_polygon_scale(const Polygon& p) {
  if (p.vertices.empty()) return;
  const auto& fi = p.file_index;
  Eigen::Vector2d lo = p.vertices.front(), hi = lo;
  std::size_t far = 0;
  for (std::size_t i = 0; i < p.vertices.size(); ++i) {
    const Eigen::Vector2d& v = p.vertices[i];
    lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    if (v.cwiseAbs().maxCoeff() > p.vertices[far].cwiseAbs().maxCoeff()) far = i;
  }
  const Eigen::Vector2d& v = p.vertices[far];
  if (v.cwiseAbs().maxCoeff() > kMaxPolygonCoordinate) {
    std::ostringstream s;
    s << "vertex " << (fi.empty() ? far : fi[far]) << " " << fmt_point(v.x(), v.y())
      << " is too far from the origin: coordinates must lie within +-" << kMaxPolygonCoordinate
      << " (lengths are squared in areas and Jacobian determinants, which would overflow); rescale the "
         "coordinates (e.g. to km) or shift them nearer the origin";
    throw InputError(s.str());
  }
  // Extent: the larger side of the bounding box (exact, no squares).
  const double extent = (hi - lo).maxCoeff();
  if (extent < kMinPolygonExtent) {
    std::ostringstream s;
    s << "polygon is too small: its bounding box is " << (hi - lo).x() << " x " << (hi - lo).y()
      << ", below the smallest supported extent " << kMinPolygonExtent
      << " (areas and Jacobian determinants would underflow); rescale the coordinates (e.g. to mm or um)";
    throw InputError(s.str());
  }
}

double signed_area(const Polygon& p) { return signed_area(p.vertices); }

namespace {

// File indices (0..n-1 where the polygon has none), enough vertices, finite coordinates.
void check_vertices(Polygon& p, std::size_t min_vertices) {
  const std::size_t n = p.vertices.size();
  if (p.file_index.empty()) {
    p.file_index.resize(n);
    for (std::size_t i = 0; i < n; ++i) p.file_index[i] = i;
  } else if (p.file_index.size() != n) {
    throw toolkit::InputError("validate_polygon: file_index has " + std::to_string(p.file_index.size()) +
                              " entries for " + std::to_string(n) + " vertices");
  }
  if (n < std::max<std::size_t>(min_vertices, 3)) {
    throw InputError("polygon has " + std::to_string(n) + " vertices; at least " +
                     std::to_string(std::max<std::size_t>(min_vertices, 3)) + " are needed");
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& v = p.vertices[i];
    if (!std::isfinite(v.x()) || !std::isfinite(v.y())) {
      throw InputError("vertex " + std::to_string(p.file_index[i]) + " has a non-finite coordinate " +
                       fmt_point(v.x(), v.y()));
    }
  }
}

void check_no_repeated_neighbours(const Polygon& p) {
  const std::size_t n = p.vertices.size();
  const auto& fi = p.file_index;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    if (p.vertices[i] == p.vertices[j]) {
      throw InputError("vertices " + std::to_string(fi[i]) + " and " + std::to_string(fi[j]) + " are equal " +
                       fmt_point(p.vertices[i].x(), p.vertices[i].y()) + "; remove the duplicate");
    }
  }
}

// Positive area and no two edges meeting but neighbours at their shared
// vertex, by exact predicates.
void check_simple(const std::vector<Point>& pts, const std::vector<std::size_t>& fi) {
  const std::size_t n = pts.size();
  // Zero area (exact): every vertex collinear with the first two distinct ones.
  bool all_collinear = true;
  for (std::size_t i = 2; i < n && all_collinear; ++i)
    all_collinear = CGAL::collinear(pts[0], pts[1], pts[i]);
  if (all_collinear) throw InputError("polygon has zero area (all vertices are collinear)");

  // Candidate edge pairs from overlapping bounding boxes (O(n log n + k)), then
  // exact tests. Keep the pair with the smallest indices so the report is
  // deterministic whatever order the box algorithm reports pairs in.
  std::vector<Box> boxes;
  boxes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) boxes.emplace_back(pts[i].bbox() + pts[(i + 1) % n].bbox(), i);
  bool found = false;
  std::size_t n_conflicts = 0;
  Crossing first;
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& a, const Box& b) {
    Crossing c;
    if (!edges_conflict(pts, a.info(), b.info(), c)) return;
    ++n_conflicts;
    if (!found || std::pair(c.e1, c.e2) < std::pair(first.e1, first.e2)) first = c;
    found = true;
  });
  if (found) {
    auto edge = [&](std::size_t e) { return std::to_string(fi[e]) + "-" + std::to_string(fi[(e + 1) % n]); };
    std::string msg = "polygon is not simple: edges " + edge(first.e1) + " and " + edge(first.e2) +
                      (first.overlap ? " overlap near " : " intersect near ") +
                      fmt_point(first.where.x(), first.where.y());
    if (n_conflicts > 1) msg += " (" + std::to_string(n_conflicts - 1) + " more conflicting edge pair(s))";
    msg += "; the domain must be bounded by one simple closed polygon: fix the vertices there (check the "
           "vertex order, duplicated or stray points)";
    throw InputError(msg);
  }
}

// The polygon counter-clockwise (reversed, file indices too, if it was not).
// \pre simple (check_simple).
void orient_counter_clockwise(Polygon& p, const std::vector<Point>& pts) {
  const std::size_t n = pts.size();
  // Orientation, exactly: the lexicographically smallest vertex of a simple
  // polygon is convex, and its neighbours are not collinear with it (they would
  // lie on the same ray from it, i.e. the edges would overlap, excluded above).
  const std::size_t m =
      static_cast<std::size_t>(std::min_element(pts.begin(), pts.end(),
                                                [](const Point& a, const Point& b) {
                                                  return CGAL::compare_xy(a, b) == CGAL::SMALLER;
                                                }) -
                               pts.begin());
  const auto o = CGAL::orientation(pts[(m + n - 1) % n], pts[m], pts[(m + 1) % n]);
  if (o == CGAL::CLOCKWISE) {
    std::reverse(p.vertices.begin(), p.vertices.end());
    std::reverse(p.file_index.begin(), p.file_index.end());
  }
}

}  // namespace

Polygon validate_polygon(Polygon p, std::size_t min_vertices) {
  check_vertices(p, min_vertices);
  check_polygon_scale(p);
  check_no_repeated_neighbours(p);
  std::vector<Point> pts;
  pts.reserve(p.vertices.size());
  for (const auto& v : p.vertices) pts.emplace_back(v.x(), v.y());
  check_simple(pts, p.file_index);
  orient_counter_clockwise(p, pts);
  return p;
}

double bounding_box_diagonal(const Polygon& p) {
  if (p.vertices.empty()) return 0.0;
  Eigen::Vector2d lo = p.vertices.front(), hi = lo;
  for (const auto& v : p.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return (hi - lo).norm();
}

double needle_width_for_tolerance(double tolerance_area, double diagonal) {
  if (!(diagonal > 0.0) || !std::isfinite(diagonal) || !(tolerance_area > 0.0) || !std::isfinite(tolerance_area))
    return 0.0;
  return tolerance_area / diagonal;
}

namespace {

std::string three_digits(double x) {
  std::ostringstream os;
  os.precision(3);
  os << x;
  return os.str();
}

// The passes of clean_polygon over one ring (finite vertices, file indices set).
//
// One pass goes over a stack: a vertex is dropped if it repeats the previous
// one, or if it is the tip of a needle between the previous kept vertex and
// the next one (a zero-area spike: the two edges on one line, doubling back;
// or the two edges folding back within needle_width of each other). Dropping
// a vertex can expose the next needle (a -> b -> a -> ..., or a needle drawn
// with several vertices out and back), which the stack handles.
class NeedleRemoval {
 public:
  NeedleRemoval(const Polygon& p, double needle_width) : p_(p), needle_width_(needle_width) {}

  PolygonCleaning run() {
    std::vector<std::size_t> order(p_.vertices.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    // Repeat, rotating the ring between passes so that the triples across each
    // pass's seam (the last, first and second vertex) are inside the next pass,
    // until passes have found nothing three times in a row (a 3-vertex ring needs
    // three rotations to look at each of its triples; a longer ring, two passes).
    int quiet_passes = 0;
    while (quiet_passes < 3 && order.size() >= 3) {
      const bool changed = pass(order);
      // Rotate so that the seam between the last and first vertex is looked at too.
      if (keep_.size() >= 3)
        std::rotate(keep_.begin(), keep_.begin() + static_cast<std::ptrdiff_t>(keep_.size() / 2), keep_.end());
      order = keep_;
      quiet_passes = changed ? 0 : quiet_passes + 1;
    }
    std::sort(order.begin(), order.end());  // file order
    Polygon q;
    for (std::size_t i : order) q.vertices.push_back(p_.vertices[i]), q.file_index.push_back(p_.file_index[i]);
    std::sort(out_.removed_file_indices.begin(), out_.removed_file_indices.end());
    out_.polygon = std::move(q);
    return std::move(out_);
  }

 private:
  // One pass over `order` into keep_; whether it dropped anything.
  bool pass(const std::vector<std::size_t>& order) {
    changed_ = false;
    keep_.clear();
    for (std::size_t i : order) {
      if (repeats(i, false)) continue;
      double width = 0.0;
      bool tip = false;
      while (keep_.size() >= 2 && (width = needle(keep_[keep_.size() - 2], keep_.back(), i)) >= 0.0) {
        drop_tip(i, width);
        tip = true;
        if (!keep_.empty() && (p_.vertices[keep_.back()] - p_.vertices[i]).norm() <= needle_width_) break;
      }
      if (repeats(i, tip)) continue;
      keep_.push_back(i);
    }
    return changed_;
  }

  // The width of the needle with tip b (< 0: b is no needle's tip). Exactly
  // collinear fold-backs (exact predicates) have width 0.
  double needle(std::size_t a, std::size_t b, std::size_t c) const {
    const Point pa(p_.vertices[a].x(), p_.vertices[a].y()), pb(p_.vertices[b].x(), p_.vertices[b].y()),
        pc(p_.vertices[c].x(), p_.vertices[c].y());
    if (CGAL::collinear(pa, pb, pc)) return CGAL::collinear_are_ordered_along_line(pa, pb, pc) ? -1.0 : 0.0;
    if (needle_width_ == 0.0) return -1.0;
    // The edges b->a and b->c fold back (angle below 90 degrees); the width is the
    // distance of the nearer neighbour from the line of the longer edge, whose
    // foot lies on that edge.
    const Eigen::Vector2d u = p_.vertices[a] - p_.vertices[b], v = p_.vertices[c] - p_.vertices[b];
    if (!(u.dot(v) > 0.0)) return -1.0;
    const double longer = std::max(u.norm(), v.norm());
    const double width = std::abs(u.x() * v.y() - u.y() * v.x()) / longer;
    return width <= needle_width_ ? width : -1.0;
  }

  // The last kept vertex is the tip of a needle of `width` before vertex i: it goes.
  void drop_tip(std::size_t i, double width) {
    const std::string a = std::to_string(p_.file_index[keep_[keep_.size() - 2]]),
                      b = std::to_string(p_.file_index[keep_.back()]), c = std::to_string(p_.file_index[i]);
    if (width == 0.0)
      note(keep_.back(), "(tip of a zero-area spike: edges " + a + "-" + b + " and " + b + "-" + c + " overlap)");
    else
      note(keep_.back(), "(tip of a needle of width " + three_digits(width) + ", narrower than " +
                             three_digits(needle_width_) + ": edges " + a + "-" + b + " and " + b + "-" + c +
                             " fold back)");
    ++out_.needles;
    out_.max_needle_width = std::max(out_.max_needle_width, width);
    keep_.pop_back();
    changed_ = true;
  }

  // Whether vertex i repeats the last kept vertex; if so, the one later in the
  // file goes (the closing vertex of a file that repeats its first one, say).
  // Where a needle's tip has just gone, a vertex within needle_width of the
  // last kept one repeats it too (the two base vertices of a needle, or the
  // flat end of a needle drawn with two tip vertices): the change is a triangle
  // of height at most needle_width. Elsewhere short edges are kept.
  bool repeats(std::size_t i, bool after_tip) {
    if (keep_.empty()) return false;
    const bool exact = p_.vertices[keep_.back()] == p_.vertices[i];
    const double gap = (p_.vertices[keep_.back()] - p_.vertices[i]).norm();
    if (!exact && !(after_tip && needle_width_ > 0.0 && gap <= needle_width_)) return false;
    changed_ = true;
    const bool drop_last = p_.file_index[i] < p_.file_index[keep_.back()];
    const std::size_t dropped = drop_last ? keep_.back() : i, kept = drop_last ? i : keep_.back();
    note(dropped, exact ? "(repeats vertex " + std::to_string(p_.file_index[kept]) + ")"
                        : "(lies " + three_digits(gap) + " from vertex " + std::to_string(p_.file_index[kept]) +
                              ", closer than the needle width " + three_digits(needle_width_) + ")");
    if (drop_last) keep_.back() = i;
    return true;
  }

  void note(std::size_t dropped, const std::string& why) {
    out_.removed_file_indices.push_back(p_.file_index[dropped]);
    out_.notes.push_back("removed vertex " + std::to_string(p_.file_index[dropped]) + " " + why);
  }

  const Polygon& p_;
  const double needle_width_;
  PolygonCleaning out_;
  std::vector<std::size_t> keep_;  // the vertices kept so far in this pass (indices into p_)
  bool changed_ = false;           // whether this pass dropped a vertex
};

}  // namespace

PolygonCleaning clean_polygon(Polygon p, double needle_width) {
  if (!(needle_width >= 0.0) || !std::isfinite(needle_width))
    throw toolkit::InputError("clean_polygon: the needle width must be finite and >= 0");
  if (p.file_index.empty()) {
    p.file_index.resize(p.vertices.size());
    for (std::size_t i = 0; i < p.vertices.size(); ++i) p.file_index[i] = i;
  }
  for (const auto& v : p.vertices)
    if (!std::isfinite(v.x()) || !std::isfinite(v.y())) {
      PolygonCleaning out;
      out.polygon = std::move(p);  // validate_polygon names the vertex
      return out;
    }
  return NeedleRemoval(p, needle_width).run();
}

double needle_width_for_ring(const Polygon& p, std::optional<double> tolerance_absolute, double tolerance_relative) {
  auto width_at = [&](double d) {
    return needle_width_for_tolerance(tolerance_absolute ? *tolerance_absolute : tolerance_relative * d * d, d);
  };
  double d = bounding_box_diagonal(p);
  double w = width_at(d);
  // At most a few rounds: each one only looks at a smaller diagonal.
  for (int round = 0; round < 8 && w > 0.0; ++round) {
    const PolygonCleaning c = clean_polygon(p, w);
    const double dc = c.polygon.vertices.size() >= 3 ? bounding_box_diagonal(c.polygon) : 0.0;
    if (dc >= 0.5 * d) return w;
    d = dc;
    w = width_at(d);
  }
  return w > 0.0 && std::isfinite(w) ? w : 0.0;
}

Polygon validate_cleaned_polygon(PolygonCleaning c, double needle_width, std::size_t min_vertices) {
  const std::size_t left = c.polygon.vertices.size();
  if (c.needles > 0 && left < std::max<std::size_t>(min_vertices, 3)) {
    std::ostringstream m;
    m.precision(3);
    m << "the ring encloses no area: it is nothing but ";
    if (needle_width > 0.0) m << "needles narrower than " << needle_width;
    else m << "zero-area spikes";
    m << " (" << left << " of its " << left + c.removed_file_indices.size()
      << " vertices are left once they are removed)";
    throw InputError(m.str());
  }
  return validate_polygon(std::move(c.polygon), min_vertices);
}

std::string cleaning_summary(const std::string& ring, const PolygonCleaning& c) {
  if (c.notes.empty()) return {};
  constexpr std::size_t kShown = 4;
  std::string s = ring + ": ";
  for (std::size_t k = 0; k < c.notes.size() && k < kShown; ++k) s += (k ? "; " : "") + c.notes[k];
  if (c.notes.size() > kShown) s += "; and " + std::to_string(c.notes.size() - kShown) + " more vertices";
  return s;
}

}  // namespace tspline

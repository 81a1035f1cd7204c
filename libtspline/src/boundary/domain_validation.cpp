// Validation of a domain with holes: each ring by validate_polygon, then the
// rings against each other with CGAL's exact predicates (Epick).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/convex_hull_2.h>

#include <cctype>
#include <cmath>
#include <iterator>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/errors.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/boundary/sharp_tips.h"

namespace tspline {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_2;
using Segment = K::Segment_2;
// One box per edge; the info is (ring, edge index in that ring).
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 2, std::pair<std::size_t, std::size_t>>;

const Polygon& ring(const Domain& d, std::size_t r) { return r == 0 ? d.outer : d.holes[r - 1]; }

Point point(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }

Segment edge(const Polygon& p, std::size_t e) {
  return {point(p.vertices[e]), point(p.vertices[(e + 1) % p.vertices.size()])};
}

std::string edge_name(const Polygon& p, std::size_t e) {
  const std::size_t n = p.vertices.size();
  return std::to_string(p.file_index[e]) + "-" + std::to_string(p.file_index[(e + 1) % n]);
}

CGAL::Bounded_side side_of(const Polygon& p, const Eigen::Vector2d& x) {
  std::vector<Point> pts;
  pts.reserve(p.vertices.size());
  for (const auto& v : p.vertices) pts.push_back(point(v));
  return CGAL::bounded_side_2(pts.begin(), pts.end(), point(x), K());
}

// The first pair of edges of two different rings that intersect (cross,
// touch or overlap), found by box intersection in O(n log n + k).
// number[r]: ring r's number in the file (holes dropped in cleaning leave gaps).
void check_rings_disjoint(const Domain& d, const std::vector<std::size_t>& number) {
  std::vector<Box> boxes;
  const std::size_t rings = d.holes.size() + 1;
  for (std::size_t r = 0; r < rings; ++r) {
    const Polygon& p = ring(d, r);
    for (std::size_t e = 0; e < p.vertices.size(); ++e) boxes.emplace_back(edge(p, e).bbox(), std::make_pair(r, e));
  }
  struct Hit {
    bool found = false;
    std::pair<std::size_t, std::size_t> a, b;
  } hit;
  auto report = [&](const Box& x, const Box& y) {
    if (x.info().first == y.info().first) return;  // within a ring: validate_polygon's job
    const Segment s = edge(ring(d, x.info().first), x.info().second);
    const Segment t = edge(ring(d, y.info().first), y.info().second);
    if (!CGAL::do_intersect(s, t)) return;
    auto a = x.info(), b = y.info();
    if (a > b) std::swap(a, b);
    if (!hit.found || std::make_pair(a, b) < std::make_pair(hit.a, hit.b)) hit = {true, a, b};
  };
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), report);
  if (!hit.found) return;
  const Polygon& pa = ring(d, hit.a.first);
  const Polygon& pb = ring(d, hit.b.first);
  const Segment s = edge(pa, hit.a.second), t = edge(pb, hit.b.second);
  const auto where = CGAL::intersection(s, t);
  Point at = s.source();
  if (where) {
    if (const Point* q = boost::get<Point>(&*where)) at = *q;
    else if (const Segment* q = boost::get<Segment>(&*where)) at = q->source();
  }
  // Crossing if each segment has endpoints strictly on both sides of the
  // other; otherwise an endpoint lies on the other ring (touching).
  const bool proper = CGAL::orientation(s.source(), s.target(), t.source()) *
                              CGAL::orientation(s.source(), s.target(), t.target()) < 0 &&
                      CGAL::orientation(t.source(), t.target(), s.source()) *
                              CGAL::orientation(t.source(), t.target(), s.target()) < 0;
  std::ostringstream m;
  m.precision(10);
  const std::string na = ring_name(number[hit.a.first]), nb = ring_name(number[hit.b.first]);
  m << nb << (proper ? " crosses " : " touches ") << na << ": edge " << edge_name(pb, hit.b.second) << " of " << nb
    << " and edge " << edge_name(pa, hit.a.second) << " of " << na << (proper ? " intersect" : " meet") << " near ("
    << at.x() << ", "
    << at.y() << "); holes must lie strictly inside the outer ring and apart from each other";
  throw InputError(m.str());
}

}  // namespace

std::string ring_name(std::size_t r) { return r == 0 ? "the outer ring" : "hole " + std::to_string(r); }

namespace {

// The convex hull of a ring's vertices, counter-clockwise, with their file numbers.
Polygon convex_hull_of(const Polygon& p) {
  std::vector<Point> pts, hull;
  for (const auto& v : p.vertices) pts.push_back(point(v));
  CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull), K());
  Polygon h;
  for (const Point& q : hull)
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (pts[i] == q) {
        h.vertices.push_back(p.vertices[i]), h.file_index.push_back(p.file_index[i]);
        break;
      }
  return h;
}

// The rings of a domain whose rings are each valid: no two meet, every hole
// inside the outer ring and outside every other hole. number[r]: ring r's
// number in messages.
void check_ring_relations(const Domain& d, const std::vector<std::size_t>& number) {
  check_rings_disjoint(d, number);
  // No ring meets another: each hole lies entirely on one side of every other ring.
  for (std::size_t h = 0; h < d.holes.size(); ++h) {
    const Eigen::Vector2d x = d.holes[h].vertices.front();
    if (side_of(d.outer, x) != CGAL::ON_BOUNDED_SIDE)
      throw InputError(ring_name(number[h + 1]) + " lies outside the outer ring (its vertex " +
                       std::to_string(d.holes[h].file_index.front()) + " is not inside it)");
    for (std::size_t g = 0; g < d.holes.size(); ++g) {
      if (g == h) continue;
      if (side_of(d.holes[g], x) == CGAL::ON_BOUNDED_SIDE)
        throw InputError(ring_name(number[h + 1]) + " lies inside " + ring_name(number[g + 1]) +
                         " (a hole in a hole is not part of the domain)");
    }
  }
}

}  // namespace

namespace {

// The cleaning of a domain's rings with the widths and areas derived from
// its outer ring (DomainCleaningOptions); what it did goes to the notes.
class DomainCleaner {
 public:
  DomainCleaner(const Polygon& outer, const DomainCleaningOptions& cleaning)
      : cleaning_(cleaning),
        width_(cleaning.needle_width ? *cleaning.needle_width
                                     : needle_width_for_ring(outer, std::nullopt, kDefaultNeedleWidthRelative)),
        // A crossing islet whose convex hull is smaller than this is below the boundary tolerance.
        repair_area_(cleaning.crossing_repair_area ? *cleaning.crossing_repair_area
                                                   : finite_width() * bounding_box_diagonal(outer)) {}

  // Ring r (0: the outer ring) cleaned and validated; nullopt for a hole that
  // is nothing but needles. Errors name the ring.
  std::optional<Polygon> ring(Polygon p, std::size_t r) const {
    std::string name = ring_name(r);
    try {
      PolygonCleaning c = clean_polygon(std::move(p), width_ > 0.0 ? finite_width() : 0.0);
      if (r > 0 && c.needles > 0 && c.polygon.vertices.size() < 3) {
        std::ostringstream m;
        m.precision(3);
        m << name << ": dropped: it encloses no area once its needles narrower than " << width_
          << " are removed (an islet below the boundary tolerance)";
        note(m.str());
        return std::nullopt;
      }
      if (!c.notes.empty()) note(cleaning_summary(name, c));
      if (r > 0 && c.polygon.vertices.size() >= 3) unless_simple_take_hull(c, name);
      return validate_cleaned_polygon(std::move(c), width_, r == 0 ? 4 : 3);
    } catch (const InputError& e) {
      name[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(name[0])));
      throw InputError(name + ": " + e.what());
    }
  }

  // Sharp tips cut off within the boundary tolerance (sharp_tips.h); all kept
  // if a cut would make two rings meet. number[r]: ring r's number in messages.
  void blunt_tips(Domain& d, const std::vector<std::size_t>& number) const {
    const double area = cleaning_.blunt_tip_area ? *cleaning_.blunt_tip_area : repair_area_;
    Domain blunted = d;
    std::vector<std::string> notes;
    auto blunt = [&](Polygon& ring, bool hole, std::size_t r) {
      TipBlunting t = blunt_sharp_tips(std::move(ring), hole, cleaning_.blunt_tips_below_degrees, area,
                                       finite_width(), ring_name(r));
      ring = std::move(t.polygon);
      notes.insert(notes.end(), t.notes.begin(), t.notes.end());
    };
    blunt(blunted.outer, false, 0);
    for (std::size_t h = 0; h < blunted.holes.size(); ++h) blunt(blunted.holes[h], true, number[h + 1]);
    if (notes.empty()) return;
    try {
      check_ring_relations(blunted, number);
    } catch (const InputError& e) {
      note(std::string("sharp tips kept as they are: cutting them would make two rings meet (") + e.what() + ")");
      return;
    }
    d = std::move(blunted);
    for (const std::string& n : notes) note(n);
    if (cleaning_.blunted_tips) *cleaning_.blunted_tips = notes.size();
  }

 private:
  double finite_width() const { return std::isfinite(width_) ? width_ : 0.0; }
  void note(const std::string& s) const {
    if (cleaning_.notes) cleaning_.notes->push_back(s);
  }

  // A hole that crosses itself becomes its convex hull where the options ask
  // for it or the hull is below the boundary tolerance (else validation
  // rejects it, naming the edges).
  void unless_simple_take_hull(PolygonCleaning& c, const std::string& name) const {
    std::vector<Point> pts;
    for (const auto& v : c.polygon.vertices) pts.push_back(point(v));
    if (CGAL::is_simple_2(pts.begin(), pts.end(), K())) return;
    Polygon h = convex_hull_of(c.polygon);
    const double hull_area = signed_area(h);
    const bool below_tolerance = hull_area <= repair_area_;
    if (!cleaning_.repair_crossing_holes && !below_tolerance) return;
    std::ostringstream m;
    m.precision(4);
    m << name << ": crosses itself; replaced by its convex hull (" << h.vertices.size() << " of its "
      << c.polygon.vertices.size() << " vertices; area " << std::abs(signed_area(c.polygon))
      << " (signed, lobes cancelling) -> " << hull_area;
    if (below_tolerance) m << ", below the boundary tolerance " << repair_area_;
    m << ")";
    note(m.str());
    c.polygon = std::move(h);
  }

  const DomainCleaningOptions& cleaning_;
  const double width_;
  const double repair_area_;
};

}  // namespace

Domain validate_domain(Domain d, const DomainCleaningOptions& cleaning) {
  const DomainCleaner cleaner(d.outer, cleaning);
  d.outer = *cleaner.ring(std::move(d.outer), 0);
  std::vector<std::size_t> number = {0};  // the holes kept, by their numbers in the input
  std::vector<Polygon> holes;
  for (std::size_t h = 0; h < d.holes.size(); ++h)
    if (std::optional<Polygon> p = cleaner.ring(std::move(d.holes[h]), h + 1)) {
      holes.push_back(std::move(*p));
      number.push_back(h + 1);
    }
  d.holes = std::move(holes);
  check_ring_relations(d, number);
  if (cleaning.blunted_tips) *cleaning.blunted_tips = 0;
  if (cleaning.blunt_tips_below_degrees > 0.0) cleaner.blunt_tips(d, number);
  return d;
}

double domain_area(const Domain& d) {
  double a = signed_area(d.outer);
  for (const Polygon& h : d.holes) a -= std::abs(signed_area(h));
  return a;
}

bool domain_contains(const Domain& d, const Eigen::Vector2d& p) {
  if (side_of(d.outer, p) != CGAL::ON_BOUNDED_SIDE) return false;
  for (const Polygon& h : d.holes)
    if (side_of(h, p) != CGAL::ON_UNBOUNDED_SIDE) return false;
  return true;
}

}  // namespace tspline

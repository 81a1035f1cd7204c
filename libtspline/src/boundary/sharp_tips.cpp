#include "tspline/boundary/sharp_tips.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "tspline/boundary/plane.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/errors.h"

namespace tspline {
namespace {

using V = Eigen::Vector2d;

// The angle at p from the direction to q counter-clockwise to the direction
// to r, in [0, 360) degrees: the inside angle of a counter-clockwise ring at
// p when q is its next vertex and r its previous one.
double angle_at(const V& p, const V& q, const V& r) {
  return ccw_degrees(q - p, r - p);
}

// From vertex i along the ring (step +1 or -1) a distance d: the vertices
// passed, in walking order, and the point reached (on the edge from the last
// vertex passed, or from i, to the next). Nothing if that takes more than
// max_steps vertices.
struct Walk {
  std::vector<std::size_t> passed;
  V end;
  std::size_t last = 0;  // the last vertex of the ring before `end` on the walk (i if none passed)
};

std::optional<Walk> walk(const std::vector<V>& v, std::size_t i, int step, double d, std::size_t max_steps) {
  const std::size_t n = v.size();
  Walk w;
  std::size_t cur = i;
  double rest = d;
  for (std::size_t k = 0; k <= max_steps; ++k) {
    const std::size_t next = step > 0 ? (cur + 1) % n : (cur + n - 1) % n;
    const double length = (v[next] - v[cur]).norm();
    // (A point within a rounding error of the next vertex is that vertex,
    // passed: no cut point doubles a vertex.)
    if (rest < length * (1.0 - 1e-9)) {
      w.end = v[cur] + (rest / length) * (v[next] - v[cur]);
      w.last = cur;
      return w;
    }
    rest -= length;
    cur = next;
    w.passed.push_back(cur);
  }
  return std::nullopt;
}

// One tip's cut: the two cut points, the vertices that go, the piece's area
// on the domain side, and the corners at the two cut points.
struct Cut {
  Walk back, ahead;
  double area = 0.0;
  double angle_back = 0.0, angle_ahead = 0.0;
};

std::optional<Cut> cut_at(const Polygon& p, std::size_t i, double d, bool hole) {
  const std::vector<V>& v = p.vertices;
  const std::size_t n = v.size();
  const std::size_t max_steps = n / 4;
  std::optional<Walk> back = walk(v, i, -1, d, max_steps), ahead = walk(v, i, +1, d, max_steps);
  if (!back || !ahead || back->passed.size() + ahead->passed.size() + 4 > n) return std::nullopt;
  Cut c{*back, *ahead};
  // The piece in ring order: back cut point, the vertices from there to the
  // tip and on to the ahead cut point; closed by the chord.
  std::vector<V> piece = {c.back.end};
  for (auto it = c.back.passed.rbegin(); it != c.back.passed.rend(); ++it) piece.push_back(v[*it]);
  piece.push_back(v[i]);
  for (const std::size_t k : c.ahead.passed) piece.push_back(v[k]);
  piece.push_back(c.ahead.end);
  double twice = 0.0;
  for (std::size_t k = 0; k < piece.size(); ++k) twice += cross(piece[k], piece[(k + 1) % piece.size()]);
  c.area = (hole ? -0.5 : 0.5) * twice;
  // The corners the chord makes: at the back cut point between the ring
  // before it and the chord, at the ahead one between the chord and the ring after it.
  const std::size_t before = (c.back.last + n - 1) % n;  // the ring vertex before the back cut point
  const std::size_t after = (c.ahead.last + 1) % n;       // the ring vertex after the ahead cut point
  c.angle_back = angle_at(c.back.end, c.ahead.end, v[before]);
  c.angle_ahead = angle_at(c.ahead.end, v[after], c.back.end);
  if (hole) c.angle_back = 360.0 - c.angle_back, c.angle_ahead = 360.0 - c.angle_ahead;
  return c;
}

// The ring with the cut made.
Polygon with_cut(const Polygon& p, std::size_t i, const Cut& c) {
  const std::size_t n = p.vertices.size();
  std::vector<char> gone(n, 0);
  gone[i] = 1;
  for (const std::size_t k : c.back.passed) gone[k] = 1;
  for (const std::size_t k : c.ahead.passed) gone[k] = 1;
  Polygon out;
  for (std::size_t k = 0; k < n; ++k) {
    if (k == i) {
      out.vertices.push_back(c.back.end), out.file_index.push_back(p.file_index[i]);
      out.vertices.push_back(c.ahead.end), out.file_index.push_back(p.file_index[i]);
    }
    if (!gone[k]) out.vertices.push_back(p.vertices[k]), out.file_index.push_back(p.file_index[k]);
  }
  // A tip whose back walk wrapped past vertex 0 removed vertices before i in
  // the loop above and after it: the order is still the ring's (a rotation).
  return out;
}

}  // namespace

double domain_angle_degrees(const Polygon& ring, std::size_t i, bool hole) {
  const std::vector<V>& v = ring.vertices;
  const std::size_t n = v.size();
  const double inside = angle_at(v[i], v[(i + 1) % n], v[(i + n - 1) % n]);
  return hole ? 360.0 - inside : inside;
}

TipBlunting blunt_sharp_tips(Polygon ring, bool hole, double max_degrees, double max_area, double min_width,
                             const std::string& ring_label) {
  if (!(max_degrees >= 0.0 && max_degrees <= 90.0))
    throw InputError("blunt_sharp_tips: the tip angle must be in [0, 90] degrees");
  if (!(max_area >= 0.0) || !std::isfinite(max_area))
    throw InputError("blunt_sharp_tips: the area must be finite and >= 0");
  if (!(min_width >= 0.0) || !std::isfinite(min_width))
    throw InputError("blunt_sharp_tips: the width must be finite and >= 0");
  TipBlunting out;
  out.polygon = std::move(ring);
  if (max_degrees == 0.0 || max_area == 0.0) return out;
  std::set<std::size_t> tried;  // file indices of tips looked at
  for (;;) {
    const Polygon& p = out.polygon;
    const std::size_t n = p.vertices.size();
    if (n < 5) break;
    // The sharpest tip not looked at yet.
    std::optional<std::size_t> tip;
    double theta = max_degrees;
    for (std::size_t i = 0; i < n; ++i) {
      const double a = domain_angle_degrees(p, i, hole);
      if (a < theta && !tried.count(p.file_index[i])) tip = i, theta = a;
    }
    if (!tip) break;
    const std::size_t i = *tip;
    tried.insert(p.file_index[i]);
    // The cut of an isosceles tip: area d^2 sin(theta) / 2.
    const double d_iso = std::sqrt(2.0 * max_area / std::max(std::sin(theta * std::numbers::pi / 180.0), 1e-12));
    // The largest d (bisection) whose piece has area <= max_area.
    double lo = 0.0, hi = 4.0 * d_iso;
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      const std::optional<Cut> c = cut_at(p, i, mid, hole);
      if (c && c->area <= max_area) lo = mid;
      else hi = mid;
    }
    // Shorter cuts where the chord would make a corner of 170 degrees or more
    // (a long thin feature whose sides run on), down to a sixteenth.
    std::optional<Cut> cut;
    double d = lo;
    for (int k = 0; k < 5 && d > 0.0; ++k, d *= 0.5) {
      std::optional<Cut> c = cut_at(p, i, d, hole);
      if (c && c->area > 0.0 && c->angle_back < 170.0 && c->angle_ahead < 170.0) {
        cut = std::move(c);
        break;
      }
    }
    if (!cut || (cut->ahead.end - cut->back.end).norm() < min_width) continue;
    Polygon blunted = with_cut(p, i, *cut);
    try {
      blunted = validate_polygon(std::move(blunted), hole ? 3 : 4);
    } catch (const InputError&) {
      continue;  // the chord would cross the ring: the tip stays
    }
    std::ostringstream note;
    note.precision(3);
    const double sj = std::sin(theta * std::numbers::pi / 180.0);
    note << ring_label << ": blunted the tip at vertex " << p.file_index[i] << " (" << theta
         << " degrees: a patch corner there caps the scaled Jacobian at sin(" << theta << ") = " << sj
         << "): cut " << d << " from it along the ring on both sides, " << 1 + cut->back.passed.size() + cut->ahead.passed.size()
         << " vertex(es) removed, area " << cut->area << " <= the boundary tolerance " << max_area
         << "; new corners " << cut->angle_back << " and " << cut->angle_ahead << " degrees";
    out.notes.push_back(note.str());
    ++out.tips;
    out.removed_area += cut->area;
    out.polygon = std::move(blunted);
  }
  return out;
}

}  // namespace tspline

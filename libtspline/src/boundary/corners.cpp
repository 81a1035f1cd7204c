// Choice of the four corner vertices (user-given or automatic).
#include "tspline/boundary/corners.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "tspline/boundary/plane.h"
#include "tspline/errors.h"

namespace tspline {
namespace {

constexpr double kPi = std::numbers::pi;

// Cumulative arc length: cum[i] = length from vertex 0 to vertex i, cum[n] = perimeter.
std::vector<double> arc_lengths(const Polygon& p) {
  const std::size_t n = p.vertices.size();
  std::vector<double> cum(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) cum[i + 1] = cum[i] + (p.vertices[(i + 1) % n] - p.vertices[i]).norm();
  return cum;
}

// Inner angle (degrees, in [0, 360)) of a CCW polygon at v, between the directions
// to the next point `b` and to the previous point `a`: the interior lies to the left
// of the boundary, so the inner angle is the CCW rotation taking (b - v) to (a - v).
double inner_angle(const Eigen::Vector2d& a, const Eigen::Vector2d& v, const Eigen::Vector2d& b) {
  return ccw_degrees(b - v, a - v);
}

double local_angle(const Polygon& p, std::size_t i) {
  const std::size_t n = p.vertices.size();
  return inner_angle(p.vertices[(i + n - 1) % n], p.vertices[i], p.vertices[(i + 1) % n]);
}

// Point at arc length s (taken modulo the perimeter) along the polygon. O(log n).
Eigen::Vector2d point_at_arc(const Polygon& p, const std::vector<double>& cum, double s) {
  const std::size_t n = p.vertices.size();
  const double per = cum[n];
  s = std::fmod(s, per);
  if (s < 0) s += per;
  std::size_t k = static_cast<std::size_t>(std::upper_bound(cum.begin(), cum.end(), s) - cum.begin());
  k = std::min(std::max<std::size_t>(k, 1), n) - 1;  // cum[k] <= s < cum[k+1]
  const double len = cum[k + 1] - cum[k];
  const double w = len > 0 ? (s - cum[k]) / len : 0.0;
  return p.vertices[k] + w * (p.vertices[(k + 1) % n] - p.vertices[k]);
}

// Angles are also measured "at scale": the chords from vertex i to the boundary
// points at arc length +-h. A finely sampled smooth curve has ~180 deg at every
// vertex, but a real corner keeps its angle for h up to the length of its sides.
// Scales as fractions of the perimeter; the cost averages over them.
constexpr double kScales[] = {0.01, 0.02, 0.04};

double scale_angle(const Polygon& p, const std::vector<double>& cum, std::size_t i, double frac) {
  const double h = frac * cum.back();
  return inner_angle(point_at_arc(p, cum, cum[i] - h), p.vertices[i], point_at_arc(p, cum, cum[i] + h));
}

double mean_scale_angle(const Polygon& p, const std::vector<double>& cum, std::size_t i) {
  double s = 0;
  for (double f : kScales) s += scale_angle(p, cum, i, f);
  return s / std::size(kScales);
}

// Per-vertex cost: 0 for a convex 90-degree corner at every scale, about 1 for a
// straight (180 deg) or smooth vertex; non-convex angles are penalized further,
// and a vertex that is not strictly convex locally gets a large penalty.
double vertex_cost(const Polygon& p, const std::vector<double>& cum, std::size_t i) {
  double c = 0;
  for (double f : kScales) {
    const double a = scale_angle(p, cum, i, f);
    c += std::pow((a - 90.0) / 90.0, 2) + (a >= 180.0 ? 1.0 : 0.0);
  }
  // The local angle, between the two polygon edges at the vertex, counts twice:
  // the map's boundary tangents at a corner of the square follow it (J_r there is
  // at most sin of that angle), so a vertex of 176 degrees between two straight
  // runs would be the worst point of the map however good its angle at scale.
  const double local = local_angle(p, i);
  c += 2.0 * std::pow((std::min(local, 180.0) - 90.0) / 90.0, 2);
  c /= std::size(kScales) + 2.0;
  if (local >= 180.0) c += 10.0;
  return c;
}

// Cost of a whole choice given the four chain lengths (CCW order) and the sum
// of the vertex costs. Balance terms: opposite chains of similar length (they
// map to opposite sides of the same length), overall aspect near 1, and no chain
// shorter than 5% of the perimeter unless the angles strongly ask for it. The
// aspect weight is small on purpose: a long strip (e.g. a C-shaped annular
// sector) is better served by its four true 90-degree corners, which give a
// stretched but regular map, than by corners on smooth parts of the boundary,
// where the corner cells degenerate (inner angle near 180 degrees).
double choice_cost(const double L[4], double vertex_sum) {
  const double per = L[0] + L[1] + L[2] + L[3];
  auto sq = [](double x) { return x * x; };
  double c = vertex_sum;
  c += 0.5 * (sq(std::log(L[0] / L[2])) + sq(std::log(L[1] / L[3])));
  c += 0.1 * sq(std::log((L[0] + L[2]) / (L[1] + L[3])));
  for (int k = 0; k < 4; ++k)
    if (L[k] < 0.05 * per) c += sq(std::log(L[k] / (0.05 * per)));
  return c;
}

std::string fmt(double x, int prec = 1) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, x);
  return buf;
}

// Fills inner_angle_deg and a description of angles and chain lengths.
void describe(const Polygon& p, Corners& c, const std::string& prefix, const std::string& suffix) {
  const auto cum = arc_lengths(p);
  const double per = cum.back();
  std::string idx, ang, sang, len, pct;
  for (int k = 0; k < 4; ++k) {
    const std::size_t a = c.index[k], b = c.index[(k + 1) % 4];
    c.inner_angle_deg[k] = local_angle(p, a);
    double L = cum[b] - cum[a];
    if (L <= 0) L += per;
    const std::string sep = k ? ", " : "";
    idx += sep + std::to_string(p.file_index[a]);
    ang += sep + fmt(c.inner_angle_deg[k]);
    sang += sep + fmt(mean_scale_angle(p, cum, a));
    len += sep + fmt(L, 4);
    pct += sep + fmt(100.0 * L / per, 0) + "%";
  }
  c.explanation = prefix + " corners at file vertices " + idx + ": inner angles " + ang +
                  " deg at the vertex (" + sang + " deg at 1-4% of the perimeter); chain lengths " + len +
                  " (" + pct + " of the perimeter)." + suffix;
}

}  // namespace

Corners corners_from_file_indices(const Polygon& p, const std::array<long long, 4>& f) {
  const std::size_t n = p.vertices.size();
  if (n < 4 || p.file_index.size() != n) throw InputError("corners: the polygon must be validated first");
  // Position in the CCW polygon of every file index.
  // File indices can have gaps where clean_polygon removed vertices.
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  const std::size_t file_n = *std::max_element(p.file_index.begin(), p.file_index.end()) + 1;
  std::vector<std::size_t> pos(file_n, kNone);
  for (std::size_t i = 0; i < n; ++i) pos[p.file_index[i]] = i;
  const std::string range = " (the file has vertices 0.." + std::to_string(file_n - 1) + ")";
  for (int k = 0; k < 4; ++k) {
    if (f[k] < 0 || f[k] >= static_cast<long long>(file_n))
      throw InputError("corner " + std::to_string(k + 1) + ": vertex index " + std::to_string(f[k]) +
                       " is out of range" + range + "; indices are 0-based, in the file's own numbering");
    if (pos[static_cast<std::size_t>(f[k])] == kNone)
      throw InputError("corner " + std::to_string(k + 1) + ": vertex " + std::to_string(f[k]) +
                       " was removed from the input (a repeated vertex, the tip of a zero-area spike or part of a sharp tip "
                       "cut off: see the notes); "
                       "choose a neighbouring vertex");
    for (int j = 0; j < k; ++j)
      if (f[j] == f[k])
        throw InputError("corner " + std::to_string(k + 1) + ": vertex index " + std::to_string(f[k]) +
                         " is repeated (also corner " + std::to_string(j + 1) + ")");
  }
  // Distinct values are in cyclic order iff, going round the 4-cycle, the value
  // decreases exactly once (at the wrap from the largest back to the smallest).
  // The first corner whose prefix breaks this is the offending one.
  auto cyclic = [](const long long* v, int m) {
    int descents = 0;
    for (int i = 0; i < m; ++i) descents += v[(i + 1) % m] < v[i];
    return descents == 1;
  };
  for (int k = 2; k < 4; ++k)
    if (!cyclic(f.data(), k + 1))
      throw InputError("corner " + std::to_string(k + 1) + ": vertex index " + std::to_string(f[k]) +
                       " is out of cyclic order (given " + std::to_string(f[0]) + " " + std::to_string(f[1]) +
                       " " + std::to_string(f[2]) + " " + std::to_string(f[3]) +
                       "); the corners must increase along the file's vertex order up to a cyclic shift");
  // Along the CCW polygon the user's corners come in increasing cyclic order if
  // the file was CCW, decreasing if it was CW (validate_polygon reversed it).
  long long q[4];
  for (int k = 0; k < 4; ++k) q[k] = static_cast<long long>(pos[static_cast<std::size_t>(f[k])]);
  Corners c;
  if (cyclic(q, 4)) {
    for (int k = 0; k < 4; ++k) c.index[k] = static_cast<std::size_t>(q[k]);
  } else {
    const long long r[4] = {q[3], q[2], q[1], q[0]};
    if (!cyclic(r, 4)) throw InputError("corners: the polygon's file_index is not in file order");
    // The user's first corner stays at (0,0); the CCW-next corner is the user's last.
    for (int k = 0; k < 4; ++k) c.index[k] = static_cast<std::size_t>(q[(4 - k) % 4]);
  }
  describe(p, c, "User-given", "");
  return c;
}

namespace {
Corners finish_choice(const Polygon& p, const std::vector<double>& cum, const std::array<std::size_t, 4>& pick,
                      double best_cost, std::size_t K);
}  // namespace

namespace {

// Quadruples of corners ranked by choice_cost: four vertices (in ring order)
// and their cost.
using CornerChoice = std::pair<double, std::array<std::size_t, 4>>;

// The search of corner_candidates over one validated polygon: arc lengths,
// vertex costs, and the vertices by cost.
class CornerSearch {
 public:
  explicit CornerSearch(const Polygon& p) : p_(p), n_(p.vertices.size()), cum_(arc_lengths(p)), per_(cum_[n_]) {
    vc_.resize(n_);
    for (std::size_t i = 0; i < n_; ++i) vc_[i] = vertex_cost(p, cum_, i);
    by_cost_.resize(n_);
    for (std::size_t i = 0; i < n_; ++i) by_cost_[i] = i;
    std::stable_sort(by_cost_.begin(), by_cost_.end(), [&](std::size_t a, std::size_t b) { return vc_[a] < vc_[b]; });
  }

  // Candidate set, O(n log n): (1) the best convex vertices by vertex cost, with
  // non-maximum suppression so that they are at least 1% of the perimeter apart;
  // (2) 16 equally spaced positions and (3) the positions a quarter, half and
  // three quarters of the perimeter after the 4 best candidates, each snapped to
  // the cheapest vertex within 1/64 of the perimeter. (2) and (3) give balanced
  // choices when the boundary is smooth (disk) or corners are few. Ascending.
  std::vector<std::size_t> candidates() const {
    const std::vector<std::size_t> best = best_convex();
    std::vector<std::size_t> cand = best;
    for (int j = 0; j < 16; ++j) cand.push_back(snap(j * per_ / 16));
    for (std::size_t b = 0; b < std::min<std::size_t>(4, best.size()); ++b)
      for (int j = 1; j < 4; ++j) cand.push_back(snap(cum_[best[b]] + j * per_ / 4));
    std::sort(cand.begin(), cand.end());
    cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    add_cheapest(cand);
    // Where four convex candidates are, drop the others, so that no balance
    // term can pick a reflex or straight vertex.
    if (std::count_if(cand.begin(), cand.end(), [&](std::size_t i) { return convex(i); }) >= 4)
      cand.erase(std::remove_if(cand.begin(), cand.end(), [&](std::size_t i) { return !convex(i); }), cand.end());
    return cand;
  }

  // Exhaustive search over ordered quadruples of candidates: O(K^4), K <= 72.
  // The kKeep cheapest, ascending by cost (a max-heap while searching).
  std::vector<CornerChoice> cheapest_quadruples(const std::vector<std::size_t>& cand) const {
    const std::size_t K = cand.size();
    constexpr std::size_t kKeep = 256;
    std::vector<CornerChoice> heap;
    heap.reserve(kKeep + 1);
    for (std::size_t a = 0; a < K; ++a)
      for (std::size_t b = a + 1; b < K; ++b)
        for (std::size_t c = b + 1; c < K; ++c)
          for (std::size_t d = c + 1; d < K; ++d) {
            const std::size_t q[4] = {cand[a], cand[b], cand[c], cand[d]};
            const double L[4] = {cum_[q[1]] - cum_[q[0]], cum_[q[2]] - cum_[q[1]], cum_[q[3]] - cum_[q[2]],
                                 per_ - (cum_[q[3]] - cum_[q[0]])};
            const double cost = choice_cost(L, vc_[q[0]] + vc_[q[1]] + vc_[q[2]] + vc_[q[3]]);
            if (heap.size() == kKeep && cost >= heap.front().first) continue;
            heap.push_back({cost, {q[0], q[1], q[2], q[3]}});
            std::push_heap(heap.begin(), heap.end());
            if (heap.size() > kKeep) {
              std::pop_heap(heap.begin(), heap.end());
              heap.pop_back();
            }
          }
    std::sort_heap(heap.begin(), heap.end());  // ascending cost
    return heap;
  }

  // Up to `count` of the choices (ascending by cost) that differ from each
  // other: some corner more than 2% of the perimeter away. K: the number of
  // candidates searched, for the report.
  std::vector<Corners> distinct_choices(const std::vector<CornerChoice>& choices, std::size_t count,
                                        std::size_t K) const {
    std::vector<Corners> result;
    std::vector<std::array<std::size_t, 4>> kept;
    for (const CornerChoice& ch : choices) {
      if (result.size() == count) break;
      const bool distinct = std::all_of(kept.begin(), kept.end(), [&](const std::array<std::size_t, 4>& k) {
        for (int i = 0; i < 4; ++i)
          if (arc_dist(k[i], ch.second[i]) > 0.02 * per_) return true;
        return false;
      });
      if (!distinct) continue;
      kept.push_back(ch.second);
      result.push_back(finish_choice(p_, cum_, ch.second, ch.first, K));
    }
    return result;
  }

 private:
  bool convex(std::size_t i) const { return vc_[i] < 10.0; }  // vc >= 10: not strictly convex

  double arc_dist(std::size_t a, std::size_t b) const {
    const double d = std::abs(cum_[a] - cum_[b]);
    return std::min(d, per_ - d);
  }

  // The cheapest convex vertices, at most 32, at least 1% of the perimeter apart.
  std::vector<std::size_t> best_convex() const {
    constexpr std::size_t kBest = 32;
    std::vector<std::size_t> best;
    for (std::size_t i : by_cost_) {
      if (best.size() == kBest || vc_[i] >= 10.0) break;
      if (std::all_of(best.begin(), best.end(), [&](std::size_t b) { return arc_dist(i, b) >= 0.01 * per_; }))
        best.push_back(i);
    }
    return best;
  }

  // The cheapest vertex within 1/64 of the perimeter of arc length s.
  std::size_t snap(double s) const {
    s = std::fmod(s, per_);
    if (s < 0) s += per_;
    const double w = per_ / 64;
    const std::size_t k =
        static_cast<std::size_t>(std::lower_bound(cum_.begin(), cum_.begin() + n_, s) - cum_.begin()) % n_;
    std::size_t pick = k;
    // Walk forward and backward from the vertex at/after s while within the window.
    for (int dir : {1, -1}) {
      for (std::size_t step = 0, j = k; step < n_; ++step) {
        const double d = std::abs(cum_[j] - s);
        if (std::min(d, per_ - d) > w) break;
        if (vc_[j] < vc_[pick]) pick = j;
        j = dir > 0 ? (j + 1) % n_ : (j + n_ - 1) % n_;
      }
    }
    return pick;
  }

  // Too few distinct candidates (a small polygon, or one whose perimeter is
  // nearly all in a few long edges, so that the snapped positions coincide):
  // the cheapest other vertices (convex ones first) join until there are 8,
  // or all n. A corner must be strictly convex (run_front rejects others), so
  // at least four convex candidates are wanted where the polygon has them.
  void add_cheapest(std::vector<std::size_t>& cand) const {
    auto is_convex = [&](std::size_t i) { return convex(i); };
    const std::size_t convex_wanted =
        std::min<std::size_t>(4, std::count_if(by_cost_.begin(), by_cost_.end(), is_convex));
    for (std::size_t i : by_cost_) {
      if (cand.size() >= std::min<std::size_t>(8, n_) &&
          static_cast<std::size_t>(std::count_if(cand.begin(), cand.end(), is_convex)) >= convex_wanted)
        break;
      const auto at = std::lower_bound(cand.begin(), cand.end(), i);
      if (at == cand.end() || *at != i) cand.insert(at, i);
    }
  }

  const Polygon& p_;
  const std::size_t n_;
  const std::vector<double> cum_;  // arc length at each vertex; cum_[n_] the perimeter
  const double per_;
  std::vector<double> vc_;             // vertex costs
  std::vector<std::size_t> by_cost_;   // the vertices by ascending cost (stable)
};

}  // namespace

std::vector<Corners> corner_candidates(const Polygon& p, std::size_t count) {
  if (count == 0) return {};
  if (p.vertices.size() < 4 || p.file_index.size() != p.vertices.size())
    throw InputError("corners: the polygon must be validated first");
  const CornerSearch search(p);
  const std::vector<std::size_t> cand = search.candidates();
  std::vector<Corners> result = search.distinct_choices(search.cheapest_quadruples(cand), count, cand.size());
  // Unreachable for a validated polygon (n >= 4 candidates, finite costs); a
  // clear error rather than an empty list that callers index.
  if (result.empty()) throw NumericalError("corners: no automatic choice of four corners could be evaluated");
  return result;
}

Corners choose_corners(const Polygon& p) { return corner_candidates(p, 1).front(); }

namespace {

Corners finish_choice(const Polygon& p, const std::vector<double>& cum, const std::array<std::size_t, 4>& pick,
                      double best_cost, std::size_t K) {
  // Which corner becomes (0,0): the one whose outgoing chord (to the next corner,
  // the image of the bottom side) points most nearly along +x, so the parametric
  // square is oriented like the domain.
  int first = 0;
  double best_dir = -2;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d d = p.vertices[pick[(k + 1) % 4]] - p.vertices[pick[k]];
    const double cx = d.x() / d.norm();
    if (cx > best_dir + 1e-12) best_dir = cx, first = k;
  }
  Corners out;
  for (int k = 0; k < 4; ++k) out.index[k] = pick[(first + k) % 4];
  double mean_angle = 0;
  for (std::size_t i : out.index) mean_angle += mean_scale_angle(p, cum, i) / 4;
  std::string why = " Chosen among " + std::to_string(K) +
                    " candidate vertices by a cost favouring convex corners near 90 deg and balanced "
                    "opposite chains (cost " +
                    fmt(best_cost, 3) + ")";
  why +=
      mean_angle > 150 ? "; the boundary has no sharp corners at this scale, so chain balance decided." : ".";
  describe(p, out, "Automatic", why);
  return out;
}

}  // namespace

}  // namespace tspline

#include "tspline/multipatch/automatic_cuts.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>

#include "tspline/errors.h"
#include "toolkit/union_find.h"
#include "tspline/boundary/plane.h"

namespace tspline {
namespace {

constexpr double kPi = std::numbers::pi;


// A closed polyline with arc-length access.
class Loop {
 public:
  explicit Loop(std::vector<Eigen::Vector2d> pts) : p_(std::move(pts)), s_(p_.size() + 1, 0.0) {
    for (std::size_t i = 0; i < p_.size(); ++i) s_[i + 1] = s_[i] + (p_[(i + 1) % p_.size()] - p_[i]).norm();
  }
  double length() const { return s_.back(); }
  std::size_t size() const { return p_.size(); }
  const Eigen::Vector2d& vertex(std::size_t i) const { return p_[i]; }
  double arc_of_vertex(std::size_t i) const { return s_[i]; }
  Eigen::Vector2d at(double s) const {
    const double L = length();
    s = std::fmod(s, L);
    if (s < 0) s += L;
    const std::size_t i = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(s_.begin(), s_.end(), s) - s_.begin()) - 1, p_.size() - 1);
    const double len = s_[i + 1] - s_[i];
    const double f = len > 0 ? (s - s_[i]) / len : 0.0;
    return p_[i] + f * (p_[(i + 1) % p_.size()] - p_[i]);
  }
  // Closest point: (arc position, distance).
  std::pair<double, double> closest(const Eigen::Vector2d& x) const {
    double best_s = 0.0, best_d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const Eigen::Vector2d a = p_[i], ab = p_[(i + 1) % p_.size()] - a;
      const double l2 = ab.squaredNorm();
      const double f = l2 > 0 ? std::clamp((x - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
      const double d = (a + f * ab - x).norm();
      if (d < best_d) best_d = d, best_s = s_[i] + f * (s_[i + 1] - s_[i]);
    }
    return {best_s, best_d};
  }
  // Interior angle at arc position s measured by chords to s -+ h (the
  // interior on the left of increasing s).
  double angle_at(double s, double h) const {
    const Eigen::Vector2d x = at(s);
    return ccw_angle(at(s + h) - x, at(s - h) - x);
  }

 private:
  std::vector<Eigen::Vector2d> p_;
  std::vector<double> s_;
};

double arc_distance(double a, double b, double L) {
  const double d = std::fmod(std::abs(a - b), L);
  return std::min(d, L - d);
}

// Rings as loops with the domain on the left (holes reversed).
std::vector<Loop> domain_loops(const Domain& d) {
  std::vector<Loop> out{Loop(d.outer.vertices)};
  for (const Polygon& h : d.holes) out.emplace_back(std::vector<Eigen::Vector2d>(h.vertices.rbegin(), h.vertices.rend()));
  return out;
}

// Penalty of a cut end at arc position s of loop L, cut direction c: the two
// angles a, b it leaves on its sides should be equal.
double end_penalty(const Loop& L, double s, const Eigen::Vector2d& c, double h) {
  const Eigen::Vector2d x = L.at(s);
  const Eigen::Vector2d fwd = L.at(s + h) - x, back = L.at(s - h) - x;
  const double a = ccw_angle(fwd, c), b = ccw_angle(c, back);
  const double theta = ccw_angle(fwd, back);
  if (a + b > theta + 1e-9 || std::min(a, b) < kPi / 9) return 4.0;  // leaves the domain at this scale, or too sharp
  return std::pow((a - b) / (a + b), 2);
}

struct Candidate {
  Cut cut;
  std::size_t ring_p = 0, ring_q = 0;
  double s_p = 0.0, s_q = 0.0;
  double cost = 0.0;
  bool to_sharp = false;
};

bool valid_cut(const Domain& d, const Cut& c) {
  try {
    validate_cuts(d, {c});
    return true;
  } catch (const InputError&) {
    return false;
  }
}

bool segments_meet(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& e) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, e - a), d3 = cross(e - c, a - c), d4 = cross(e - c, b - c);
  if (d1 == 0 && d2 == 0) {  // collinear: meet iff the boxes overlap
    const Eigen::Vector2d lo1 = a.cwiseMin(b), hi1 = a.cwiseMax(b), lo2 = c.cwiseMin(e), hi2 = c.cwiseMax(e);
    return (lo1.array() <= hi2.array()).all() && (lo2.array() <= hi1.array()).all();
  }
  return d1 * d2 <= 0 && d3 * d4 <= 0;
}

struct Context {
  const Domain& d;
  std::vector<Loop> loops;
  double scale;  // sqrt(area)
};

std::vector<Candidate> hole_candidates(const Context& cx, std::size_t h) {
  std::vector<Candidate> out;
  const Loop& H = cx.loops[h];
  auto add = [&](double s_p, std::size_t r, double s_q, bool sharp) {
    const Eigen::Vector2d p = H.at(s_p), q = cx.loops[r].at(s_q);
    const double len = (q - p).norm();
    if (!(len > 0)) return;
    const Cut cut{p, q};
    if (!valid_cut(cx.d, cut)) return;
    const double hp = std::min(0.3 * len, H.length() / 12), hq = std::min(0.3 * len, cx.loops[r].length() / 12);
    const double cost = len / cx.scale + end_penalty(H, s_p, q - p, hp) + end_penalty(cx.loops[r], s_q, p - q, hq);
    out.push_back({cut, h, r, s_p, s_q, cost, sharp});
  };
  const std::size_t stride = std::max<std::size_t>(1, H.size() / 96);
  for (std::size_t i = 0; i < H.size(); i += stride) {
    const Eigen::Vector2d p = H.vertex(i);
    std::size_t best_r = 0;
    std::pair<double, double> best{0.0, std::numeric_limits<double>::infinity()};
    for (std::size_t r = 0; r < cx.loops.size(); ++r) {
      if (r == h) continue;
      const auto c = cx.loops[r].closest(p);
      if (c.second < best.second) best = c, best_r = r;
    }
    add(H.arc_of_vertex(i), best_r, best.first, false);
  }
  // Into the sharp convex vertices of the other rings (angle < 150 degrees at 1/50 of the ring's length).
  for (std::size_t r = 0; r < cx.loops.size(); ++r) {
    if (r == h) continue;
    const Loop& R = cx.loops[r];
    for (std::size_t i = 0; i < R.size(); ++i) {
      if (R.angle_at(R.arc_of_vertex(i), R.length() / 50) > kPi * 150.0 / 180.0) continue;
      if (R.angle_at(R.arc_of_vertex(i), 0.0) > kPi) continue;
      add(H.closest(R.vertex(i)).first, r, R.arc_of_vertex(i), true);
    }
  }
  return out;
}

// First hit of the ray a + s u (s > 0) with the edges of face f that do not
// touch vertex i: (edge index, s), or edge -1.
std::pair<int, double> cast_ray(const LayoutFace& f, std::size_t i, const Eigen::Vector2d& u) {
  const Eigen::Vector2d a = f.points[i];
  const std::size_t n = f.points.size();
  std::pair<int, double> best{-1, std::numeric_limits<double>::infinity()};
  for (std::size_t e = 0; e < n; ++e) {
    const std::size_t e1 = (e + 1) % n;
    if (e == i || e1 == i) continue;
    const Eigen::Vector2d p = f.points[e], d = f.points[e1] - p;
    const double den = cross(u, d);
    if (den == 0.0) continue;
    const double s = cross(p - a, d) / den, t = cross(p - a, u) / den;
    if (s > 0 && t >= 0 && t <= 1 && s < best.second) best = {static_cast<int>(e), s};
  }
  return best;
}

// Cheapest chord that cuts a four-sided patch off a face with more than four
// cut ends: between cut ends k and k+3 (the rest keeps c - 2 of its c cut
// ends; only for even c, so that the rest stays even), or from cut end k into
// the ring side between cut ends k+2 and k+3, or k-3 and k-2 (the rest keeps
// c - 1), along the bisector of the face angle at k or within 30 degrees of it.
// The node-to-ring chords only where no node-to-node chord fits (odd c, or
// cut ends in line).
bool best_chord(const Context& cx, const LayoutFace& f, Cut& chord) {
  std::vector<std::size_t> nodes;
  for (std::size_t i = 0; i < f.points.size(); ++i)
    if (f.is_node[i]) nodes.push_back(i);
  const std::size_t c = nodes.size();
  const Loop F(f.points);
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](const Eigen::Vector2d& a, double s_a, const Eigen::Vector2d& b, double s_b) {
    const double len = (b - a).norm();
    if (!(len > 0)) return;
    const double h = std::min(0.3 * len, F.length() / 40);
    const double pa = end_penalty(F, s_a, b - a, h), pb = end_penalty(F, s_b, a - b, h);
    if (pa >= 4.0 || pb >= 4.0) return;
    const double cost = len / cx.scale + pa + pb;
    if (cost < best) best = cost, chord = {a, b};
  };
  for (std::size_t k = 0; k < c; ++k) {
    const std::size_t i = nodes[k];
    const Eigen::Vector2d a = f.points[i];
    if (c % 2 == 0) {  // node to node
      const std::size_t j = nodes[(k + 3) % c];
      const Eigen::Vector2d b = f.points[j];
      bool ok = true;
      for (std::size_t e = 0; e < f.points.size() && ok; ++e) {
        const std::size_t e1 = (e + 1) % f.points.size();
        if (e == i || e1 == i || e == j || e1 == j) continue;
        if (segments_meet(a, b, f.points[e], f.points[e1])) ok = false;
      }
      if (ok && domain_contains(cx.d, 0.5 * (a + b))) consider(a, F.arc_of_vertex(i), b, F.arc_of_vertex(j));
    }
  }
  // Node-to-node chords first: they add no new corner on a ring side.
  if (std::isfinite(best)) return true;
  for (std::size_t k = 0; k < c; ++k) {
    const std::size_t i = nodes[k];
    const Eigen::Vector2d a = f.points[i];
    // Node to ring: rays around the bisector of the face angle at a.
    const std::size_t n = f.points.size();
    const Eigen::Vector2d fwd = (f.points[(i + 1) % n] - a).normalized(), back = (f.points[(i + n - 1) % n] - a).normalized();
    const double theta = ccw_angle(fwd, back);
    const std::size_t lo1 = nodes[(k + 2) % c], hi1 = nodes[(k + 3) % c];
    const std::size_t lo2 = nodes[(k + c - 3) % c], hi2 = nodes[(k + c - 2) % c];
    auto between = [&](std::size_t e, std::size_t from, std::size_t to) {  // edge e on the face path from..to
      return from <= to ? (e >= from && e < to) : (e >= from || e < to);
    };
    for (int deg = -30; deg <= 30; deg += 10) {
      const double phi = theta / 2 + deg * kPi / 180;
      if (phi <= 0 || phi >= theta) continue;
      const Eigen::Vector2d u(std::cos(phi) * fwd.x() - std::sin(phi) * fwd.y(),
                              std::sin(phi) * fwd.x() + std::cos(phi) * fwd.y());
      const auto [e, dist] = cast_ray(f, i, u);
      if (e < 0 || f.edge_cut[e] != -1) continue;
      const auto ue = static_cast<std::size_t>(e);
      if (!between(ue, lo1, hi1) && !between(ue, lo2, hi2)) continue;
      const Eigen::Vector2d b = a + dist * u;
      if (!domain_contains(cx.d, 0.5 * (a + b))) continue;
      consider(a, F.arc_of_vertex(i), b, F.closest(b).first);
    }
  }
  return std::isfinite(best);
}

// Counts the sharp convex ring vertices of a face as nodes (corners that a
// side should not pass through): inner angle at most 120 degrees both at the
// vertex and between chords to 1/50 of the face's perimeter on either side.
void mark_sharp_vertices(LayoutFace& f) {
  const Loop F(f.points);
  const std::size_t n = f.points.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (f.is_node[i]) continue;
    const Eigen::Vector2d a = f.points[(i + n - 1) % n] - f.points[i], b = f.points[(i + 1) % n] - f.points[i];
    const double sharp = kPi * 120.0 / 180.0;
    if (ccw_angle(b, a) <= sharp && F.angle_at(F.arc_of_vertex(i), F.length() / 50) <= sharp) f.is_node[i] = 1;
  }
}

// One variant: k cut ends per hole, sharp-vertex cuts first or not.
std::optional<std::vector<Cut>> variant(const Context& cx, const std::vector<std::vector<Candidate>>& cands, int k,
                                        bool sharp_first, bool sharp_nodes) {
  const std::size_t rings = cx.loops.size();
  std::vector<Candidate> chosen;
  std::vector<std::vector<std::pair<double, double>>> ends(rings);  // per ring: (arc position, cut length)
  auto crosses_chosen = [&](const Cut& c) {
    for (const Candidate& o : chosen)
      if (segments_meet(c.front(), c.back(), o.cut.front(), o.cut.back())) return true;
    return false;
  };
  auto separated = [&](std::size_t r, double s, double min_gap) {
    for (const auto& [t, len] : ends[r])
      if (arc_distance(s, t, cx.loops[r].length()) < std::max(min_gap, 0.5 * len)) return false;
    return true;
  };
  auto accept = [&](const Candidate& c) {
    chosen.push_back(c);
    const double len = (c.cut.back() - c.cut.front()).norm();
    ends[c.ring_p].push_back({c.s_p, len});
    ends[c.ring_q].push_back({c.s_q, len});
  };
  auto fits = [&](const Candidate& c, int per_ring) {
    return !crosses_chosen(c.cut) && separated(c.ring_p, c.s_p, cx.loops[c.ring_p].length() / (2.0 * per_ring)) &&
           separated(c.ring_q, c.s_q, 0.0);
  };
  for (std::size_t h = 1; h < rings; ++h) {
    std::vector<const Candidate*> order;
    for (const Candidate& c : cands[h]) order.push_back(&c);
    std::stable_sort(order.begin(), order.end(), [&](const Candidate* a, const Candidate* b) {
      if (sharp_first && a->to_sharp != b->to_sharp) return a->to_sharp;
      return a->cost < b->cost;
    });
    for (const Candidate* c : order) {
      if (static_cast<int>(ends[h].size()) >= k) break;
      if (fits(*c, k)) accept(*c);
    }
  }
  // Join every hole to the outer ring (union-find over rings).
  toolkit::UnionFind joined(rings);
  auto find = [&](std::size_t x) { return joined.find(x); };
  for (const Candidate& c : chosen) joined.unite(c.ring_p, c.ring_q);
  for (bool again = true; again;) {
    again = false;
    const Candidate* best = nullptr;
    for (std::size_t h = 1; h < rings; ++h)
      for (const Candidate& c : cands[h])
        if (find(c.ring_p) != find(c.ring_q) && (find(c.ring_p) != find(0) || find(c.ring_q) != find(0)) &&
            fits(c, k) && (!best || c.cost < best->cost))
          best = &c;
    if (best) {
      accept(*best);
      joined.unite(best->ring_p, best->ring_q);
      again = true;
    }
  }
  for (std::size_t r = 1; r < rings; ++r)
    if (find(r) != find(0) || ends[r].size() < 2) return std::nullopt;
  std::vector<Cut> cuts;
  for (const Candidate& c : chosen) cuts.push_back(c.cut);
  // Split the faces with more than four cut ends.
  for (std::size_t round = 0; round < 8 * rings + 8; ++round) {
    std::vector<LayoutFace> faces;
    try {
      faces = layout_faces(cx.d, cuts);
    } catch (const InputError&) {
      return std::nullopt;
    }
    if (sharp_nodes)
      for (LayoutFace& f : faces) mark_sharp_vertices(f);
    const LayoutFace* big = nullptr;
    for (const LayoutFace& f : faces)
      if (f.nodes() > 4) big = &f;
    if (!big) return cuts;
    Cut chord;
    if (!best_chord(cx, *big, chord)) return std::nullopt;
    cuts.push_back(chord);
  }
  return std::nullopt;
}

}  // namespace

double layout_cost(const Domain& d, const PatchLayout& layout) {
  const double scale = std::sqrt(domain_area(d));
  double cost = 0.0;
  for (const Cut& c : layout.cuts)
    for (std::size_t k = 0; k + 1 < c.size(); ++k) cost += (c[k + 1] - c[k]).norm() / scale;
  for (const Patch& p : layout.patches) {
    const Loop F(p.polygon.vertices);
    const double h = F.length() / 40;
    std::vector<char> corner(p.polygon.vertices.size(), 0);
    for (std::size_t c : p.corners) corner[c] = 1;
    for (std::size_t i = 0; i < F.size(); ++i) {
      const double angle = F.angle_at(F.arc_of_vertex(i), h);
      if (corner[i]) cost += std::pow((angle - kPi / 2) / (kPi / 2), 2);
      else if (std::abs(kPi - angle) > kPi * 25.0 / 180.0) cost += 4.0 * std::pow((kPi - angle) / (kPi / 2), 2);
    }
  }
  return cost;
}

AutomaticCuts automatic_cuts(const Domain& d) {
  if (d.holes.empty()) throw InputError("automatic cuts need a domain with holes");
  Context cx{d, domain_loops(d), std::sqrt(domain_area(d))};
  std::vector<std::vector<Candidate>> cands(cx.loops.size());
  for (std::size_t h = 1; h < cx.loops.size(); ++h) cands[h] = hole_candidates(cx, h);
  AutomaticCuts best;
  best.cost = std::numeric_limits<double>::infinity();
  for (int k = 2; k <= 4; ++k)
    for (int v = 0; v < 4; ++v) {
      const bool sharp_first = v % 2 == 1, sharp_nodes = v >= 2;
      const auto cuts = variant(cx, cands, k, sharp_first, sharp_nodes);
      if (!cuts) continue;
      try {
        const PatchLayout L = build_patch_layout(d, *cuts);
        const double cost = layout_cost(d, L);
        if (cost < best.cost) {
          std::ostringstream s;
          s << k << " cut ends per hole" << (sharp_first ? ", cuts into sharp vertices first" : "")
            << (sharp_nodes ? ", sharp vertices as corners" : "") << ", "
            << L.cuts.size() << " cuts, " << L.patches.size() << " patches, layout cost " << cost;
          best = {*cuts, cost, s.str()};
        }
      } catch (const InputError&) {
        // this variant leaves a face that is not a four-sided patch
      }
    }
  if (best.cuts.empty())
    throw InputError("no automatic decomposition into four-sided patches found for this domain with " +
                     std::to_string(d.holes.size()) + " hole(s); give the cuts by hand (`cuts`)");
  return best;
}

}  // namespace tspline

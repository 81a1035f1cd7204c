#include "tspline/analysis/multipatch_poisson.h"
#include "tspline/detail/quadrature.h"

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <map>
#include <set>
#include <numeric>

#include "tspline/spline/bezier_extraction.h"
#include "tspline/boundary/border_knots.h"
#include "tspline/errors.h"
#include "tspline/validity/map_quality.h"
#include "tspline/multipatch/multipatch_parameterization.h"

namespace tspline {
namespace {

// Index range of a level-l function along a side: [0, 2^l + 2].
std::int64_t last_index(int level) { return (std::int64_t{1} << level) + 2; }

// Tangential index (side's own direction) of a function that does not vanish
// on `side`, or -1 if it vanishes there.
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

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

double value_of(const ScalarField& g, const char* name, const Eigen::Vector2d& x) {
  const double v = g(x.x(), x.y());
  if (!std::isfinite(v)) throw InputError(std::string(name) + " is not finite at a point of the domain");
  return v;
}

// Gauss points of the border cell edges of `side` of analysis cell c (none if c is not on it).
void side_quadrature(const TMesh& mesh, int c, int side, std::vector<double>& t_pts, std::vector<Eigen::Vector2d>& uv) {
  const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
  double a = 0, b = 0;
  switch (static_cast<Side>(side)) {
    case Side::Bottom: if (lo.y() != 0.0) return; a = lo.x(), b = hi.x(); break;
    case Side::Right: if (hi.x() != 1.0) return; a = lo.y(), b = hi.y(); break;
    case Side::Top: if (hi.y() != 1.0) return; a = 1.0 - hi.x(), b = 1.0 - lo.x(); break;
    case Side::Left: if (lo.x() != 0.0) return; a = 1.0 - hi.y(), b = 1.0 - lo.y(); break;
  }
  std::vector<double> p, w;
  detail::gauss_points_01(5, p, w);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double t = a + (b - a) * p[k];
    t_pts.push_back((b - a) * w[k]);
    uv.push_back(side_point_uv(side, t));
  }
}

// Calls fn(c, d, w, bv) at every point of n x n Gauss points per piece of every
// analysis cell c of one patch: d the map's derivatives up to `order`, w the
// physical weight (parametric weight times |det J|), bv the analysis functions
// up to `order`.
template <class Fn>
void for_each_point(const TSplineMap& map, const AnalysisSpace& sp, int n, int order, Fn&& fn) {
  std::vector<QuadraturePoint> qp;
  BasisValues bv;
  for (int c = 0; c < static_cast<int>(sp.mesh().num_cells()); ++c) {
    qp.clear();
    box_quadrature(sp.mesh().cell_min(c), sp.mesh().cell_max(c), n, qp, map.basis(), sp.geometry_cell(c));
    for (const QuadraturePoint& q : qp) {
      const MapDerivatives d = map.derivatives(q.uv, order, sp.geometry_cell(c));
      sp.basis().evaluate(c, q.uv, bv, order);
      fn(c, d, q.weight * std::abs(d.J.determinant()), bv);
    }
  }
}

}  // namespace

MultiPatchSolution solve_multipatch_poisson(const std::vector<const TSplineMap*>& maps,
                                            const std::vector<Interface>& interfaces,
                                            const std::vector<TMesh>& meshes, const PoissonProblem& problem) {
  if (!problem.f || !problem.g) throw InputError("the Poisson problem needs f and g");
  const std::size_t P = maps.size();
  MultiPatchSolution S;
  std::vector<std::size_t> offset(P + 1, 0);
  for (std::size_t p = 0; p < P; ++p) {
    S.spaces.push_back(std::make_shared<const AnalysisSpace>(*maps[p], meshes[p]));
    offset[p + 1] = offset[p] + S.spaces[p]->num_dofs();
  }
  // Gluing across the interfaces.
  UnionFind uf(offset[P]);
  std::vector<std::array<char, 4>> is_interface(P, {0, 0, 0, 0});
  for (const Interface& f : interfaces) {
    is_interface[f.patch_a][f.side_a] = is_interface[f.patch_b][f.side_b] = 1;
    std::map<std::pair<int, std::int64_t>, int> on_b;
    const HierarchicalBasis& bb = S.spaces[f.patch_b]->basis();
    for (int a = 0; a < static_cast<int>(bb.size()); ++a) {
      const std::int64_t k = side_index(bb.function(a), f.side_b);
      if (k >= 0) on_b[{bb.function(a).level, k}] = a;
    }
    const HierarchicalBasis& ba = S.spaces[f.patch_a]->basis();
    std::size_t matched = 0;
    for (int a = 0; a < static_cast<int>(ba.size()); ++a) {
      const HierarchicalFunction& h = ba.function(a);
      const std::int64_t k = side_index(h, f.side_a);
      if (k < 0) continue;
      const auto it = on_b.find({h.level, last_index(h.level) - k});
      if (it == on_b.end())
        throw NumericalError("interface along cut " + std::to_string(f.cut) + ": patch " + std::to_string(f.patch_a) +
                             " has a border function with no partner in patch " + std::to_string(f.patch_b) +
                             " (the analysis spaces are not conforming there)");
      uf.unite(static_cast<int>(offset[f.patch_a]) + a, static_cast<int>(offset[f.patch_b]) + it->second);
      ++matched;
    }
    if (matched != on_b.size())
      throw NumericalError("interface along cut " + std::to_string(f.cut) + ": the two sides have " +
                           std::to_string(matched) + " and " + std::to_string(on_b.size()) + " border functions");
    S.glued_pairs += matched;
  }
  std::vector<int> root_id(offset[P], -1);
  S.global.resize(P);
  int n = 0;
  for (std::size_t p = 0; p < P; ++p) {
    S.global[p].resize(S.spaces[p]->num_dofs());
    for (std::size_t a = 0; a < S.global[p].size(); ++a) {
      const int r = uf.find(static_cast<int>(offset[p] + a));
      if (root_id[r] < 0) root_id[r] = n++;
      S.global[p][a] = root_id[r];
    }
  }
  S.unknowns = static_cast<std::size_t>(n);

  // Dirichlet: L2 projection of g on the ring sides (physical arc length).
  std::vector<char> dirichlet(n, 0);
  std::vector<Eigen::Triplet<double>> mt;
  Eigen::VectorXd mb = Eigen::VectorXd::Zero(n);
  BasisValues bv;
  for (std::size_t p = 0; p < P; ++p) {
    const AnalysisSpace& sp = *S.spaces[p];
    for (int side = 0; side < 4; ++side) {
      if (is_interface[p][side]) continue;
      for (int c = 0; c < static_cast<int>(sp.mesh().num_cells()); ++c) {
        std::vector<double> w;
        std::vector<Eigen::Vector2d> uv;
        side_quadrature(sp.mesh(), c, side, w, uv);
        for (std::size_t q = 0; q < uv.size(); ++q) {
          const MapDerivatives d = maps[p]->derivatives(uv[q], 1, sp.geometry_cell(c));
          const Eigen::Vector2d tangent = (side % 2 == 0) ? d.J.col(0) : d.J.col(1);
          const double ww = w[q] * tangent.norm();
          const double gv = value_of(problem.g, "g", d.x);
          sp.basis().evaluate(c, uv[q], bv, 0);
          for (std::size_t i = 0; i < bv.ids.size(); ++i) {
            if (bv.R[i] == 0.0) continue;
            const int gi = S.global[p][bv.ids[i]];
            dirichlet[gi] = 1;
            mb[gi] += ww * gv * bv.R[i];
            for (std::size_t j = 0; j < bv.ids.size(); ++j)
              if (bv.R[j] != 0.0) mt.emplace_back(gi, S.global[p][bv.ids[j]], ww * bv.R[i] * bv.R[j]);
          }
        }
      }
    }
  }
  // Number the Dirichlet and the interior unknowns.
  std::vector<int> dnum(n, -1), inum(n, -1);
  int nd = 0, ni = 0;
  for (int g = 0; g < n; ++g) (dirichlet[g] ? dnum[g] = nd++ : inum[g] = ni++);
  S.interior_unknowns = static_cast<std::size_t>(ni);
  S.values = Eigen::VectorXd::Zero(n);
  {
    std::vector<Eigen::Triplet<double>> md;
    Eigen::VectorXd rhs(nd);
    for (const auto& t : mt) md.emplace_back(dnum[t.row()], dnum[t.col()], t.value());
    for (int g = 0; g < n; ++g)
      if (dirichlet[g]) rhs[dnum[g]] = mb[g];
    Eigen::SparseMatrix<double> M(nd, nd);
    M.setFromTriplets(md.begin(), md.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
    if (ldlt.info() != Eigen::Success) throw NumericalError("the Dirichlet projection system is singular");
    const Eigen::VectorXd c = ldlt.solve(rhs);
    for (int g = 0; g < n; ++g)
      if (dirichlet[g]) S.values[g] = c[dnum[g]];
  }
  // Stiffness and load.
  std::vector<Eigen::Triplet<double>> kt;
  Eigen::VectorXd load = Eigen::VectorXd::Zero(ni);
  for (std::size_t p = 0; p < P; ++p) {
    for_each_point(*maps[p], *S.spaces[p], 4, 1, [&](int, const MapDerivatives& d, double w, const BasisValues& bv) {
      const Eigen::Matrix2d JinvT = d.J.inverse().transpose();
      const double fv = value_of(problem.f, "f", d.x);
      const std::size_t m = bv.ids.size();
      std::vector<Eigen::Vector2d> grad(m);
      for (std::size_t i = 0; i < m; ++i) grad[i] = JinvT * Eigen::Vector2d(bv.R_xi[i], bv.R_eta[i]);
      for (std::size_t i = 0; i < m; ++i) {
        const int gi = S.global[p][bv.ids[i]];
        if (inum[gi] < 0) continue;
        load[inum[gi]] += w * fv * bv.R[i];
        for (std::size_t j = 0; j < m; ++j) {
          const int gj = S.global[p][bv.ids[j]];
          const double k = w * grad[i].dot(grad[j]);
          if (inum[gj] >= 0) kt.emplace_back(inum[gi], inum[gj], k);
          else load[inum[gi]] -= k * S.values[gj];
        }
      }
    });
  }
  Eigen::SparseMatrix<double> K(ni, ni);
  K.setFromTriplets(kt.begin(), kt.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(K);
  if (solver.info() != Eigen::Success) throw NumericalError("the multi-patch stiffness matrix could not be factored");
  const Eigen::VectorXd u = solver.solve(load);
  if (solver.info() != Eigen::Success) throw NumericalError("the multi-patch Poisson solve failed");
  for (int g = 0; g < n; ++g)
    if (inum[g] >= 0) S.values[g] = u[inum[g]];
  return S;
}

PoissonErrors multipatch_errors(const std::vector<const TSplineMap*>& maps, const MultiPatchSolution& S,
                                const PoissonProblem& problem) {
  if (!problem.exact) throw InputError("errors need the exact solution");
  PoissonErrors e;
  const double h = kGradientStep;
  for (std::size_t p = 0; p < maps.size(); ++p) {
    for_each_point(*maps[p], *S.spaces[p], 6, 1, [&](int, const MapDerivatives& d, double w, const BasisValues& bv) {
      double uh = 0;
      Eigen::Vector2d gxi = Eigen::Vector2d::Zero();
      for (std::size_t i = 0; i < bv.ids.size(); ++i) {
        const double v = S.values[S.global[p][bv.ids[i]]];
        uh += v * bv.R[i];
        gxi += v * Eigen::Vector2d(bv.R_xi[i], bv.R_eta[i]);
      }
      const Eigen::Vector2d guh = d.J.inverse().transpose() * gxi;
      const double x = d.x.x(), y = d.x.y();
      const double ue = problem.exact(x, y);
      const Eigen::Vector2d gue =
          problem.exact_gradient ? problem.exact_gradient(x, y)
                                 : Eigen::Vector2d((problem.exact(x + h, y) - problem.exact(x - h, y)) / (2 * h),
                                                   (problem.exact(x, y + h) - problem.exact(x, y - h)) / (2 * h));
      e.l2 += w * (ue - uh) * (ue - uh);
      e.h1 += w * (gue - guh).squaredNorm();
      e.l2_exact += w * ue * ue;
      e.h1_exact += w * gue.squaredNorm();
      e.max_abs_at_qp = std::max(e.max_abs_at_qp, std::abs(ue - uh));
    });
  }
  e.l2 = std::sqrt(e.l2), e.h1 = std::sqrt(e.h1), e.l2_exact = std::sqrt(e.l2_exact), e.h1_exact = std::sqrt(e.h1_exact);
  return e;
}

double multipatch_interface_jump(const std::vector<Interface>& interfaces, const MultiPatchSolution& S) {
  auto value = [&](std::size_t p, const Eigen::Vector2d& uv) {
    const AnalysisSpace& sp = *S.spaces[p];
    const int c = sp.basis().locate(uv);
    BasisValues bv;
    sp.basis().evaluate(c, uv, bv, 0);
    double u = 0;
    for (std::size_t i = 0; i < bv.ids.size(); ++i) u += S.values[S.global[p][bv.ids[i]]] * bv.R[i];
    return u;
  };
  double jump = 0.0;
  for (const Interface& f : interfaces)
    for (int k = 0; k <= 32; ++k) {
      const double t = k / 32.0;
      jump = std::max(jump, std::abs(value(f.patch_a, side_point_uv(f.side_a, t)) -
                                     value(f.patch_b, side_point_uv(f.side_b, 1.0 - t))));
    }
  return jump;
}

std::vector<std::vector<double>> multipatch_estimate(const std::vector<const TSplineMap*>& maps,
                                                     const MultiPatchSolution& S, const PoissonProblem& problem) {
  std::vector<std::vector<double>> eta(maps.size());
  for (std::size_t p = 0; p < maps.size(); ++p) {
    const TMesh& mesh = S.spaces[p]->mesh();
    eta[p].assign(mesh.num_cells(), 0.0);
    for_each_point(*maps[p], *S.spaces[p], 4, 2, [&](int c, const MapDerivatives& d, double w, const BasisValues& bv) {
      Eigen::Vector2d gxi = Eigen::Vector2d::Zero();
      Eigen::Matrix2d hxi = Eigen::Matrix2d::Zero();
      for (std::size_t i = 0; i < bv.ids.size(); ++i) {
        const double v = S.values[S.global[p][bv.ids[i]]];
        gxi += v * Eigen::Vector2d(bv.R_xi[i], bv.R_eta[i]);
        hxi(0, 0) += v * bv.R_xixi[i], hxi(0, 1) += v * bv.R_xieta[i], hxi(1, 1) += v * bv.R_etaeta[i];
      }
      hxi(1, 0) = hxi(0, 1);
      const Eigen::Vector2d gx = d.J.inverse().transpose() * gxi;
      const double r = value_of(problem.f, "f", d.x) + physical_hessian(gx, hxi, d).trace();
      eta[p][c] += w * r * r;  // h_e^2 applied below
    });
    for (int c = 0; c < static_cast<int>(mesh.num_cells()); ++c) {
      // h_e: the longer diagonal of the image of the cell's corners.
      const Eigen::Vector2d lo = mesh.cell_min(c), hi = mesh.cell_max(c);
      const double h = std::max((maps[p]->point(hi) - maps[p]->point(lo)).norm(),
                                (maps[p]->point({hi.x(), lo.y()}) - maps[p]->point({lo.x(), hi.y()})).norm());
      eta[p][c] = h * std::sqrt(eta[p][c]);
    }
  }
  return eta;
}

std::vector<TMesh> refine_multipatch(const std::vector<TMesh>& meshes, const std::vector<Interface>& interfaces,
                                     const std::vector<std::vector<int>>& marked) {
  std::vector<TMesh> out;
  for (std::size_t p = 0; p < meshes.size(); ++p)
    out.push_back(marked[p].empty() ? meshes[p] : refine_cells(meshes[p], refinement_patch(meshes[p], marked[p])));
  // Propagation: refining one side of a cut adds border knots there; the other
  // side gets them too (and balancing may add more, hence the loop).
  for (std::size_t splits = 1; splits > 0;) {
    splits = 0;
    for (const Interface& f : interfaces) {
      std::set<double> u;
      for (double t : border_params(out[f.patch_a], static_cast<Side>(f.side_a))) u.insert(t);
      for (double t : border_params(out[f.patch_b], static_cast<Side>(f.side_b))) u.insert(reversed_param(t));
      BorderParams a, b;
      a[f.side_a].assign(u.begin(), u.end());
      for (double t : u) b[f.side_b].push_back(reversed_param(t));
      splits += refine_to_border_params(out[f.patch_a], a, TMesh::kMaxLevel);
      splits += refine_to_border_params(out[f.patch_b], b, TMesh::kMaxLevel);
    }
  }
  return out;
}

}  // namespace tspline

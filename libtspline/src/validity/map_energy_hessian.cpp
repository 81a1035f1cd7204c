// The Hessian of the map's energy for projected Newton: each sample's 4 x 4
// Hessian in J, projected to positive semi-definite in closed form, and its
// assembly over the free control points; see map_energy.h.
#include "tspline/validity/map_energy.h"
#include "tspline/detail/thread_pool.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace tspline {

SampleTerm sample_term(const Eigen::Matrix2d& J, double eps, double theta, double power, bool project) {
  constexpr double s2 = 0.70710678118654752440;  // 1 / sqrt(2)
  // Conformal (z) and anticonformal (w) coordinates of J in the orthonormal
  // basis e1..e4 of map_energy.h: vec J = E (z1, z2, w1, w2).
  const Eigen::Vector2d z(s2 * (J(0, 0) + J(1, 1)), s2 * (J(1, 0) - J(0, 1)));
  const Eigen::Vector2d w(s2 * (J(0, 0) - J(1, 1)), s2 * (J(0, 1) + J(1, 0)));
  const double P = z.squaredNorm(), Q = w.squaredNorm();
  const double D = J.determinant();  // = (P - Q) / 2, without the cancellation
  const double I = J.squaredNorm();  // = P + Q
  // t(I, D) = N / chi, N = (1 - theta) I + theta (D^2 + 1) (Garanzha et al. 2021, Eqs. 2-4);
  // chi' = chi / r, chi'' = eps^2 / (2 r^3), r = sqrt(eps^2 + D^2).
  const double r = std::sqrt(eps * eps + D * D);
  const double chi = regularized_det(D, eps);
  const double c1 = chi / r, c2 = eps * eps / (2.0 * r * r * r);
  const double N = (1.0 - theta) * I + theta * (D * D + 1.0);
  const double t = N / chi;
  const double tI = (1.0 - theta) / chi;
  const double tD = (2.0 * theta * D - t * c1) / chi;
  const double tID = -(1.0 - theta) * c1 / (chi * chi);
  const double tDD = (2.0 * theta - 4.0 * theta * D * c1 / chi - t * c2 + 2.0 * t * c1 * c1 / chi) / chi;
  // phi = t^p: phi_a = p t^(p-1) t_a, phi_ab = p t^(p-1) t_ab + p (p-1) t^(p-2) t_a t_b.
  const double tp1 = power == 1.0 ? 1.0 : std::pow(t, power - 1.0);
  const double d1 = power * tp1, d2 = power == 1.0 ? 0.0 : power * (power - 1.0) * tp1 / t;
  const double fI = d1 * tI, fD = d1 * tD;
  const double fII = d2 * tI * tI, fID = d1 * tID + d2 * tI * tD, fDD = d1 * tDD + d2 * tD * tD;
  // To (P, Q): I = P + Q, D = (P - Q) / 2.
  const double fP = fI + 0.5 * fD, fQ = fI - 0.5 * fD;
  const double fPP = fII + fID + 0.25 * fDD, fQQ = fII - fID + 0.25 * fDD, fPQ = fII - 0.25 * fDD;

  SampleTerm out;
  out.value = power == 1.0 ? t : tp1 * t;
  // Gradient: d phi / dz = 2 phi_P z, d phi / dw = 2 phi_Q w, then vec J = E (z, w).
  const Eigen::Vector2d gz = 2.0 * fP * z, gw = 2.0 * fQ * w;
  out.gradient << s2 * (gz[0] + gw[0]), s2 * (-gz[1] + gw[1]), s2 * (gz[1] + gw[1]), s2 * (gz[0] - gw[0]);

  // Eigensystem of H_zw: unit directions (any, where z or w vanishes).
  const double nz = std::sqrt(P), nw = std::sqrt(Q);
  const Eigen::Vector2d zh = nz > 0.0 ? Eigen::Vector2d(z / nz) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d wh = nw > 0.0 ? Eigen::Vector2d(w / nw) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d zp(-zh[1], zh[0]), wp(-wh[1], wh[0]);
  double lz = 2.0 * fP, lw = 2.0 * fQ;                      // twist (z-perp), flip (w-perp)
  double a = 2.0 * fP + 4.0 * fPP * P, c = 2.0 * fQ + 4.0 * fQQ * Q;  // scalings: [[a, b], [b, c]]
  double b = 4.0 * fPQ * nz * nw;                            //   on (zh, 0), (0, wh)
  if (project) {
    lz = std::max(lz, 0.0), lw = std::max(lw, 0.0);
    const double m = 0.5 * (a + c), h = std::hypot(0.5 * (a - c), b);
    const double lp = m + h, lm = m - h;
    if (lp <= 0.0) {
      a = b = c = 0.0;
    } else if (lm < 0.0) {
      // Keep the positive eigenpair only: v v^T lp, v the better conditioned
      // of the two (equivalent) eigenvector formulas.
      Eigen::Vector2d v1(b, lp - a), v2(lp - c, b);
      Eigen::Vector2d v = v1.squaredNorm() >= v2.squaredNorm() ? v1 : v2;
      const double n2 = v.squaredNorm();
      if (n2 > 0.0) {
        v /= std::sqrt(n2);
      } else {
        v = a >= c ? Eigen::Vector2d(1.0, 0.0) : Eigen::Vector2d(0.0, 1.0);
      }
      a = lp * v[0] * v[0], b = lp * v[0] * v[1], c = lp * v[1] * v[1];
    }
  }
  // H_zw in the (z1, z2, w1, w2) coordinates.
  Eigen::Matrix4d Hzw = Eigen::Matrix4d::Zero();
  Hzw.topLeftCorner<2, 2>() = lz * zp * zp.transpose() + a * zh * zh.transpose();
  Hzw.bottomRightCorner<2, 2>() = lw * wp * wp.transpose() + c * wh * wh.transpose();
  Hzw.topRightCorner<2, 2>() = b * zh * wh.transpose();
  Hzw.bottomLeftCorner<2, 2>() = Hzw.topRightCorner<2, 2>().transpose();
  Eigen::Matrix4d E;  // columns e1..e4 in vec J = (J00, J01, J10, J11)
  E << s2, 0, s2, 0,  //
      0, -s2, 0, s2,  //
      0, s2, 0, s2,   //
      s2, 0, -s2, 0;
  out.hessian = E * Hzw * E.transpose();
  return out;
}

void MapEnergy::build_hessian_pattern() const {
  HessianPattern& hp = hpattern_;
  const auto& es = extraction_.elements();
  const std::size_t nodes = free_functions_.size();
  // Node adjacency, lower part (rows i >= column j).
  std::vector<std::vector<int>> col(nodes);
  std::vector<int> fn;
  for (std::size_t k = 0; k < es.size(); ++k) {
    if (!elements_[k].active) continue;
    fn.clear();
    for (int a : es[k].functions)
      if (variable_of_[a] >= 0) fn.push_back(variable_of_[a] / 2);
    for (int j : fn)
      for (int i : fn)
        if (i >= j) col[j].push_back(i);
  }
  for (std::vector<int>& c : col) {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
  }
  // Scalar structure: columns 2j and 2j+1 both hold rows 2i, 2i+1, i in col[j].
  const Eigen::Index n = static_cast<Eigen::Index>(2 * nodes);
  std::size_t nnz = 0;
  for (const std::vector<int>& c : col) nnz += 4 * c.size();
  hp.H = Eigen::SparseMatrix<double>(n, n);
  hp.H.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  int* outer = hp.H.outerIndexPtr();
  int* inner = hp.H.innerIndexPtr();
  double* val = hp.H.valuePtr();
  std::size_t pos = 0;
  for (std::size_t j = 0; j < nodes; ++j)
    for (int d = 0; d < 2; ++d) {
      outer[2 * j + d] = static_cast<int>(pos);
      for (int i : col[j]) {
        inner[pos] = 2 * i, val[pos++] = 0.0;
        inner[pos] = 2 * i + 1, val[pos++] = 0.0;
      }
    }
  outer[n] = static_cast<int>(pos);
  // Slots per element.
  hp.slot_offset.assign(es.size() + 1, 0);
  for (std::size_t k = 0; k < es.size(); ++k) {
    const std::size_t m = es[k].functions.size();
    hp.slot_offset[k + 1] = hp.slot_offset[k] + (elements_[k].active ? m * m : 0);
  }
  hp.slots.assign(hp.slot_offset.back(), -1);
  for (std::size_t k = 0; k < es.size(); ++k) {
    if (!elements_[k].active) continue;
    const std::vector<int>& f = es[k].functions;
    const std::size_t m = f.size();
    for (std::size_t c = 0; c < m; ++c) {
      if (variable_of_[f[c]] < 0) continue;
      const int j = variable_of_[f[c]] / 2;
      for (std::size_t r = 0; r < m; ++r) {
        if (variable_of_[f[r]] < 0) continue;
        const int i = variable_of_[f[r]] / 2;
        if (i < j) continue;
        const auto it = std::lower_bound(col[j].begin(), col[j].end(), i);
        hp.slots[hp.slot_offset[k] + r * m + c] = static_cast<int>(it - col[j].begin());
      }
    }
  }
  // Greedy colouring: elements of one colour share no free function, so that
  // they can be assembled in parallel without conflicts.
  std::vector<std::vector<int>> support(nodes);
  for (std::size_t k = 0; k < es.size(); ++k)
    if (elements_[k].active)
      for (int a : es[k].functions)
        if (variable_of_[a] >= 0) support[variable_of_[a] / 2].push_back(static_cast<int>(k));
  std::vector<int> color(es.size(), -1);
  std::vector<char> used;
  hp.colors.clear();
  for (std::size_t k = 0; k < es.size(); ++k) {
    if (!elements_[k].active) continue;
    used.assign(hp.colors.size() + 1, 0);
    for (int a : es[k].functions)
      if (variable_of_[a] >= 0)
        for (int o : support[variable_of_[a] / 2])
          if (color[o] >= 0) used[color[o]] = 1;
    int cc = 0;
    while (used[cc]) ++cc;
    color[k] = cc;
    if (cc == static_cast<int>(hp.colors.size())) hp.colors.emplace_back();
    hp.colors[cc].push_back(static_cast<int>(k));
  }
  hp.built = true;
}

void MapEnergy::hessian(const double* xv, double eps, Eigen::SparseMatrix<double>& H, double power,
                        bool project) const {
  if (!hpattern_.built) build_hessian_pattern();
  const HessianPattern& hp = hpattern_;
  if (H.rows() != hp.H.rows() || H.nonZeros() != hp.H.nonZeros() || !H.isCompressed())
    H = hp.H;
  else
    std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
  const auto& es = extraction_.elements();
  const double theta = options_.theta;
  const int* outer = H.outerIndexPtr();
  double* val = H.valuePtr();
  using Mat16 = Eigen::Matrix<double, 16, 16>;
  using MatA = Eigen::Matrix<double, 16, Eigen::Dynamic>;
  for (const std::vector<int>& group : hp.colors) {
    detail::parallel_ranges(group.size(), options_.threads, [&](std::size_t b, std::size_t e_end, int) {
      MatA A, Mxx, Mxy, Myy;
      Eigen::MatrixXd Cf, Kxx, Kxy, Kyy;
      std::vector<int> rows;
      Samples s(*this);
      for (std::size_t gi = b; gi < e_end; ++gi) {
        const std::size_t k = static_cast<std::size_t>(group[gi]);
        const BezierElement& e = es[k];
        const Element& d = elements_[k];
        const Level& level = levels_[d.level];
        const detail::TensorGrid& grid = level.grid;
        const Eigen::Index nq = static_cast<Eigen::Index>(level.weight.size());
        std::array<double, 16> X, Y;
        element_coefficients(k, xv, X, Y);
        element_samples(k, X.data(), Y.data(), s);
        A.resize(16, 2 * nq), Mxx.resize(16, 2 * nq), Mxy.resize(16, 2 * nq), Myy.resize(16, 2 * nq);
        for (Eigen::Index q = 0; q < nq; ++q) {
          Eigen::Matrix2d J;
          J << s.J00[q], s.J01[q], s.J10[q], s.J11[q];
          const SampleTerm st = sample_term(J, eps, theta, power, project);
          const Eigen::Matrix4d Hq = (level.weight[q] * d.weight) * st.hessian;
          // J00 = as . X, J01 = at . X, J10 = as . Y, J11 = at . Y (element_samples):
          // as_i = (B_i,s - B_i w_s / w) / (w hx), at_i alike, B_(i1 + 4 j1) = B_i1(s) B_j1(t).
          const double* bp = &grid.b[4 * (q % grid.m)];
          const double* dp = &grid.db[4 * (q % grid.m)];
          const double* br = &grid.b[4 * (q / grid.m)];
          const double* dr = &grid.db[4 * (q / grid.m)];
          const double rw = d.rational ? s.rw[q] : 1.0, rs = d.rational ? s.rs[q] : 0.0;
          const double rt = d.rational ? s.rt[q] : 0.0;
          for (int j1 = 0; j1 < 4; ++j1)
            for (int i1 = 0; i1 < 4; ++i1) {
              const double B = bp[i1] * br[j1];
              A(i1 + 4 * j1, 2 * q) = (dp[i1] * br[j1] - B * rs) * rw / d.hx;
              A(i1 + 4 * j1, 2 * q + 1) = (bp[i1] * dr[j1] - B * rt) * rw / d.hy;
            }
          Mxx.middleCols<2>(2 * q) = A.middleCols<2>(2 * q) * Hq.topLeftCorner<2, 2>();
          Mxy.middleCols<2>(2 * q) = A.middleCols<2>(2 * q) * Hq.topRightCorner<2, 2>();
          Myy.middleCols<2>(2 * q) = A.middleCols<2>(2 * q) * Hq.bottomRightCorner<2, 2>();
        }
        // Bernstein-coefficient blocks (sum over samples of A_q H_q A_q^T).
        const Mat16 Bxx = Mxx * A.transpose(), Bxy = Mxy * A.transpose(), Byy = Myy * A.transpose();
        // To the element's free control points: K = C_f B C_f^T.
        rows.clear();
        for (Eigen::Index r = 0; r < e.C.rows(); ++r)
          if (variable_of_[e.functions[r]] >= 0) rows.push_back(static_cast<int>(r));
        const Eigen::Index nf = static_cast<Eigen::Index>(rows.size());
        Cf.resize(nf, 16);
        for (Eigen::Index r = 0; r < nf; ++r) Cf.row(r) = e.C.row(rows[r]);
        Kxx.noalias() = Cf * Bxx * Cf.transpose();
        Kxy.noalias() = Cf * Bxy * Cf.transpose();
        Kyy.noalias() = Cf * Byy * Cf.transpose();
        const std::size_t m = e.functions.size();
        const int* slot = &hp.slots[hp.slot_offset[k]];
        for (Eigen::Index c = 0; c < nf; ++c) {
          const int j = variable_of_[e.functions[rows[c]]] / 2;
          for (Eigen::Index r = 0; r < nf; ++r) {
            const int sl = slot[rows[r] * m + rows[c]];
            if (sl < 0) continue;
            double* c0 = val + outer[2 * j] + 2 * sl;
            double* c1 = val + outer[2 * j + 1] + 2 * sl;
            c0[0] += Kxx(r, c);  // (x_i, x_j)
            c0[1] += Kxy(c, r);  // (y_i, x_j) = (x_j, y_i)
            c1[0] += Kxy(r, c);  // (x_i, y_j)
            c1[1] += Kyy(r, c);  // (y_i, y_j)
          }
        }
      }
    }, 8);
  }
}


}  // namespace tspline

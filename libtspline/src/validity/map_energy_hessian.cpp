// The Hessian of the map's energy for projected Newton: each sample's 4 x 4
// Hessian in J, projected to positive semi-definite in closed form, and its
// assembly over the free control points; see map_energy.h.
#include "tspline/validity/map_energy.h"
#include "tspline/detail/simd_clones.h"
#include "tspline/detail/thread_pool.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>

#include <Eigen/Dense>

namespace tspline {

namespace {

// The 4 x 4 Hessian in vec J = (J00, J01, J10, J11) of phi(P, Q), P = |z|^2,
// Q = |w|^2 (map_energy.h, top), from phi's derivatives, projected to positive
// semi-definite if `project`; packed upper triangle (00 01 02 03 11 12 13 22 23 33).
// H = E H_zw E^T with H_zw's closed-form eigensystem (Smith et al. 2019):
// H = lz Zp Zp^T + a Zh Zh^T + b (Zh Wh^T + Wh Zh^T) + lw Wp Wp^T + c Wh Wh^T,
// Zh = E_z z/|z|, Zp = E_z z-perp, Wh = E_w w/|w|, Wp = E_w w-perp.
void sample_hessian_packed(double z0, double z1, double w0, double w1, double fP, double fQ, double fPP, double fQQ,
                           double fPQ, bool project, double* h) {
  constexpr double s2 = 0.70710678118654752440;  // 1 / sqrt(2)
  const double P = z0 * z0 + z1 * z1, Q = w0 * w0 + w1 * w1;
  // Unit directions (any, where z or w vanishes).
  const double nz = std::sqrt(P), nw = std::sqrt(Q);
  const double zh0 = nz > 0.0 ? z0 / nz : 1.0, zh1 = nz > 0.0 ? z1 / nz : 0.0;
  const double wh0 = nw > 0.0 ? w0 / nw : 1.0, wh1 = nw > 0.0 ? w1 / nw : 0.0;
  double lz = 2.0 * fP, lw = 2.0 * fQ;                                // twist (z-perp), flip (w-perp)
  double a = 2.0 * fP + 4.0 * fPP * P, c = 2.0 * fQ + 4.0 * fQQ * Q;  // scalings: [[a, b], [b, c]]
  double b = 4.0 * fPQ * nz * nw;                                     //   on (zh, 0), (0, wh)
  if (project) {
    lz = std::max(lz, 0.0), lw = std::max(lw, 0.0);
    const double m = 0.5 * (a + c), hh = std::sqrt(0.25 * (a - c) * (a - c) + b * b);
    const double lp = m + hh, lm = m - hh;
    if (lp <= 0.0) {
      a = b = c = 0.0;
    } else if (lm < 0.0) {
      // Keep the positive eigenpair only: v v^T lp, v the better conditioned
      // of the two (equivalent) eigenvector formulas.
      double v0 = b, v1 = lp - a;
      const double u0 = lp - c, u1 = b;
      if (u0 * u0 + u1 * u1 > v0 * v0 + v1 * v1) v0 = u0, v1 = u1;
      const double n2 = v0 * v0 + v1 * v1;
      if (n2 > 0.0) {
        const double in = 1.0 / std::sqrt(n2);
        v0 *= in, v1 *= in;
      } else {
        v0 = a >= c ? 1.0 : 0.0, v1 = a >= c ? 0.0 : 1.0;
      }
      a = lp * v0 * v0, b = lp * v0 * v1, c = lp * v1 * v1;
    }
  }
  // E_z (v0, v1) = s2 (v0, -v1, v1, v0), E_w (v0, v1) = s2 (v0, v1, v1, -v0).
  const double Zh[4] = {s2 * zh0, -s2 * zh1, s2 * zh1, s2 * zh0};
  const double Zp[4] = {-s2 * zh1, -s2 * zh0, s2 * zh0, -s2 * zh1};  // z-perp = (-zh1, zh0)
  const double Wh[4] = {s2 * wh0, s2 * wh1, s2 * wh1, -s2 * wh0};
  const double Wp[4] = {-s2 * wh1, s2 * wh0, s2 * wh0, s2 * wh1};  // w-perp = (-wh1, wh0)
  int k = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j)
      h[k++] = lz * Zp[i] * Zp[j] + a * Zh[i] * Zh[j] + b * (Zh[i] * Wh[j] + Wh[i] * Zh[j]) + lw * Wp[i] * Wp[j] +
               c * Wh[i] * Wh[j];
}

}  // namespace

namespace {

// phi = t^p of one sample (map_energy.h) and its derivatives in (P, Q).
struct PhiDerivatives {
  double z0, z1, w0, w1;  // conformal and anticonformal parts of J
  double value, fP, fQ, fPP, fQQ, fPQ;
};

PhiDerivatives phi_derivatives(double j00, double j01, double j10, double j11, double eps, double theta,
                               double power) {
  constexpr double s2 = 0.70710678118654752440;  // 1 / sqrt(2)
  PhiDerivatives o;
  // Conformal (z) and anticonformal (w) coordinates of J in the orthonormal
  // basis e1..e4 of map_energy.h: vec J = E (z1, z2, w1, w2).
  o.z0 = s2 * (j00 + j11), o.z1 = s2 * (j10 - j01);
  o.w0 = s2 * (j00 - j11), o.w1 = s2 * (j01 + j10);
  const double D = j00 * j11 - j01 * j10;                    // = (P - Q) / 2, without the cancellation
  const double I = j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11;  // = P + Q
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
  const double tp1 = power == 1.0   ? 1.0
                     : power == 4.0 ? t * t * t
                     : power == 8.0 ? (t * t) * (t * t) * (t * t) * t
                                    : std::pow(t, power - 1.0);
  const double d1 = power * tp1, d2 = power == 1.0 ? 0.0 : power * (power - 1.0) * tp1 / t;
  const double fI = d1 * tI, fD = d1 * tD;
  const double fII = d2 * tI * tI, fID = d1 * tID + d2 * tI * tD, fDD = d1 * tDD + d2 * tD * tD;
  // To (P, Q): I = P + Q, D = (P - Q) / 2.
  o.value = power == 1.0 ? t : tp1 * t;
  o.fP = fI + 0.5 * fD, o.fQ = fI - 0.5 * fD;
  o.fPP = fII + fID + 0.25 * fDD, o.fQQ = fII - fID + 0.25 * fDD, o.fPQ = fII - 0.25 * fDD;
  return o;
}

}  // namespace

SampleTerm sample_term(const Eigen::Matrix2d& J, double eps, double theta, double power, bool project) {
  constexpr double s2 = 0.70710678118654752440;  // 1 / sqrt(2)
  const PhiDerivatives f = phi_derivatives(J(0, 0), J(0, 1), J(1, 0), J(1, 1), eps, theta, power);
  SampleTerm out;
  out.value = f.value;
  // Gradient: d phi / dz = 2 phi_P z, d phi / dw = 2 phi_Q w, then vec J = E (z, w).
  const double gz0 = 2.0 * f.fP * f.z0, gz1 = 2.0 * f.fP * f.z1, gw0 = 2.0 * f.fQ * f.w0, gw1 = 2.0 * f.fQ * f.w1;
  out.gradient << s2 * (gz0 + gw0), s2 * (-gz1 + gw1), s2 * (gz1 + gw1), s2 * (gz0 - gw0);
  double h[10];
  sample_hessian_packed(f.z0, f.z1, f.w0, f.w1, f.fP, f.fQ, f.fPP, f.fQQ, f.fPQ, project, h);
  out.hessian << h[0], h[1], h[2], h[3],  //
      h[1], h[4], h[5], h[6],             //
      h[2], h[5], h[7], h[8],             //
      h[3], h[6], h[8], h[9];
  return out;
}

void MapEnergy::build_hessian_pattern() const {
  HessianPattern& hp = hpattern_;
  const auto& es = extraction_->elements();
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
  hp.max_rows = 0;
  for (const BezierElement& e : es) hp.max_rows = std::max(hp.max_rows, e.functions.size());
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

namespace {

// Sum over an element's samples of A_q H_q A_q^T, the Hessian in the 2 x 16
// Bernstein coefficients (X_i, Y_i): with a_s, a_t (16 each) the derivatives
// of J00 = a_s . X, J01 = a_t . X (and J10, J11 with Y) and h the sample's
// packed 4 x 4 H_q, B_ab[i][j] += a_s[i] (h_(a s)(b s) a_s[j] + h_(a s)(b t) a_t[j])
// + a_t[i] (h_(a t)(b s) a_s[j] + h_(a t)(b t) a_t[j]) for the blocks xx, xy, yy.
TSPLINE_SIMD_CLONES
void bernstein_blocks(std::size_t nq, const double* __restrict as, const double* __restrict at,
                      const double* __restrict h, double* __restrict Bxx, double* __restrict Bxy,
                      double* __restrict Byy) {
  for (int i = 0; i < 256; ++i) Bxx[i] = Bxy[i] = Byy[i] = 0.0;
  for (std::size_t q = 0; q < nq; ++q) {
    const double* s = as + 16 * q;
    const double* t = at + 16 * q;
    const double* hq = h + 10 * q;  // 00 01 02 03 11 12 13 22 23 33
    double u[6][16];
    for (int j = 0; j < 16; ++j) {
      u[0][j] = hq[0] * s[j] + hq[1] * t[j];  // xx: row s
      u[1][j] = hq[1] * s[j] + hq[4] * t[j];  // xx: row t
      u[2][j] = hq[2] * s[j] + hq[3] * t[j];  // xy: row s
      u[3][j] = hq[5] * s[j] + hq[6] * t[j];  // xy: row t
      u[4][j] = hq[7] * s[j] + hq[8] * t[j];  // yy: row s
      u[5][j] = hq[8] * s[j] + hq[9] * t[j];  // yy: row t
    }
    for (int i = 0; i < 16; ++i) {
      const double si = s[i], ti = t[i];
      double* bxx = Bxx + 16 * i;
      double* bxy = Bxy + 16 * i;
      double* byy = Byy + 16 * i;
      for (int j = 0; j < 16; ++j) {
        bxx[j] += si * u[0][j] + ti * u[1][j];
        bxy[j] += si * u[2][j] + ti * u[3][j];
        byy[j] += si * u[4][j] + ti * u[5][j];
      }
    }
  }
}

// K = C B C^T for the three blocks, C the nf x 16 rows of the element's free
// functions and Ct its transpose, 16 x ld (ld >= nf, a multiple of 4, the
// columns past nf zero); K row-major nf x ld, T holds 16 nf values. Both
// products are sums of rows scaled by a number (T_r = sum_i C_ri B_i, then
// K_r = sum_j T_rj Ct_j), in four-double vectors along the rows: written as
// plain loops GCC 12 vectorized them across the rows instead, transposing B
// with shuffles (four times the time of the Bernstein blocks).
TSPLINE_SIMD_CLONES
void project_blocks(int nf, int ld, const double* __restrict C, const double* __restrict Ct,
                    const double* const* B, double* const* K, double* __restrict T) {
  typedef double v4d __attribute__((vector_size(32)));
  for (int blk = 0; blk < 3; ++blk) {
    const double* __restrict Bb = B[blk];
    for (int r = 0; r < nf; ++r) {
      v4d acc[4] = {};
      for (int i = 0; i < 16; ++i) {
        const double c = C[16 * r + i];
        for (int q = 0; q < 4; ++q) {
          v4d b;
          __builtin_memcpy(&b, Bb + 16 * i + 4 * q, sizeof b);
          acc[q] += c * b;
        }
      }
      __builtin_memcpy(T + 16 * r, acc, sizeof acc);
    }
    double* __restrict Kb = K[blk];
    for (int r = 0; r < nf; ++r) {
      const double* tr = T + 16 * r;
      for (int c = 0; c < ld; c += 4) {
        v4d acc = {};
        for (int j = 0; j < 16; ++j) {
          v4d x;
          __builtin_memcpy(&x, Ct + static_cast<std::ptrdiff_t>(ld) * j + c, sizeof x);
          acc += tr[j] * x;
        }
        __builtin_memcpy(Kb + static_cast<std::ptrdiff_t>(ld) * r + c, &acc, sizeof acc);
      }
    }
  }
}

}  // namespace

void MapEnergy::hessian(const double* xv, double eps, Eigen::SparseMatrix<double>& H, double power,
                        bool project) const {
  if (!hpattern_.built) build_hessian_pattern();
  const HessianPattern& hp = hpattern_;
  if (H.rows() != hp.H.rows() || H.nonZeros() != hp.H.nonZeros() || !H.isCompressed())
    H = hp.H;
  else
    std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
  const auto& es = extraction_->elements();
  const double theta = options_.theta;
  const int* outer = H.outerIndexPtr();
  double* val = H.valuePtr();
  // Each slot's buffers, made once per call by the first range that runs on
  // it (one call has a range per colour and slot: with the buffers made per
  // range, zeroing them was more than the assembly of a small patch).
  const int finest = finest_active_level();
  const std::size_t max_points = levels_[static_cast<std::size_t>(finest)].grid.size();
  const std::size_t mr = hp.max_rows;
  struct Work {
    Work(const MapEnergy& energy, int level, std::size_t points, std::size_t rows)
        : s(energy, level),
          as(16 * points),
          at(16 * points),
          h(10 * points),
          Bbuf(3 * 256),
          C(16 * rows),
          Ct(16 * padded(rows)),
          T(16 * rows),
          Kbuf(3 * rows * padded(rows)),
          rows(rows) {}
    static std::size_t padded(std::size_t n) { return (n + 3) / 4 * 4; }
    Samples s;
    std::vector<double> as, at, h, Bbuf, C, Ct, T, Kbuf;
    std::vector<int> rows;
  };
  std::vector<std::optional<Work>> work(static_cast<std::size_t>(std::max(1, detail::pool_threads())));
  for (const std::vector<int>& group : hp.colors) {
    detail::parallel_ranges(
        group.size(), options_.threads,
        [&](std::size_t b, std::size_t e_end, int slot) {
          std::optional<Work>& w = work[static_cast<std::size_t>(slot)];
          if (!w) w.emplace(*this, finest, max_points, mr);
          Samples& s = w->s;
          std::vector<double>&as = w->as, &at = w->at, &h = w->h, &Bbuf = w->Bbuf, &C = w->C, &T = w->T;
          const double* Bp[3] = {Bbuf.data(), Bbuf.data() + 256, Bbuf.data() + 512};
          const std::size_t kb = mr * Work::padded(mr);
          double* Kp[3] = {w->Kbuf.data(), w->Kbuf.data() + kb, w->Kbuf.data() + 2 * kb};
          double* Ct = w->Ct.data();
          std::vector<int>& rows = w->rows;
          for (std::size_t gi = b; gi < e_end; ++gi) {
            const std::size_t k = static_cast<std::size_t>(group[gi]);
            const BezierElement& e = es[k];
            const Element& d = elements_[k];
            const Level& level = levels_[d.level];
            const detail::TensorGrid& grid = level.grid;
            const std::size_t nq = level.weight.size();
            std::array<double, 16> X, Y;
            element_coefficients(k, xv, X, Y);
            element_samples(k, X.data(), Y.data(), s);
            const double ihx = 1.0 / d.hx, ihy = 1.0 / d.hy;
            for (std::size_t q = 0; q < nq; ++q) {
              const PhiDerivatives f =
                  phi_derivatives(s.J00[q], s.J01[q], s.J10[q], s.J11[q], eps, theta, power);
              double* hq = &h[10 * q];
              sample_hessian_packed(f.z0, f.z1, f.w0, f.w1, f.fP, f.fQ, f.fPP, f.fQQ, f.fPQ, project, hq);
              const double omega = level.weight[q] * d.weight;
              for (int i = 0; i < 10; ++i) hq[i] *= omega;
              // J00 = a_s . X, J01 = a_t . X (element_samples): a_s = (B_s - B w_s / w) / (w hx),
              // a_t alike, B_(i1 + 4 j1) = B_i1(s) B_j1(t).
              const double* bp = &grid.b[4 * (q % grid.m)];
              const double* dp = &grid.db[4 * (q % grid.m)];
              const double* br = &grid.b[4 * (q / grid.m)];
              const double* dr = &grid.db[4 * (q / grid.m)];
              const double rw = d.rational ? s.rw[q] : 1.0, rs = d.rational ? s.rs[q] : 0.0;
              const double rt = d.rational ? s.rt[q] : 0.0;
              double* aq = &as[16 * q];
              double* tq = &at[16 * q];
              for (int j1 = 0; j1 < 4; ++j1)
                for (int i1 = 0; i1 < 4; ++i1) {
                  const double B = bp[i1] * br[j1];
                  aq[i1 + 4 * j1] = (dp[i1] * br[j1] - B * rs) * rw * ihx;
                  tq[i1 + 4 * j1] = (bp[i1] * dr[j1] - B * rt) * rw * ihy;
                }
            }
            bernstein_blocks(nq, as.data(), at.data(), h.data(), Bbuf.data(), Bbuf.data() + 256,
                             Bbuf.data() + 512);
            // To the element's free control points: K = C_f B C_f^T.
            int nf = 0;
            for (Eigen::Index r = 0; r < e.C.rows(); ++r)
              if (variable_of_[e.functions[r]] >= 0) rows[nf++] = static_cast<int>(r);
            const int ld = static_cast<int>(Work::padded(static_cast<std::size_t>(nf)));
            for (int r = 0; r < nf; ++r)
              for (int i = 0; i < 16; ++i) C[16 * r + i] = Ct[ld * i + r] = e.C(rows[r], i);
            for (int i = 0; i < 16; ++i)
              for (int r = nf; r < ld; ++r) Ct[ld * i + r] = 0.0;
            project_blocks(nf, ld, C.data(), Ct, Bp, Kp, T.data());
            const double* Kxx = Kp[0];
            const double* Kxy = Kp[1];
            const double* Kyy = Kp[2];
            const std::size_t m = e.functions.size();
            const int* slot = &hp.slots[hp.slot_offset[k]];
            for (int c = 0; c < nf; ++c) {
              const int j = variable_of_[e.functions[rows[c]]] / 2;
              for (int r = 0; r < nf; ++r) {
                const int sl = slot[rows[r] * m + rows[c]];
                if (sl < 0) continue;
                double* c0 = val + outer[2 * j] + 2 * sl;
                double* c1 = val + outer[2 * j + 1] + 2 * sl;
                c0[0] += Kxx[ld * r + c];  // (x_i, x_j)
                c0[1] += Kxy[ld * c + r];  // (y_i, x_j) = (x_j, y_i)
                c1[0] += Kxy[ld * r + c];  // (x_i, y_j)
                c1[1] += Kyy[ld * r + c];  // (y_i, y_j)
              }
            }
          }
        },
        8);
  }
}

}  // namespace tspline

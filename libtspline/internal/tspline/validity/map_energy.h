#pragma once
// Internal (not installed): the options are map_energy_options.h.
// The distortion energy of a T-spline map as a function of its free control
// points, for the global untangling and smoothing of the map itself
// (map_untangling.h).
//
// The energy is the regularized one of Garanzha, Kaporin, Kudryavtseva,
// Protais, Ray, Sokolov, "Foldover-free maps in 50 lines of code", ACM TOG
// 40(4), 2021 (Eqs. 2-4 there), summed over sample points q of the Bezier
// elements of the map (bezier_extraction.h):
//
//   E_eps = sum_q w_q [ (1 - theta) |J_q|_F^2 + theta (det J_q^2 + 1) ] / chi(det J_q, eps),
//   chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2,
//
// with J_q = dS/d(xi, eta) / L, L^2 the area of the domain, so that the ideal
// element is the parametric square scaled to the domain's area and det J = 1
// on average. chi > 0 for every D, so E_eps is defined and smooth on tangled
// maps; as eps -> 0, chi -> max(D, 0) and the first term tends to 2 / J_r
// (J_r = 2 det J / |J|^2, the mean ratio of Brovka 2013 Eq. 9) on valid
// points and to +infinity on folded ones: the same regularization as the K*
// objective of Brovka Sect. 4 with h(sigma). The second term (theta = 1/128
// as in the paper) keeps the element areas from collapsing.
//
// Samples: on every element, n x n Gauss-Lobatto (or Gauss) points on each of 2^l x 2^l equal
// sub-squares (sample level l, per element; raised where a certificate fails,
// so that the energy sees a fold between the samples of level 0). The weight
// w_q is the Gauss weight times the sub-square's share of the element times
// the element weight: its parametric area (the energy approximates an
// integral over [0,1]^2) or 1 for every element (every element counts
// equally, like the cells of the T-mesh objective; the default, see below).
//
// Free variables: the control points of the functions that vanish on the
// border of [0,1]^2 (touches_border is false), in normalized coordinates
// (P - centre) / L; the border control points define the boundary curve and
// stay fixed.
//
// On an element the map is S = X / w with X = sum_a P_a N_a and w = sum_a N_a
// in Bernstein form (X_k = sum_r P_r C(r, k)), so the energy and its exact
// gradient cost O(samples x 16 + functions x 16) per element, without storing
// basis values per sample.
//
// Hessian (projected Newton). On a sample J is linear in the control
// points (J = dS/d(xi, eta), S = X / w, w independent of them), so the
// sample's Hessian over the element's control points is A^T H_J A with A the
// 4 x (2 n) map from control points to vec J and H_J the 4 x 4 Hessian of the
// sample's term with respect to J (sample_term below). The term is isotropic:
// with J = z1 e1 + z2 e2 + w1 e3 + w2 e4 in the orthonormal basis
// e1 = I/sqrt2, e2 = [[0,-1],[1,0]]/sqrt2 (conformal part z), e3 = [[1,0],[0,-1]]/sqrt2,
// e4 = [[0,1],[1,0]]/sqrt2 (anticonformal part w), |J|^2 = P + Q and
// det J = (P - Q) / 2 with P = |z|^2, Q = |w|^2, so the term is phi(P, Q) and
//   H_zw = 2 phi_P I_z (+) 2 phi_Q I_w + 4 [phi_PP z z^T, phi_PQ z w^T; phi_PQ w z^T, phi_QQ w w^T],
// whose eigenvectors are known in closed form: z-perp (eigenvalue 2 phi_P),
// w-perp (2 phi_Q), and two in the plane of (z/|z|, 0), (0, w/|w|) from a 2 x 2
// matrix. These are the analytic eigensystems of Smith, De Goes & Kim,
// "Analytic eigensystems for isotropic distortion energies", ACM TOG 38(1),
// 2019 (twist = z-perp, flip = w-perp, two scalings), written in the
// conformal/anticonformal split; clamping the eigenvalues at 0 (Teran,
// Sifakis, Irving & Fedkiw, SCA 2005) gives the projected H_J, positive
// semi-definite, and equal to the exact one where that already is.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstddef>
#include <optional>
#include <vector>

#include "tspline/detail/tensor_grid.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/tspline_map.h"
#include "tspline/validity/map_energy_options.h"

namespace tspline {

class MapEnergy {
 public:
  /// \throw InputError for options out of range or a map whose
  /// domain has no positive area.
  /// `extraction`: the Bezier extraction of the map's basis, made by the
  /// caller and outliving this (shared with its other checks); nullptr: made here.
  MapEnergy(const TSplineMap& map, const MapEnergyOptions& options = {},
            const BezierExtraction* extraction = nullptr);
  MapEnergy(const MapEnergy&) = delete;  // (extraction_ may point into this)
  MapEnergy& operator=(const MapEnergy&) = delete;

  std::size_t num_variables() const { return 2 * free_functions_.size(); }
  /// Indices (into the basis) of the functions whose control points are free.
  const std::vector<int>& free_functions() const { return free_functions_; }
  std::size_t num_elements() const { return elements_.size(); }
  /// Does element k touch a free control point (else the energy leaves it out)?
  bool element_active(std::size_t k) const { return elements_[k].active; }
  const BezierExtraction& extraction() const { return *extraction_; }
  double length_scale() const { return L_; }

  /// The free coordinates of `map` (same basis as at construction), normalized.
  Eigen::VectorXd variables(const TSplineMap& map) const;
  /// All control points with the free ones taken from x.
  std::vector<Eigen::Vector2d> control_points(const double* x) const;

  /// E_eps at x; if gradient is not null, also dE/dx (num_variables() values);
  /// if nonpositive is not null, the number of samples with det J <= 0.
  /// With power p != 1 each sample's term is raised to p (sum_q w_q term_q^p):
  /// p > 1 weighs the worst samples more, raising the minimum J_r rather than the mean.
  double evaluate(const double* x, double eps, double* gradient, std::size_t* nonpositive = nullptr,
                  double power = 1.0) const;
  SampleStats stats(const double* x) const;

  /// The Hessian of evaluate(x, eps, ..., power) with respect to x, each
  /// sample's 4 x 4 Hessian in J projected to positive semi-definite if
  /// `project` (map_energy.h, top). H gets the sparsity pattern of the
  /// Bezier extraction (computed once per MapEnergy, i.e. per T-mesh: H's
  /// structure is the same on every call) and holds the LOWER triangle: per
  /// column pair (2j, 2j+1) of a control point the rows 2i, 2i+1 of the
  /// points i >= j that share an element with it; the one entry (2j, 2j+1)
  /// above the diagonal is stored too, with its value. Read H as
  /// H.selfadjointView<Eigen::Lower>() (CHOLMOD with stype -1 does).
  /// Not thread-safe on its first call (the pattern is built then).
  void hessian(const double* x, double eps, Eigen::SparseMatrix<double>& H, double power = 1.0,
               bool project = true) const;
  /// Largest a in (0, a_max] such that every sample with det J > 0 at x has
  /// det J > 0 at x + t d for all t in [0, a] (det J along the line is a
  /// quadratic in t: J is linear in x), times `safety`; a_max if none ever
  /// turns non-positive.
  double max_positive_step(const double* x, const double* d, double a_max, double safety = 0.9) const;

  int sample_level(std::size_t element) const { return elements_[element].level; }
  /// \pre 0 <= level <= max_sample_level.
  void set_sample_level(std::size_t element, int level);
  int max_sample_level() const { return options_.max_sample_level; }
  std::size_t num_samples() const;

 private:
  // Per-thread buffers for one element's samples (element_samples), sized
  // for sample level `level` (a finer element's samples do not fit).
  struct Samples {
    Samples(const MapEnergy& energy, int level);
    // At the samples: X, Y and their derivatives in the local (s, t), then
    // (after element_samples) the adjoints of evaluate's gradient in place.
    std::vector<double> x, xs, xt, y, ys, yt;
    std::vector<double> rw, rs, rt;          // rational elements: 1 / w, w_s / w, w_t / w
    std::vector<double> J00, J01, J10, J11;  // the Jacobian in normalized coordinates
    std::vector<double> term;                // evaluate: each sample's weighted term
    std::vector<double> scratch;             // tensor_values
  };
  struct Level {  // the samples of one sample level on the unit square
    detail::TensorGrid grid;     // (n 2^l)^2 points: n x n on each of 2^l x 2^l sub-squares
    std::vector<double> weight;  // per point, sums to 1
  };
  struct Element {
    std::array<double, 16> W{};  // Bernstein coefficients of w = sum_a N_a
    bool rational = false;       // w is not 1 (the functions are not a partition of unity here)
    double hx = 1.0, hy = 1.0;   // parametric size
    double weight = 1.0;
    int level = 0;
    bool active = true;  // touches a variable (else constant: left out)
  };
  struct HessianPattern {
    Eigen::SparseMatrix<double> H;          // the structure, values 0
    std::vector<std::size_t> slot_offset;   // per element: start of its n x n slots
    std::vector<int> slots;                 // (r, c): position of node(r) in node column node(c), -1 if above
    std::vector<std::vector<int>> colors;   // elements in groups sharing no free function
    std::size_t max_rows = 0;               // functions per element at most
    bool built = false;
  };
  void build_hessian_pattern() const;
  // A sample level no element is finer than (the finest set so): what a pass
  // over the elements needs of its Samples (the finest level possible,
  // max_sample_level, has 1,600 points: zeroing buffers that large for every
  // range of every call cost more than a small patch's evaluation).
  int finest_active_level() const { return finest_level_; }
  // X and Y Bernstein coefficients of element k at the variables x.
  void element_coefficients(std::size_t k, const double* x, std::array<double, 16>& X,
                            std::array<double, 16>& Y) const;
  // The Jacobian J at every sample of element k (its level) of the map whose
  // Bernstein coefficients on k are X, Y: s.J00 ... s.J11, and s.x ... s.yt,
  // s.rw, s.rs, s.rt for the chain rule. Linear in (X, Y).
  void element_samples(std::size_t k, const double* X, const double* Y, Samples& s) const;

  MapEnergyOptions options_;
  std::optional<BezierExtraction> own_extraction_;  // where the caller gave none
  const BezierExtraction* extraction_;
  std::vector<Element> elements_;
  std::vector<int> active_;  // the elements that touch a variable, in order
  std::vector<Level> levels_;
  int finest_level_ = 0;                     // at least every element's level
  std::vector<int> variable_of_;             // per function: index of its x coordinate, or -1
  std::vector<int> free_functions_;
  std::vector<Eigen::Vector2d> normalized_;  // all control points, normalized
  std::vector<Eigen::Vector2d> original_;    // as given (the fixed ones are returned exactly)
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  double L_ = 1.0;
  mutable HessianPattern hpattern_;
};

/// chi(D, eps) of the header, evaluated without cancellation for D < 0.
double regularized_det(double D, double eps);

/// One sample's term phi(J) = t(J)^p with t = [(1 - theta) |J|^2 + theta (det J^2 + 1)] / chi(det J, eps),
/// its gradient and its Hessian with respect to vec J = (J00, J01, J10, J11) (row-major),
/// the Hessian projected to positive semi-definite if `project` (header, top).
struct SampleTerm {
  double value = 0.0;
  Eigen::Vector4d gradient = Eigen::Vector4d::Zero();
  Eigen::Matrix4d hessian = Eigen::Matrix4d::Zero();
};
SampleTerm sample_term(const Eigen::Matrix2d& J, double eps, double theta, double power, bool project);

}  // namespace tspline

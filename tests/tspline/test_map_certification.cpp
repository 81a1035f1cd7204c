// Certified validity (map_certification.h): Bernstein arithmetic against direct
// evaluation, the (8,8) numerator against det J of the map, a map folded between
// the Gauss points found invalid, a distorted square certified, the undecided
// outcome, agreement with dense sampling (50 x 50 per element) on the test
// domains, and the parallel whole-map certification (and on a subset of the
// elements) against element-by-element certification.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <random>

#include "perturbed_map.h"
#include "separable_maps.h"
#include "test_support.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/io/polygon_reader.h"
#include "tspline/detail/bernstein.h"
#include "tspline/detail/element_jacobian.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"

using test_support::separable_cubic_map;
using tspline::detail::BernsteinPoly;
using tspline::BezierElement;
using tspline::ElementStatus;
using tspline::TMesh;
using tspline::TSplineMap;

namespace {

BernsteinPoly random_poly(int m, int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BernsteinPoly p(m, n);
  for (int k = 0; k < p.size(); ++k) p.c[k] = u(rng);
  return p;
}


// Dense sampling of det J on every element: a k x k grid including the
// element's edges and corners. det J is evaluated directly from the B-splines
// (cubic_bspline), independently of the Bernstein form: on the grid the sums
// X = sum_a P_a N_a(u) M_a(v), w = sum_a N_a(u) M_a(v) and their derivatives are
// matrix products (N diag(P) M^T), and S = X / w gives
// det J = det(X_u w - X w_u, X_v w - X w_v) / w^4.
struct SampledElement {
  BezierElement e;
  double min_det;
  Eigen::Vector2d at;
};
std::vector<SampledElement> sample_elements(const TSplineMap& map, int k) {
  using Mat = Eigen::MatrixXd;
  std::vector<SampledElement> out;
  const tspline::TSplineBasis& basis = map.basis();
  for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c)
    for (BezierElement& e : tspline::extract_cell(basis, c)) {
      SampledElement s{std::move(e), std::numeric_limits<double>::infinity(), {}};
      const std::vector<int>& fs = basis.functions_on_cell(c);
      const Eigen::Index nf = static_cast<Eigen::Index>(fs.size());
      Mat Nu(k, nf), Du(k, nf), Nv(k, nf), Dv(k, nf);
      Eigen::VectorXd px(nf), py(nf);
      std::vector<double> u(k), v(k);
      for (int i = 0; i < k; ++i) {
        u[i] = s.e.lo.x() + i * (s.e.hi.x() - s.e.lo.x()) / (k - 1);
        v[i] = s.e.lo.y() + i * (s.e.hi.y() - s.e.lo.y()) / (k - 1);
      }
      for (Eigen::Index a = 0; a < nf; ++a) {
        const tspline::BlendingFunction& f = basis.function(fs[a]);
        px[a] = map.control_points()[fs[a]].x();
        py[a] = map.control_points()[fs[a]].y();
        for (int i = 0; i < k; ++i) {
          Nu(i, a) = tspline::cubic_bspline(f.knots_xi, u[i], &Du(i, a));
          Nv(i, a) = tspline::cubic_bspline(f.knots_eta, v[i], &Dv(i, a));
        }
      }
      const Mat W = Nu * Nv.transpose(), Wu = Du * Nv.transpose(), Wv = Nu * Dv.transpose();
      const Mat X = Nu * px.asDiagonal() * Nv.transpose(), Xu = Du * px.asDiagonal() * Nv.transpose(),
                Xv = Nu * px.asDiagonal() * Dv.transpose();
      const Mat Y = Nu * py.asDiagonal() * Nv.transpose(), Yu = Du * py.asDiagonal() * Nv.transpose(),
                Yv = Nu * py.asDiagonal() * Dv.transpose();
      for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
          const double w = W(i, j);
          const double su_x = Xu(i, j) * w - X(i, j) * Wu(i, j), su_y = Yu(i, j) * w - Y(i, j) * Wu(i, j);
          const double sv_x = Xv(i, j) * w - X(i, j) * Wv(i, j), sv_y = Yv(i, j) * w - Y(i, j) * Wv(i, j);
          const double d = (su_x * sv_y - su_y * sv_x) / (w * w * w * w);
          if (d < s.min_det) s.min_det = d, s.at = {u[i], v[j]};
        }
      // The sampler itself against the map's own evaluation at the minimum.
      CHECK(s.min_det == doctest::Approx(map.derivatives(s.at, 1, c).J.determinant()).epsilon(1e-9));
      out.push_back(std::move(s));
    }
  return out;
}

// Certification agrees with dense sampling element by element: certified =>
// no sampled negative, and the certified lower bound is below every sample;
// a sampled negative => proven invalid; proven invalid => det J < 0 at the
// reported point (direct evaluation). Returns the number of elements.
std::size_t check_agreement(const TSplineMap& map, int k, std::size_t* sampled_negative = nullptr,
                            std::size_t* proven_invalid = nullptr) {
  const std::vector<SampledElement> samples = sample_elements(map, k);
  std::size_t negatives = 0, certified = 0, invalid = 0;
  for (const SampledElement& s : samples) {
    const tspline::ElementCertificate cert = tspline::certify_element(s.e, map.control_points());
    CAPTURE(s.e.cell);
    // A bound in exact arithmetic: allow round-off where det J is constant.
    CHECK(cert.det_lower_bound <= s.min_det + 1e-9 * std::abs(s.min_det));
    if (cert.status == ElementStatus::Certified) {
      ++certified;
      CHECK(s.min_det > 0.0);
    }
    if (s.min_det < 0.0) {
      ++negatives;
      CHECK(cert.status == ElementStatus::Invalid);
    }
    if (cert.status == ElementStatus::Invalid) {
      ++invalid;
      const Eigen::Vector2d& at = cert.negative_at;
      CHECK(at.x() >= s.e.lo.x());
      CHECK(at.x() <= s.e.hi.x());
      CHECK(at.y() >= s.e.lo.y());
      CHECK(at.y() <= s.e.hi.y());
      CHECK(map.derivatives(at, 1, s.e.cell).J.determinant() < 0.0);
    }
  }
  if (sampled_negative) *sampled_negative = negatives;
  if (proven_invalid) *proven_invalid = invalid;
  const tspline::MapCertification mc = tspline::certify_map(map);
  CHECK(mc.elements == samples.size());
  CHECK(mc.certified == certified);
  CHECK(mc.certified_valid() == (certified == samples.size()));
  return samples.size();
}

// Runs the parameterization of each domain with default options and checks the
// agreement on the map of every adaptive iteration; the final map must be
// certified. Returns the number of elements proven invalid (all iterations).
std::size_t domain_agreement(const std::vector<std::string>& names) {
  std::size_t total_invalid = 0;
  for (const std::string& name : names) {
    CAPTURE(name);
    const auto poly = tspline::io::read_polygon(test_support::polygon_file(name));
    std::size_t elements = 0, negatives = 0, invalid = 0;
    const tspline::ParameterizationResult r = tspline::run_parameterization(
        poly, {}, {},
        [&](int, const TMesh&, const std::vector<Eigen::Vector2d>&, const TSplineMap& map,
            const std::vector<tspline::CellMapQuality>&) {
          std::size_t neg = 0, inv = 0;
          elements += check_agreement(map, 50, &neg, &inv);
          negatives += neg;
          invalid += inv;
        });
    CHECK(r.certified_valid());
    MESSAGE(name << ": " << r.iterations.size() << " iterations, " << elements << " elements sampled, "
                 << negatives << " with a sampled det J < 0, " << invalid << " proven invalid");
    total_invalid += invalid;
  }
  return total_invalid;
}

}  // namespace

TEST_SUITE("map_certification") {
  TEST_CASE("Bernstein product, derivatives and subdivision agree with direct evaluation") {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
      const BernsteinPoly a = random_poly(3, 2, rng), b = random_poly(5, 6, rng);
      const BernsteinPoly ab = tspline::detail::bernstein_product(a, b);
      REQUIRE(ab.m == 8);
      REQUIRE(ab.n == 8);
      const BernsteinPoly as = tspline::detail::bernstein_ds(a), at = tspline::detail::bernstein_dt(a);
      const auto quarters = tspline::detail::bernstein_subdivide(b);
      for (int k = 0; k < 10; ++k) {
        const double s = u01(rng), t = u01(rng);
        CHECK(ab(s, t) == doctest::Approx(a(s, t) * b(s, t)).epsilon(1e-12));
        const double h = 1e-6;
        CHECK(as(s, t) == doctest::Approx((a(s + h, t) - a(s - h, t)) / (2 * h)).epsilon(1e-7));
        CHECK(at(s, t) == doctest::Approx((a(s, t + h) - a(s, t - h)) / (2 * h)).epsilon(1e-7));
        CHECK(quarters[0](s, t) == doctest::Approx(b(0.5 * s, 0.5 * t)).epsilon(1e-12));
        CHECK(quarters[1](s, t) == doctest::Approx(b(0.5 + 0.5 * s, 0.5 * t)).epsilon(1e-12));
        CHECK(quarters[2](s, t) == doctest::Approx(b(0.5 * s, 0.5 + 0.5 * t)).epsilon(1e-12));
        CHECK(quarters[3](s, t) == doctest::Approx(b(0.5 + 0.5 * s, 0.5 + 0.5 * t)).epsilon(1e-12));
      }
      // The corner coefficients are the corner values.
      CHECK(b.at(0, 0) == doctest::Approx(b(0, 0)).epsilon(1e-14));
      CHECK(b.at(5, 6) == doctest::Approx(b(1, 1)).epsilon(1e-14));
    }
  }

  TEST_CASE(
      "the (8,8) numerator D / w^3 is det J of the map at random points (T-mesh with hanging vertices)") {
    for (unsigned seed : {2u, 9u}) {
      TSplineMap map = tspline::greville_identity_map(test_support::random_leaf_splits(2, 10, seed));
      REQUIRE(map.mesh().num_hanging_vertices() > 0);
      std::vector<Eigen::Vector2d> P = map.control_points();
      // A nonlinear map far from the origin (the element centres the control points).
      for (Eigen::Vector2d& p : P)
        p = Eigen::Vector2d(1e4 + 3.0 * p.x() + 0.4 * std::sin(4.0 * p.y()),
                            -2e3 + p.y() + 0.3 * p.x() * p.y());
      map.set_control_points(P);
      std::mt19937 rng(seed);
      std::uniform_real_distribution<double> u01(0.0, 1.0);
      double max_rel = 0.0;
      int split = 0;
      for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c) {
        const auto es = tspline::extract_cell(map.basis(), c);
        if (es.size() > 1) ++split;
        for (const BezierElement& e : es) {
          const tspline::detail::ElementJacobian J = tspline::detail::element_jacobian(e, map.control_points());
          CHECK(J.numerator.m == 8);
          CHECK(J.numerator.n == 8);
          for (int k = 0; k < 5; ++k) {
            const double s = u01(rng), t = u01(rng);
            const Eigen::Vector2d uv(e.lo.x() + s * (e.hi.x() - e.lo.x()),
                                     e.lo.y() + t * (e.hi.y() - e.lo.y()));
            const double direct = map.derivatives(uv, 1, c).J.determinant();
            max_rel = std::max(max_rel, std::abs(J.det_param(e, s, t) - direct) / std::abs(direct));
          }
        }
      }
      CHECK(split > 0);
      CHECK(max_rel < 1e-10);
    }
  }

  TEST_CASE("a map folded between the 16 Gauss points is proven invalid, at the fold") {
    // S = (x(xi), eta), det J = x' < 0 exactly in the strip |xi - 1/2| < 0.1 (separable_maps.h).
    const TSplineMap map = test_support::fold_between_gauss_points();
    const tspline::MapQualityStats q = tspline::map_quality(map, 4);
    CHECK(q.nonpositive_det == 0);
    CHECK(q.min_det > 0.5);
    // The map is what it should be.
    CHECK(map.jacobian({0.5, 0.3}).determinant() == doctest::Approx(-0.3).epsilon(1e-12));
    const tspline::MapCertification mc = tspline::certify_map(map);
    CHECK(mc.elements == 1);
    CHECK_FALSE(mc.certified_valid());
    CHECK(mc.invalid == 1);
    REQUIRE(mc.failures.size() == 1);
    const tspline::ElementCertificate& cert = mc.failures[0].certificate;
    CHECK(cert.status == ElementStatus::Invalid);
    CHECK(std::abs(cert.negative_at.x() - 0.5) < 0.1);
    CHECK(cert.negative_det < 0.0);
    CHECK(cert.negative_det == doctest::Approx(map.jacobian(cert.negative_at).determinant()).epsilon(1e-10));
    CHECK(mc.cell_certified[0] == 0);
    CHECK(cert.det_lower_bound <= -0.3);
    // The same fold inside one cell of a finer mesh: only that cell fails.
    // x'(xi) = 120 (xi - 1/4)^2 - 0.3 on [0, 1/2]: negative for |xi - 1/4| < 0.05.
    const TSplineMap fine =
        separable_cubic_map(test_support::uniform_mesh(1),
                            {-0.25 * 0.25 * 0.25 * 40.0, 7.5 - 0.3, -30.0, 40.0}, {0.0, 1.0, 0.0, 0.0});
    CHECK(tspline::map_quality(fine, 4).nonpositive_det == 0);
    const tspline::MapCertification mf = tspline::certify_map(fine);
    CHECK(mf.elements == 4);
    CHECK(mf.invalid == 2);  // the two cells of the strip xi in [0, 1/2]
    for (const auto& f : mf.failures) CHECK(std::abs(f.certificate.negative_at.x() - 0.25) < 0.05);
  }

  TEST_CASE("a slightly distorted square is certified, with a lower bound below every sample") {
    TSplineMap map = tspline::greville_identity_map(test_support::uniform_mesh(2));
    std::vector<Eigen::Vector2d> P = map.control_points();
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-0.03, 0.03);
    for (std::size_t a = 0; a < P.size(); ++a)
      if (P[a].x() > 0.0 && P[a].x() < 1.0 && P[a].y() > 0.0 && P[a].y() < 1.0)
        P[a] += Eigen::Vector2d(u(rng), u(rng));
    map.set_control_points(P);
    const tspline::MapCertification mc = tspline::certify_map(map);
    CHECK(mc.elements == 16);
    CHECK(mc.certified_valid());
    CHECK(mc.failures.empty());
    CHECK(mc.min_relative_lower_bound > 0.0);
    CHECK(mc.min_relative_lower_bound <= 1.0);
    CHECK(mc.min_det_lower_bound > 0.0);
    for (char ok : mc.cell_certified) CHECK(ok == 1);
    // The bounds per cell: the minimum of its elements' certificates, and
    // their minimum the map's.
    const tspline::BezierExtraction ex(map.basis());
    REQUIRE(mc.cell_det_lower_bound.size() == map.mesh().num_cells());
    REQUIRE(mc.cell_relative_lower_bound.size() == map.mesh().num_cells());
    double min_det = std::numeric_limits<double>::infinity();
    for (int c = 0; c < static_cast<int>(map.mesh().num_cells()); ++c) {
      double det = std::numeric_limits<double>::infinity(), rel = det;
      for (std::size_t k = ex.cell_begin(c); k < ex.cell_begin(c + 1); ++k) {
        const tspline::ElementCertificate e = tspline::certify_element(ex.elements()[k], map.control_points());
        det = std::min(det, e.det_lower_bound), rel = std::min(rel, e.relative_lower_bound);
      }
      CHECK(mc.cell_det_lower_bound[c] == det);
      CHECK(mc.cell_relative_lower_bound[c] == rel);
      min_det = std::min(min_det, det);
    }
    CHECK(mc.min_det_lower_bound == min_det);
    // Only some elements examined: the others' cells have no bound (NaN).
    std::vector<char> only(ex.elements().size(), 0);
    only[ex.cell_begin(3)] = 1;
    const tspline::MapCertification part =
        tspline::certify_map(ex, map.mesh().num_cells(), map.control_points(), {}, &only);
    CHECK(part.elements == 1);
    CHECK(part.cell_det_lower_bound[3] == mc.cell_det_lower_bound[3]);
    CHECK(std::isnan(part.cell_det_lower_bound[0]));
    CHECK(std::isnan(part.cell_relative_lower_bound[0]));
    check_agreement(map, 50);
    // The identity: det J = 1 everywhere, so the bound is exactly 1.
    const tspline::MapCertification id =
        tspline::certify_map(tspline::greville_identity_map(test_support::uniform_mesh(2)));
    CHECK(id.certified_valid());
    CHECK(id.min_relative_lower_bound == doctest::Approx(1.0).epsilon(1e-12));
  }

  TEST_CASE("det J touching zero: undecided at the depth limit, not certified") {
    // S = (xi, eta^3): det J = 3 eta^2 >= 0, zero on the edge eta = 0.
    const TSplineMap map =
        separable_cubic_map(test_support::uniform_mesh(0), {0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0});
    tspline::CertificationOptions opt;
    opt.max_depth = 4;
    const tspline::MapCertification mc = tspline::certify_map(map, opt);
    CHECK(mc.undecided == 1);
    CHECK(mc.invalid == 0);
    CHECK_FALSE(mc.certified_valid());
    CHECK(mc.max_depth_used == 4);
    REQUIRE(mc.failures.size() == 1);
    CHECK(mc.failures[0].certificate.status == ElementStatus::Undecided);
    CHECK(mc.failures[0].certificate.det_lower_bound <= 0.0);
  }

  TEST_CASE("certification agrees with 50 x 50 sampling per element: square, L-shape, disk, flower") {
    // Every map of the adaptive loop comes out of the global untangling
    // certified, and sampling finds no fold either.
    CHECK(domain_agreement({"square.txt", "lshape_cw.txt", "disk.txt", "flower.txt"}) == 0);
  }

  TEST_CASE("certification agrees with 50 x 50 sampling per element: C-shape, blob bay") {
    domain_agreement({"cshape.txt", "blob_bay.txt"});
  }

  TEST_CASE("certification agrees with 50 x 50 sampling per element: gear") {
    domain_agreement({"gear.txt"});
  }

  TEST_CASE("certification agrees with 50 x 50 sampling per element: fjords") {
    // (Whether its first map folds between the Gauss points depends on the
    // T-mesh optimizer's exact result; the disk case above has such a fold.)
    domain_agreement({"fjords.txt"});
  }

  TEST_CASE("certification agrees with sampling on an invalid map (gear, no repair, no adaptive rounds)") {
    const auto gear = tspline::io::read_polygon(test_support::polygon_file("gear.txt"));
    tspline::AdaptiveOptions ad;
    ad.optimize_control_points = false;
    ad.max_adapt = 0;
    const tspline::ParameterizationResult r = tspline::run_parameterization(gear, {}, ad);
    std::size_t negatives = 0;
    check_agreement(*r.map, 20, &negatives);
    CHECK(negatives > 0);
    CHECK_FALSE(r.certified_valid());
    CHECK(r.certification.invalid >= negatives);
  }

  TEST_CASE("certify_map (parallel, and on a subset of elements) equals certify_element element by element") {
    for (unsigned seed : {1u, 4u}) {
      const TSplineMap map = test_support::perturbed_map(seed, 0.12);
      const tspline::BezierExtraction ex(map.basis());
      const std::size_t n = ex.elements().size();
      std::vector<char> only(n, 0);
      for (std::size_t k = 0; k < n; k += 3) only[k] = 1;
      for (bool subset : {false, true}) {
        const tspline::MapCertification c =
            tspline::certify_map(ex, map.mesh().num_cells(), map.control_points(), {}, subset ? &only : nullptr);
        std::size_t elements = 0, certified = 0, invalid = 0, undecided = 0;
        double min_rel = std::numeric_limits<double>::infinity();
        std::vector<std::size_t> failing;
        for (std::size_t k = 0; k < n; ++k) {
          if (subset && !only[k]) continue;
          const tspline::ElementCertificate e = tspline::certify_element(ex.elements()[k], map.control_points());
          ++elements;
          min_rel = std::min(min_rel, e.relative_lower_bound);
          if (e.status == ElementStatus::Certified)
            ++certified;
          else
            failing.push_back(k), ++(e.status == ElementStatus::Invalid ? invalid : undecided);
        }
        CAPTURE(seed);
        CAPTURE(subset);
        CHECK(c.elements == elements);
        CHECK(c.certified == certified);
        CHECK(c.invalid == invalid);
        CHECK(c.undecided == undecided);
        CHECK(c.min_relative_lower_bound == min_rel);
        REQUIRE(c.failures.size() == failing.size());
        for (std::size_t i = 0; i < failing.size(); ++i) {
          CHECK(c.failures[i].element == failing[i]);
          CHECK(c.cell_certified[c.failures[i].cell] == 0);
        }
        CHECK(invalid > 0);  // the perturbed maps fold
      }
    }
  }
}

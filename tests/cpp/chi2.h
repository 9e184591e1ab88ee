// Chi-square goodness-of-fit helper for the statistical tests of the sampling
// routines, lobes and lights (test_sampling.cpp, test_bsdf.cpp, test_lights.cpp).
//
// A test draws N samples into the cells of a 2D grid (a 1D domain is a grid one
// cell high), integrates the density claimed by the code under test over every
// cell with sub-cell midpoint quadrature, pools the cells whose expected count
// is below 5 and compares with the chi-square distribution. Directions use the
// (cosθ, φ) parameterisation of the sphere around an arbitrary pole: it is
// area preserving, so the solid-angle density is the density in (cosθ, φ).
//
// Samplers may fail (a GGX reflection below the horizon is "no sample"); such
// samples are counted apart. The cells' shape is tested conditionally on
// success, and the integral of the density is checked separately against the
// success rate (their quadrature error would otherwise dominate one cell).
//
// Significance: kChi2TestCount chi-square tests live in kauri_tests; each uses
// the Šidák-corrected level α = 1 − (1 − 0.01)^(1/kChi2TestCount), so a correct
// implementation fails the whole binary by chance with probability 0.01. Every
// Chi2 test bumps a counter and a global environment checks, after the run, that
// the constant is not smaller than the number actually performed.
// Set KAURI_CHI2_VERBOSE=1 to print the statistics of passing tests too, and
// KAURI_CHI2_SEED=k to re-run the drivers with other seeds (to look at the spread of p).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "kauri/core/math.h"
#include "kauri/sampler/rng.h"

namespace kauri::test {

// Number of chi-square tests (calls of Chi2Table::test) in kauri_tests when all tests run.
// See the breakdown on the next line.
inline constexpr int kChi2TestCount = 134;  // sampling 25, bsdf 22, lights 12, conductor 11, extra lobes 44, layers 4, oren-nayar 7, rough-dielectric energy 4, wavelengths 2, light tree 3
inline constexpr double kChi2OverallSignificance = 0.01;
inline constexpr double kPiD = 3.14159265358979323846;

inline double chi2_alpha() {
  return 1 - std::pow(1 - kChi2OverallSignificance, 1.0 / double(kChi2TestCount));
}

// ------------------------------------------------------------ incomplete gamma

/// Regularized lower incomplete gamma P(a, x) by its power series (x < a + 1).
inline double gamma_p_series(double a, double x) {
  double term = 1 / a, sum = term;
  for (int n = 1; n < 100000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * 1e-16) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

/// Regularized upper incomplete gamma Q(a, x) by its continued fraction (x >= a + 1),
/// evaluated with the modified Lentz method.
inline double gamma_q_cf(double a, double x) {
  const double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1 / d;
    double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1) < 1e-16) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

/// Q(a, x) = Γ(a, x) / Γ(a).
inline double gamma_q(double a, double x) {
  if (x <= 0) return 1;
  if (x < a + 1) return 1 - gamma_p_series(a, x);
  return gamma_q_cf(a, x);
}

/// Survival function of the chi-square distribution: P(X >= chi2) with `dof` degrees of freedom.
inline double chi2_sf(double chi2, double dof) { return gamma_q(dof / 2, chi2 / 2); }

// ------------------------------------------------------------ bin edges

inline std::vector<double> uniform_edges(double lo, double hi, int n) {
  std::vector<double> e(size_t(n) + 1);
  for (int i = 0; i <= n; ++i) e[size_t(i)] = lo + (hi - lo) * double(i) / double(n);
  e.front() = lo;
  e.back() = hi;
  return e;
}

/// Edges of n roughly equiprobable bins from a pilot sample (drawn with another
/// seed than the test, so the binning is independent of the tested samples),
/// plus the domain ends and any `forced` edges (e.g. the horizon).
inline std::vector<double> quantile_edges(std::vector<double> pilot, int n, double lo, double hi,
                                          const std::vector<double>& forced = {}) {
  std::vector<double> e{lo, hi};
  for (double f : forced)
    if (f > lo && f < hi) e.push_back(f);
  pilot.erase(std::remove_if(pilot.begin(), pilot.end(), [&](double v) { return !(v > lo && v < hi); }),
              pilot.end());
  std::sort(pilot.begin(), pilot.end());
  if (!pilot.empty()) {
    auto q = [&](int k) { return pilot[std::min(pilot.size() - 1, pilot.size() * size_t(k) / size_t(n))]; };
    for (int k = 1; k < n; ++k) e.push_back(q(k));
    // Bracket the pilot's range by one more bin width on each side: a density with a
    // sharp-edged support (a light's silhouette, a cone) then ends inside a cell of
    // ordinary size, never as a sliver of the large outer cell that quadrature would miss.
    if (n >= 2) {
      e.push_back(std::max(lo, pilot.front() - (q(1) - pilot.front())));
      e.push_back(std::min(hi, pilot.back() + (pilot.back() - q(n - 1))));
    }
  }
  std::sort(e.begin(), e.end());
  // Drop edges closer than a tiny fraction of the domain (atoms in the pilot).
  std::vector<double> out{e.front()};
  const double min_gap = 1e-7 * (hi - lo);
  for (size_t i = 1; i < e.size(); ++i)
    if (e[i] - out.back() > min_gap) out.push_back(e[i]);
  if (out.back() != hi) out.back() = hi;
  return out;
}

// ------------------------------------------------------------ the test itself

struct Chi2Options {
  int sub = 8;                 // initial sub-cells per cell side for midpoint quadrature
  int max_sub = 128;           // adaptive refinement limit
  double min_expected = 5;     // pool cells expecting fewer samples than this
  double integral_tol = 2e-3;  // allowed quadrature error of ∫pdf (absolute)
  bool counted = true;         // false for negative controls (expected to fail; not in kChi2TestCount)
};

/// Number of chi-square tests performed so far (checked against kChi2TestCount).
inline int& chi2_tests_run() {
  static int n = 0;
  return n;
}

class Chi2CountGuard : public ::testing::Environment {
 public:
  void TearDown() override {
    int n = chi2_tests_run();
    if (n > 0)
      std::cout << "[chi2] " << n << " chi-square tests run; Sidak: " << kChi2TestCount
                << " registered, per-test alpha = " << chi2_alpha() << "\n";
    EXPECT_LE(n, kChi2TestCount) << "update kChi2TestCount in tests/cpp/chi2.h";
    const ::testing::UnitTest& u = *::testing::UnitTest::GetInstance();
    if (u.test_to_run_count() == u.total_test_count()) {
      EXPECT_EQ(n, kChi2TestCount) << "all tests ran: update kChi2TestCount in tests/cpp/chi2.h";
    }
  }
};
inline const bool kChi2GuardRegistered = (::testing::AddGlobalTestEnvironment(new Chi2CountGuard), true);

/// Histogram over a rectangle [x0,x1]×[y0,y1] cut by arbitrary edges.
class Chi2Table {
 public:
  Chi2Table(std::vector<double> xe, std::vector<double> ye)
      : xe_(std::move(xe)), ye_(std::move(ye)), obs_((xe_.size() - 1) * (ye_.size() - 1), 0) {}

  int nx() const { return int(xe_.size()) - 1; }
  int ny() const { return int(ye_.size()) - 1; }

  /// Samples within `slack` of the domain are clamped into it (float rounding);
  /// others are counted as out-of-domain failures.
  void add(double x, double y, double slack = 1e-6) {
    if (!(x >= xe_.front() - slack && x <= xe_.back() + slack && y >= ye_.front() - slack &&
          y <= ye_.back() + slack)) {
      if (out_of_domain_ < 5) out_examples_.push_back({x, y});
      ++out_of_domain_;
      return;
    }
    const int i = cell(x, xe_), j = cell(y, ye_);
    const size_t c = size_t(j) * size_t(nx()) + size_t(i);
    ++obs_[c];
    // Remember samples within float rounding of a cell edge: if they land in a
    // cell where the density is zero, they are moved across that edge (a warp
    // whose support ends exactly on an edge may overshoot it by an ulp).
    const double ex = 1e-6 * (xe_.back() - xe_.front()), ey = 1e-6 * (ye_.back() - ye_.front());
    int ni = i, nj = j;
    if (i > 0 && x - xe_[size_t(i)] < ex) ni = i - 1;
    else if (i < nx() - 1 && xe_[size_t(i) + 1] - x < ex) ni = i + 1;
    else if (j > 0 && y - ye_[size_t(j)] < ey) nj = j - 1;
    else if (j < ny() - 1 && ye_[size_t(j) + 1] - y < ey) nj = j + 1;
    if (ni != i || nj != j) near_edge_.push_back({c, size_t(nj) * size_t(nx()) + size_t(ni)});
  }
  void add_invalid() { ++invalid_; }
  uint64_t total() const { return valid() + invalid_ + out_of_domain_; }
  uint64_t valid() const { return std::accumulate(obs_.begin(), obs_.end(), uint64_t(0)); }

  /// Runs the chi-square test of the observed counts against the density `pdf(x, y)`.
  template <class Pdf>
  ::testing::AssertionResult test(const Pdf& pdf, const std::string& name, const Chi2Options& opt = {}) const {
    if (opt.counted) ++chi2_tests_run();
    const double alpha = chi2_alpha();
    std::ostringstream msg;
    msg << name << ": ";
    if (out_of_domain_ > 0) {
      msg << out_of_domain_ << " samples outside the domain, e.g.";
      for (auto& p : out_examples_) msg << " (" << p[0] << ", " << p[1] << ")";
      return ::testing::AssertionFailure() << msg.str();
    }
    const uint64_t n_total = total(), n_valid = valid();
    if (n_valid == 0) return ::testing::AssertionFailure() << msg.str() << "no valid samples";
    const int nx_ = nx(), ny_ = ny();
    std::vector<double> prob(obs_.size());
    double integral = 0;
    // Adaptive: double the sub-cell resolution until the change would shift the
    // expected count by less than a tenth of its standard deviation.
    const double n_d = double(n_total);
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        size_t c = size_t(j) * size_t(nx_) + size_t(i);
        double coarse = integrate(pdf, i, j, opt.sub);
        int sub = opt.sub;
        for (;;) {
          double fine = integrate(pdf, i, j, 2 * sub);
          sub *= 2;
          const bool converged = std::fabs(fine - coarse) * n_d <= 0.1 * std::sqrt(std::max(fine * n_d, 1.0));
          coarse = fine;
          if (converged || sub >= opt.max_sub) break;
        }
        prob[c] = coarse;
        integral += prob[c];
      }
    // Samples where the density integrates to ~0: refine the quadrature first, so a
    // cell that the density only grazes (a light's silhouette) is not mistaken for one.
    std::vector<uint64_t> obs = obs_;
    size_t moved = 0;
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        size_t c = size_t(j) * size_t(nx_) + size_t(i);
        if (obs[c] == 0 || prob[c] * double(n_total) > 1e-6) continue;
        double refined = integrate(pdf, i, j, std::max(opt.max_sub, 256));
        integral += refined - prob[c];
        prob[c] = refined;
        if (refined * double(n_total) > 1e-6) continue;
        for (auto [from, to] : near_edge_)
          if (from == c && prob[to] * double(n_total) > 1e-6 && obs[c] > 0) {
            --obs[c];
            ++obs[to];
            ++moved;
          }
        if (obs[c] > 0)
          return ::testing::AssertionFailure()
                 << msg.str() << obs[c] << " samples in cell x∈[" << xe_[size_t(i)] << ", " << xe_[size_t(i) + 1]
                 << "], y∈[" << ye_[size_t(j)] << ", " << ye_[size_t(j) + 1] << "] where the pdf integrates to "
                 << refined;
      }
    // The density's mass must match the success rate of the sampler.
    const double rate = double(n_valid) / double(n_total);
    const double tol = 5 * std::sqrt(std::max(rate * (1 - rate), 1e-12) / double(n_total)) + opt.integral_tol;
    if (!(std::fabs(integral - rate) <= tol))
      return ::testing::AssertionFailure() << msg.str() << "pdf integrates to " << integral
                                           << " but the sampler succeeded with rate " << rate << " (tolerance "
                                           << tol << ")";
    // Expected counts of the successful samples; pool the small cells (Mitsuba's scheme).
    std::vector<size_t> order(obs_.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::vector<double> expd(obs_.size());
    for (size_t c = 0; c < obs_.size(); ++c) expd[c] = prob[c] / integral * double(n_valid);
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expd[a] < expd[b]; });
    double chi2 = 0, pooled_obs = 0, pooled_exp = 0;
    int dof = 0;
    struct Worst {
      double contrib, o, e;
      size_t c;
    };
    std::vector<Worst> worst;
    for (size_t c : order) {
      double o = double(obs[c]), e = expd[c];
      if (e <= 0 && o == 0) continue;
      if (e < opt.min_expected || (pooled_exp > 0 && pooled_exp < opt.min_expected)) {
        pooled_obs += o;
        pooled_exp += e;
      } else {
        double d = (o - e) * (o - e) / e;
        chi2 += d;
        worst.push_back({d, o, e, c});
        ++dof;
      }
    }
    if (pooled_exp > 0) {
      chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
      ++dof;
    }
    dof -= 1;  // the total is fixed
    if (dof < 1) return ::testing::AssertionFailure() << msg.str() << "too few cells (dof " << dof << ")";
    const double p = chi2_sf(chi2, dof);
    msg << "chi2 = " << chi2 << ", dof = " << dof << ", p = " << p << ", alpha = " << alpha << ", cells "
        << nx_ << "x" << ny_ << ", samples " << n_valid << "/" << n_total << ", integral " << integral
        << (moved ? ", moved across an edge: " + std::to_string(moved) : std::string());
    if (p < alpha) {
      std::sort(worst.begin(), worst.end(), [](const Worst& a, const Worst& b) { return a.contrib > b.contrib; });
      msg << "\n  largest contributions:";
      for (size_t k = 0; k < std::min<size_t>(6, worst.size()); ++k) {
        size_t i = worst[k].c % size_t(nx_), j = worst[k].c / size_t(nx_);
        msg << "\n   x∈[" << xe_[i] << ", " << xe_[i + 1] << "] y∈[" << ye_[j] << ", " << ye_[j + 1]
            << "]: observed " << worst[k].o << ", expected " << worst[k].e;
      }
      if (pooled_exp > 0) msg << "\n   pooled: observed " << pooled_obs << ", expected " << pooled_exp;
      return ::testing::AssertionFailure() << msg.str();
    }
    if (std::getenv("KAURI_CHI2_VERBOSE")) std::cout << "[chi2] " << msg.str() << "\n";
    return ::testing::AssertionSuccess() << msg.str();
  }

 private:
  static int cell(double v, const std::vector<double>& e) {
    auto it = std::upper_bound(e.begin(), e.end(), v);
    int i = int(it - e.begin()) - 1;
    return std::clamp(i, 0, int(e.size()) - 2);
  }
  template <class Pdf>
  double integrate(const Pdf& pdf, int i, int j, int sub) const {
    const double x0 = xe_[size_t(i)], x1 = xe_[size_t(i) + 1], y0 = ye_[size_t(j)], y1 = ye_[size_t(j) + 1];
    const double dx = (x1 - x0) / sub, dy = (y1 - y0) / sub;
    double s = 0;
    for (int b = 0; b < sub; ++b)
      for (int a = 0; a < sub; ++a) s += double(pdf(x0 + (a + 0.5) * dx, y0 + (b + 0.5) * dy));
    return s * dx * dy;
  }

  std::vector<double> xe_, ye_;
  std::vector<uint64_t> obs_;
  uint64_t invalid_ = 0, out_of_domain_ = 0;
  std::vector<std::array<double, 2>> out_examples_;
  std::vector<std::pair<size_t, size_t>> near_edge_;  // (cell, neighbour across the near edge)
};

// ------------------------------------------------------------ drivers

/// The driver seed, optionally perturbed by KAURI_CHI2_SEED (default: the fixed seed).
inline uint64_t chi2_seed(uint64_t seed) {
  const char* e = std::getenv("KAURI_CHI2_SEED");
  return e ? seed ^ (std::strtoull(e, nullptr, 10) * 0x9e3779b97f4a7c15ULL) : seed;
}

/// Chi-square test over a rectangle. `sample(PCG32&, double* x, double* y) -> bool`
/// (false: the sampler produced nothing); `pdf(x, y) -> double`.
struct RectChi2Config {
  std::string name;
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  int nx = 32, ny = 32;
  int samples = 1000000;
  uint64_t seed = 1;
  Chi2Options opt;
  std::vector<double> extra_x, extra_y;  // edges added to the uniform ones
  RectChi2Config(std::string name_, double x0_, double x1_, double y0_, double y1_, int nx_, int ny_, int samples_,
                 uint64_t seed_, Chi2Options opt_ = {})
      : name(std::move(name_)), x0(x0_), x1(x1_), y0(y0_), y1(y1_), nx(nx_), ny(ny_), samples(samples_),
        seed(seed_), opt(opt_) {}
};

template <class SampleFn, class PdfFn>
::testing::AssertionResult rect_chi2(const SampleFn& sample, const PdfFn& pdf, const RectChi2Config& cfg) {
  auto edges = [](double lo, double hi, int n, std::vector<double> extra) {
    std::vector<double> u = uniform_edges(lo, hi, n);
    extra.insert(extra.end(), u.begin(), u.end());
    return quantile_edges({}, 1, lo, hi, extra);
  };
  Chi2Table t(edges(cfg.x0, cfg.x1, cfg.nx, cfg.extra_x), edges(cfg.y0, cfg.y1, cfg.ny, cfg.extra_y));
  PCG32 rng(chi2_seed(cfg.seed), 0x5eed);
  for (int k = 0; k < cfg.samples; ++k) {
    double x = 0, y = 0;
    if (sample(rng, &x, &y))
      t.add(x, y);
    else
      t.add_invalid();
  }
  return t.test(pdf, cfg.name, cfg.opt);
}

/// Chi-square test of a direction sampler over the sphere. Directions are binned in
/// (cosθ, φ) about `frame.z`, with roughly equiprobable bins taken from a pilot run
/// (different seed) so that peaked densities get resolution where their mass is.
/// `sample(PCG32&, Vec3* w) -> bool`; `pdf(Vec3 w) -> double` (solid angle).
struct SphereChi2Config {
  std::string name;
  Frame frame;                       // pole of the (cosθ, φ) parameterisation
  std::vector<double> forced_cos;    // extra cosθ edges (e.g. 0: the horizon)
  int ncos = 40, nphi = 40;
  int samples = 1000000;
  int pilot = 40000;
  bool adaptive = true;              // pilot quantiles; false: uniform in (cosθ, φ)
  uint64_t seed = 1;
  Chi2Options opt;
};

inline void direction_to_cos_phi(const Frame& f, Vec3 w, double* c, double* phi) {
  double x = double(dot(w, f.x)), y = double(dot(w, f.y)), z = double(dot(w, f.z));
  double len = std::sqrt(x * x + y * y + z * z);
  *c = std::clamp(z / len, -1.0, 1.0);
  *phi = std::atan2(y, x);
  if (*phi < 0) *phi += 2 * kPiD;
}
inline Vec3 cos_phi_to_direction(const Frame& f, double c, double phi) {
  double s = std::sqrt(std::max(0.0, 1 - c * c));
  return f.to_world(Vec3{Float(s * std::cos(phi)), Float(s * std::sin(phi)), Float(c)});
}

template <class SampleFn, class PdfFn>
::testing::AssertionResult sphere_chi2(const SampleFn& sample, const PdfFn& pdf, const SphereChi2Config& cfg) {
  std::vector<double> ce, pe;
  if (cfg.adaptive) {
    std::vector<double> pc, pp;
    PCG32 prng(chi2_seed(cfg.seed) ^ 0xa5a5a5a5ULL, 0x9170);
    for (int k = 0; k < cfg.pilot; ++k) {
      Vec3 w;
      if (!sample(prng, &w)) continue;
      double c, phi;
      direction_to_cos_phi(cfg.frame, w, &c, &phi);
      pc.push_back(c);
      pp.push_back(phi);
    }
    ce = quantile_edges(pc, cfg.ncos, -1, 1, cfg.forced_cos);
    pe = quantile_edges(pp, cfg.nphi, 0, 2 * kPiD);
  } else {
    std::vector<double> f = uniform_edges(-1, 1, cfg.ncos);
    f.insert(f.end(), cfg.forced_cos.begin(), cfg.forced_cos.end());
    ce = quantile_edges({}, 1, -1, 1, f);
    pe = uniform_edges(0, 2 * kPiD, cfg.nphi);
  }
  Chi2Table t(ce, pe);
  PCG32 rng(chi2_seed(cfg.seed), 0x5eed);
  for (int k = 0; k < cfg.samples; ++k) {
    Vec3 w;
    if (!sample(rng, &w)) {
      t.add_invalid();
      continue;
    }
    double c, phi;
    direction_to_cos_phi(cfg.frame, w, &c, &phi);
    t.add(c, phi);
  }
  const Frame f = cfg.frame;
  return t.test([&](double c, double phi) { return double(pdf(cos_phi_to_direction(f, c, phi))); }, cfg.name,
                cfg.opt);
}

}  // namespace kauri::test

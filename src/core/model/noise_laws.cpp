#include "model/noise_laws.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace amytiss::detail {
namespace {

// The continued fraction of I_x(a, b) (Numerical Recipes' betacf, modified Lentz). It converges
// fast for x < (a + 1)/(a + b + 2); the callers use the symmetry I_x(a, b) = 1 - I_{1-x}(b, a)
// beyond that point.
double beta_continued_fraction(double x, double a, double b) {
  constexpr int kMaxIterations = 100000;
  constexpr double kEpsilon = 1e-16;
  constexpr double kTiny = 1e-300;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0, d = 1.0 - qab * x / qap;
  if (std::fabs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= kMaxIterations; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEpsilon) break;
  }
  return h;
}

// I_x(a, b) evaluated directly (x on the fast side of the continued fraction).
double incomplete_beta_direct(double x, double a, double b) {
  if (x <= 0.0) return 0.0;
  const double log_front = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  return std::exp(log_front) * beta_continued_fraction(x, a, b) / a;
}

bool lower_side(double x, double a, double b) { return x < (a + 1.0) / (a + b + 2.0); }

// Gauss-Kronrod 15-point nodes (non-negative half) and weights; the 7-point Gauss rule uses the
// odd-indexed nodes.
constexpr double kKronrodNodes[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                                     0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                                     0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                                     0.207784955007898467600689403773245, 0.0};
constexpr double kKronrodWeights[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                                       0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                                       0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                                       0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kGaussWeights[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                     0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
// Bisection stops here: a piece narrower than this share of the whole interval is accepted
// with its estimate (which still enters `error`).
constexpr int kMaxDepth = 60;

void gauss_kronrod(const std::function<double(double)>& f, double a, double b, double tolerance, int depth,
                   Quadrature& total) {
  const double center = 0.5 * (a + b), half = 0.5 * (b - a);
  const double f_center = f(center);
  double kronrod = kKronrodWeights[7] * f_center, gauss = kGaussWeights[3] * f_center;
  for (int i = 0; i < 7; ++i) {
    const double sum = f(center - half * kKronrodNodes[i]) + f(center + half * kKronrodNodes[i]);
    kronrod += kKronrodWeights[i] * sum;
    if (i % 2 == 1) gauss += kGaussWeights[i / 2] * sum;
  }
  kronrod *= half;
  gauss *= half;
  const double error = std::fabs(kronrod - gauss);
  if (error <= tolerance || depth >= kMaxDepth || !(error == error)) {
    total.value += kronrod;
    total.error += error;
    return;
  }
  gauss_kronrod(f, a, center, 0.5 * tolerance, depth + 1, total);
  gauss_kronrod(f, center, b, 0.5 * tolerance, depth + 1, total);
}

}  // namespace

double incomplete_beta(double x, double a, double b) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  return lower_side(x, a, b) ? incomplete_beta_direct(x, a, b) : 1.0 - incomplete_beta_direct(1.0 - x, b, a);
}

double incomplete_beta_complement(double x, double a, double b) {
  if (x <= 0.0) return 1.0;
  if (x >= 1.0) return 0.0;
  return lower_side(x, a, b) ? 1.0 - incomplete_beta_direct(x, a, b) : incomplete_beta_direct(1.0 - x, b, a);
}

Quadrature integrate_adaptive(const std::function<double(double)>& f, double a, double b, double tolerance) {
  Quadrature total;
  if (!(a < b)) return total;
  gauss_kronrod(f, a, b, tolerance, 0, total);
  return total;
}

double UnitLaw::mass(double a, double b) const {
  if (!(a < b)) return 0.0;
  switch (distribution) {
    case Distribution::Exponential: {
      // exp(-rate*ea) - exp(-rate*eb) written so that neither tails nor narrow cells cancel.
      const double ea = std::max(a - shift, 0.0), eb = std::max(b - shift, 0.0);
      if (!(eb > ea)) return 0.0;
      return -std::exp(-rate * ea) * std::expm1(-rate * (eb - ea));
    }
    case Distribution::Beta: {
      const double width = hi - lo;
      const double ta = std::clamp((a - lo) / width, 0.0, 1.0), tb = std::clamp((b - lo) / width, 0.0, 1.0);
      if (!(ta < tb)) return 0.0;
      // Subtract on the side away from the bulk, as the normal law's masses do.
      const double middle = (alpha + 1.0) / (alpha + beta + 2.0);
      double result;
      if (tb <= middle) result = incomplete_beta(tb, alpha, beta) - incomplete_beta(ta, alpha, beta);
      else if (ta >= middle)
        result = incomplete_beta_complement(ta, alpha, beta) - incomplete_beta_complement(tb, alpha, beta);
      else result = 1.0 - incomplete_beta(ta, alpha, beta) - incomplete_beta_complement(tb, alpha, beta);
      return std::max(0.0, result);
    }
    case Distribution::Custom: {
      const double from = std::max(a, lo), to = std::min(b, hi);
      if (!(from < to)) return 0.0;
      const Expression& expression = *density;
      const Quadrature q = integrate_adaptive([&expression](double z) { return expression.evaluate_density(z); },
                                              from, to, kCustomMassTolerance * normalization);
      return std::max(0.0, q.value / normalization);
    }
    default:
      throw std::logic_error("UnitLaw::mass: not a law of this kind");
  }
}

UnitLaw unit_law(const NoiseConfig& noise, std::size_t dim, const std::map<std::string, double>& constants) {
  UnitLaw law;
  law.distribution = noise.distribution;
  switch (noise.distribution) {
    case Distribution::Exponential:
      law.rate = noise.rate.at(dim);
      law.shift = noise.shift.empty() ? 0.0 : noise.shift.at(dim);
      law.lo = law.shift;
      law.hi = std::numeric_limits<double>::infinity();
      break;
    case Distribution::Beta:
      law.alpha = noise.alpha.at(dim);
      law.beta = noise.beta.at(dim);
      law.lo = noise.support->lb.at(dim);
      law.hi = noise.support->ub.at(dim);
      break;
    case Distribution::Custom: {
      law.lo = noise.support->lb.at(dim);
      law.hi = noise.support->ub.at(dim);
      auto expression = std::make_shared<Expression>(Expression::parse_density(noise.density.at(dim), constants));
      law.normalization = integrate_adaptive([&](double z) { return expression->evaluate_density(z); }, law.lo,
                                             law.hi, 1e-3 * UnitLaw::kCustomMassTolerance)
                              .value;
      law.density = std::move(expression);
      break;
    }
    default:
      throw std::logic_error("unit_law: normal and uniform noise have no UnitLaw");
  }
  return law;
}

DensityCheck check_density(const Expression& density, double lo, double hi) {
  DensityCheck check;
  check.smallest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < DensityCheck::kDensitySamples; ++i) {
    const double z = lo + (hi - lo) * double(i) / double(DensityCheck::kDensitySamples - 1);
    const double value = density.evaluate_density(z);
    if (!std::isfinite(value)) {
      check.finite = false;
      check.nonfinite_at = z;
      return check;
    }
    if (value < check.smallest) {
      check.smallest = value;
      check.smallest_at = z;
    }
  }
  check.integral = integrate_adaptive([&](double z) { return density.evaluate_density(z); }, lo, hi, 1e-12);
  return check;
}

}  // namespace amytiss::detail

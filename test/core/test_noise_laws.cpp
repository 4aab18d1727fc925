// Exponential, beta and custom noise: closed forms of the incomplete beta, cell masses against
// independent formulas, truncation's cut mass, the configuration checks, the engines' agreement
// (reference against the OpenCL factored sweep) and a Monte Carlo run of the abstract MDP.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "agreement.hpp"
#include "monte_carlo.hpp"
#include "model/noise_laws.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

constexpr double kClosedFormTolerance = 1e-14;
constexpr double kTailRelativeTolerance = 1e-12;
// A custom density's masses are each within 1e-12 (the quadrature's target); a margin for the sum.
constexpr double kQuadratureTolerance = 5e-12;
constexpr double kEngineTolerance = 1e-5;
constexpr double kMonteCarloStandardErrors = 4.0;

using test_support::from_yaml;

std::string expect_config_error(const std::string& text, const std::string& key) {
  try {
    config_from_yaml(YAML::Load(text));
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), key) << error.what();
    return error.what();
  }
  ADD_FAILURE() << "no ConfigError for key " << key;
  return "";
}

// ---------------------------------------------------------------------------------------------
// The incomplete beta function against closed forms.

TEST(IncompleteBeta, ClosedForms) {
  for (double x = 0.0; x <= 1.0; x += 1.0 / 64) {
    // I_x(2, 5) = P(Bin(6, x) >= 2); I_x(1/2, 1/2) = (2/pi) asin(sqrt x); I_x(a, 1) = x^a.
    const double binomial = 1.0 - std::pow(1 - x, 6) - 6 * x * std::pow(1 - x, 5);
    EXPECT_NEAR(detail::incomplete_beta(x, 2, 5), binomial, kClosedFormTolerance) << x;
    EXPECT_NEAR(detail::incomplete_beta_complement(x, 2, 5), 1 - binomial, kClosedFormTolerance) << x;
    EXPECT_NEAR(detail::incomplete_beta(x, 0.5, 0.5), 2 / M_PI * std::asin(std::sqrt(x)), kClosedFormTolerance) << x;
    EXPECT_NEAR(detail::incomplete_beta(x, 3.5, 1), std::pow(x, 3.5), kClosedFormTolerance) << x;
  }
  // Large shapes: I_x(50, 30) = P(Bin(79, x) >= 50), summed in long double.
  for (double x : {0.4, 0.55, 0.62, 0.7, 0.8}) {
    long double sum = 0;
    for (int j = 50; j <= 79; ++j)
      sum += std::exp(std::lgamma(80.0L) - std::lgamma(j + 1.0L) - std::lgamma(80.0L - j) + j * std::log((long double)x) +
                      (79 - j) * std::log1p(-(long double)x));
    EXPECT_NEAR(detail::incomplete_beta(x, 50, 30), double(sum), 1e-13) << x;
  }
  // Tails keep their relative precision: the binomial sum has only positive terms.
  auto upper_binomial = [](double x) {
    const double choose[] = {1, 6, 15, 20, 15, 6, 1};
    double sum = 0;
    for (int j = 2; j <= 6; ++j) sum += choose[j] * std::pow(x, j) * std::pow(1 - x, 6 - j);
    return sum;
  };
  for (double x : {1e-6, 1e-3}) {
    EXPECT_NEAR(detail::incomplete_beta(x, 2, 5) / upper_binomial(x), 1.0, kTailRelativeTolerance) << x;
    // 1 - I_{1-x}(5, 2) = I_x(2, 5).
    EXPECT_NEAR(detail::incomplete_beta_complement(1 - x, 5, 2) / upper_binomial(x), 1.0, 1e-9) << x;
  }
}

// ---------------------------------------------------------------------------------------------
// Cell masses of the noise model against independent formulas.

const char* const kGrid = "states: {lb: [-3, -2], ub: [3, 2], eta: [0.25, 0.5]}\n";

std::string law_yaml(const std::string& noise, const std::string& truncation = "truncation: none") {
  return std::string("name: laws\n") + kGrid +
         "dynamics: [\"0.5*x0\", \"x1\"]\n"
         "noise: {" + noise + ", " + truncation + "}\n"
         "spec: {type: safety, horizon: 1}\n";
}

TEST(NoiseLaws, ExponentialMassesAreTheClosedForm) {
  const Abstraction a = from_yaml(law_yaml("distribution: exponential, rate: [2.0, 0.7], shift: [-0.5, 0.25]"));
  const double rate[] = {2.0, 0.7}, shift[] = {-0.5, 0.25};
  const double cdf_lo = 0;
  (void)cdf_lo;
  for (std::size_t d = 0; d < 2; ++d)
    for (double mean : {-3.1, -0.37, 0.0, 1.9}) {
      auto cdf = [&](double v) { return v - mean - shift[d] <= 0 ? 0.0 : 1.0 - std::exp(-rate[d] * (v - mean - shift[d])); };
      double total = 0;
      for (std::size_t k = 0; k < a.states.count(d); ++k) {
        const double lo = a.states.coordinate(d, k) - 0.5 * a.states.eta()[d], hi = lo + a.states.eta()[d];
        const double mass = a.noise->cell_mass(d, k, mean, 1.0);
        EXPECT_NEAR(mass, cdf(hi) - cdf(lo), kClosedFormTolerance) << d << " " << mean << " " << k;
        total += mass;
      }
      const double covered_lo = a.states.lb()[d] - 0.5 * a.states.eta()[d];
      const double covered_hi = a.states.last_point()[d] + 0.5 * a.states.eta()[d];
      EXPECT_NEAR(total, cdf(covered_hi) - cdf(covered_lo), kClosedFormTolerance);
    }
}

TEST(NoiseLaws, BetaMassesAreTheClosedForm) {
  // Beta(2, 5) on [-1, 1]: I_t(2, 5) with t = (v + 1)/2.
  const Abstraction a =
      from_yaml(law_yaml("distribution: beta, alpha: [2, 2], beta: [5, 5], support: {lb: [-1, -1], ub: [1, 1]}"));
  auto cdf = [](double v) {
    const double t = std::min(1.0, std::max(0.0, (v + 1) / 2));
    return 1.0 - std::pow(1 - t, 6) - 6 * t * std::pow(1 - t, 5);
  };
  for (double mean : {-2.2, -0.1, 0.3, 1.7}) {
    double total = 0;
    for (std::size_t k = 0; k < a.states.count(0); ++k) {
      const double lo = a.states.coordinate(0, k) - 0.125, hi = lo + 0.25;
      const double mass = a.noise->cell_mass(0, k, mean, 1.0);
      EXPECT_NEAR(mass, cdf(hi - mean) - cdf(lo - mean), kClosedFormTolerance) << mean << " " << k;
      total += mass;
    }
    EXPECT_NEAR(total, cdf(3.125 - mean) - cdf(-3.125 - mean), kClosedFormTolerance);
  }
}

TEST(NoiseLaws, CustomMassesMatchClosedForms) {
  // A Laplace density and the Beta(2, 5) density on [0, 1] written as expressions.
  const Abstraction a = from_yaml(law_yaml(
      "distribution: custom, density: [\"0.5*exp(-abs(z))\", \"30*z*(1 - z)^4\"], "
      "support: {lb: [-40, 0], ub: [40, 1]}"));
  auto laplace = [](double v) { return v < 0 ? 0.5 * std::exp(v) : 1.0 - 0.5 * std::exp(-v); };
  auto beta25 = [](double v) {
    const double t = std::min(1.0, std::max(0.0, v));
    return 1.0 - std::pow(1 - t, 6) - 6 * t * std::pow(1 - t, 5);
  };
  for (double mean : {-0.8, 0.05, 1.3}) {
    for (std::size_t k = 0; k < a.states.count(0); ++k) {
      const double lo = a.states.coordinate(0, k) - 0.125, hi = lo + 0.25;
      EXPECT_NEAR(a.noise->cell_mass(0, k, mean, 1.0), laplace(hi - mean) - laplace(lo - mean), kQuadratureTolerance);
    }
    for (std::size_t k = 0; k < a.states.count(1); ++k) {
      const double lo = a.states.coordinate(1, k) - 0.25, hi = lo + 0.5;
      EXPECT_NEAR(a.noise->cell_mass(1, k, mean, 1.0), beta25(hi - mean) - beta25(lo - mean), kQuadratureTolerance);
    }
  }
  EXPECT_GT(a.noise->quadrature_error_bound(), 0.0);
  EXPECT_LT(a.noise->quadrature_error_bound(), 1e-9);
}

// The mass the truncation cuts for post mean m along dimension d: the grid's mass minus the
// window's (mass beyond the grid is not the truncation's).
double cut_mass(const Abstraction& a, std::size_t d, double mean, double scale, double* kept_out) {
  std::int64_t first = 0, last = -1;
  const bool inside = a.noise->dimension_window(a.states, d, mean, &first, &last);
  double grid = 0, kept = 0;
  for (std::size_t k = 0; k < a.states.count(d); ++k) {
    const double mass = a.noise->cell_mass(d, k, mean, scale);
    grid += mass;
    if (inside && std::int64_t(k) >= first && std::int64_t(k) <= last) kept += mass;
  }
  *kept_out = kept;
  return grid - kept;
}

// Union bound over the dimensions, as the stated bound.
double cut_mass(const Abstraction& a, const double* mean, double scale) {
  double kept = 0, cut = 0;
  for (std::size_t d = 0; d < a.states.dims(); ++d) cut += cut_mass(a, d, mean[d], scale, &kept);
  return cut;
}

TEST(NoiseLaws, TruncationCutsAtMostTheBound) {
  // Wide grid so that nothing leaves it: all mass outside the window is the truncation's cut.
  const std::string grid = "states: {lb: [-30, -30], ub: [30, 30], eta: [0.2, 0.3]}\n";
  auto yaml = [&](const std::string& noise, const std::string& truncation, const std::string& type) {
    return "name: cut\n" + grid + "dynamics: [\"x0\", \"x1\"]\nnoise: {type: " + type + ", " + noise + ", " +
           truncation + "}\nspec: {type: safety, horizon: 1}\n";
  };
  const std::string exponential = "distribution: exponential, rate: [2.0, 0.5], shift: [-1.0, 0.3]";
  const std::string beta = "distribution: beta, alpha: [2, 0.5], beta: [5, 0.5], support: {lb: [-1, 0], ub: [1, 3]}";
  const std::string custom = "distribution: custom, density: [\"0.5*exp(-abs(z))\", \"exp(-z)\"], "
                             "support: {lb: [-25, 0], ub: [25, 30]}";
  std::mt19937_64 generator(7);
  std::uniform_real_distribution<double> position(-5, 5);
  for (const std::string& noise : {exponential, beta, custom})
    for (const std::string& truncation : {std::string("truncation: cutting_probability, cutting_probability: 1.0e-3"),
                                          std::string("truncation: fixed_region, fixed_region: [2.0, 3.0]")}) {
      const Abstraction a = from_yaml(yaml(noise, truncation, "additive"));
      double largest_cut = 0;
      for (int sample = 0; sample < 200; ++sample) {
        const double mean[2] = {position(generator), position(generator)};
        largest_cut = std::max(largest_cut, cut_mass(a, mean, 1.0));
      }
      EXPECT_LE(largest_cut, a.noise->cut_mass_bound() + a.noise->quadrature_error_bound() + 1e-13)
          << noise << " / " << truncation;
      if (truncation.find("cutting") != std::string::npos) {
        EXPECT_LE(a.noise->cut_mass_bound(), 1e-3);
      }
      std::printf("%s, %s: window %zu cells, measured cut %.3g <= bound %.3g\n",
                  to_string(a.noise->distribution()).c_str(), to_string(a.config.noise.truncation).c_str(),
                  a.noise->window_cells(), largest_cut, a.noise->cut_mass_bound());
    }
  // Multiplicative: the scale |x| varies; the bound holds at every current state.
  const Abstraction m = from_yaml(yaml(exponential, "truncation: cutting_probability, cutting_probability: 1.0e-3",
                                       "multiplicative"));
  for (double x : {-4.0, -0.3, 0.0, 2.5})
    for (double mean : {-2.0, 0.1, 3.3}) {
      const double means[2] = {mean, mean};
      EXPECT_LE(cut_mass(m, means, std::fabs(x)), m.noise->cut_mass_bound() + 1e-13) << x << " " << mean;
    }
}

// ---------------------------------------------------------------------------------------------
// The configuration checks.

TEST(NoiseLaws, ConfigurationErrorsNameTheKey) {
  auto bad = [](const std::string& noise) { return law_yaml(noise); };
  EXPECT_NE(expect_config_error(bad("distribution: exponential, rate: [2.0, 0]"), "noise.rate[1]").find("> 0"),
            std::string::npos);
  expect_config_error(bad("distribution: exponential, rate: [2.0]"), "noise.rate");
  expect_config_error(bad("distribution: exponential, rate: [1, 1], covariance: [1, 1]"), "noise.covariance");
  expect_config_error(bad("distribution: beta, alpha: [2, 2], beta: [5, 5]"), "noise.support");
  expect_config_error(bad("distribution: beta, alpha: [2, 2], beta: [5, -1], support: {lb: [0, 0], ub: [1, 1]}"),
                      "noise.beta[1]");
  expect_config_error(bad("distribution: beta, alpha: [2, 2], beta: [5, 5], support: {lb: [0, 1], ub: [1, 1]}"),
                      "noise.support.ub[1]");
  expect_config_error(bad("distribution: normal, covariance: [1, 1], rate: [1, 1]"), "noise.rate");
  const std::string support = "support: {lb: [-1, -1], ub: [1, 1]}";
  EXPECT_NE(expect_config_error(bad("distribution: custom, density: [\"0.5\", \"z\"], " + support), "noise.density[1]")
                .find("negative"),
            std::string::npos);
  EXPECT_NE(expect_config_error(bad("distribution: custom, density: [\"0.5\", \"0.6\"], " + support), "noise.density[1]")
                .find("integrates to 1.2"),
            std::string::npos);
  EXPECT_NE(expect_config_error(bad("distribution: custom, density: [\"0.5\", \"0.5*x0\"], " + support),
                                "noise.density[1]")
                .find("column 5"),
            std::string::npos);
  EXPECT_NE(expect_config_error(bad("distribution: custom, density: [\"0.5\", \"1/(2*z)\"], " + support),
                                "noise.density[1]")
                .find("not finite"),
            std::string::npos);
  expect_config_error(bad("distribution: custom, density: [\"0.5\"], " + support), "noise.density");
  // The variable of densities is not a constant name.
  expect_config_error("name: c\nstates: {lb: [0], ub: [1], eta: [1]}\nconstants: {z: 1}\ndynamics: [\"x0\"]\n"
                      "noise: {covariance: [1]}\nspec: {type: safety, horizon: 1}\n",
                      "constants.z");
  // A valid custom density with a constant.
  EXPECT_NO_THROW(config_from_yaml(YAML::Load(
      "name: c\nstates: {lb: [0], ub: [1], eta: [1]}\nconstants: {b: 2}\ndynamics: [\"x0\"]\n"
      "noise: {distribution: custom, density: [\"exp(-abs(z)/b)/(2*b)\"], support: {lb: [-60], ub: [60]}}\n"
      "spec: {type: safety, horizon: 1}\n")));
}

TEST(NoiseLaws, CanonicalYamlRoundTrips) {
  for (const std::string& noise :
       {std::string("distribution: exponential, rate: [2.0, 0.7], shift: [-0.5, 0.25]"),
        std::string("distribution: beta, alpha: [2, 0.5], beta: [5, 0.5], support: {lb: [-1, 0], ub: [1, 3]}"),
        std::string("distribution: custom, density: [\"0.5*exp(-abs(z))\", \"exp(-z)\"], "
                    "support: {lb: [-40, 0], ub: [40, 40]}")}) {
    const Config config = config_from_yaml(YAML::Load(law_yaml(noise)));
    const Config again = config_from_yaml(YAML::Load(to_yaml(config)));
    EXPECT_EQ(to_yaml(again), to_yaml(config)) << noise;
    EXPECT_EQ(config_hash(again), config_hash(config)) << noise;
  }
}

// ---------------------------------------------------------------------------------------------
// Engines: the reference against the OpenCL engine, whose factored sweep takes the host's masses.

std::string engine_yaml(const std::string& noise, const std::string& sweep = "auto") {
  return "name: laws_engines\n"
         "states: {lb: [-2, -2], ub: [2, 2], eta: [0.25, 0.25]}\n"
         "inputs: {lb: [-0.5], ub: [0.5], eta: [0.25]}\n"
         "disturbances: {lb: [-0.1], ub: [0.1], eta: [0.2]}\n"
         "dynamics: [\"0.9*x0 + u0 + w0\", \"0.8*x1 + 0.2*x0\"]\n"
         "noise: {" + noise + "}\n"
         "spec: {type: reach_avoid, horizon: 5, target: {lb: [0.5, -0.5], ub: [1, 0.5]}, "
         "avoid: {lb: [-1, 1], ub: [-0.5, 1.5]}}\n"
         "compute: {device: cpu, sweep: " + sweep + "}\n";
}

TEST(NoiseLawsEngines, OpenClFactoredSweepMatchesReference) {
  const std::vector<std::string> noises = {
      "distribution: exponential, rate: [4, 6], shift: [-0.25, -0.1], truncation: cutting_probability, "
      "cutting_probability: 1.0e-4",
      "type: multiplicative, distribution: exponential, rate: [8, 8], truncation: cutting_probability",
      "distribution: beta, alpha: [2, 0.7], beta: [5, 0.7], support: {lb: [-0.5, -0.4], ub: [0.5, 0.6]}, "
      "truncation: cutting_probability",
      "distribution: custom, density: [\"2.5*exp(-5*abs(z))\", \"0.75*(1 - z^2)\"], "
      "support: {lb: [-3, -1], ub: [3, 1]}, truncation: cutting_probability"};
  for (const std::string& noise : noises) {
    const Abstraction a = from_yaml(engine_yaml(noise));
    const Policy reference = synthesize_reference(a, nullptr);
    SynthesisOptions options;
    options.compute = a.config.compute;
    SynthesisReport report;
    const Policy opencl = synthesize(a, options, &report);
    bool factored = false;
    for (const auto& note : report.notes) factored = factored || note.text.find("host masses") != std::string::npos;
    EXPECT_TRUE(factored) << "the factored sweep should have run for " << noise;
    const test_support::Agreement agreement = test_support::compare(a, reference, opencl);
    EXPECT_LE(agreement.max_value_difference, kEngineTolerance) << noise;
    EXPECT_LE(agreement.max_mismatch_margin, 1e-12) << noise;
    const ValueSummary summary = summarize_initial_values(reference);
    EXPECT_GT(summary.max, 0.1) << "a trivial problem tests nothing: " << noise;
    std::printf("%s: max |V_ref - V_opencl| = %.3g over all steps, %zu input ties, V_0 max %.4f\n",
                to_string(a.noise->distribution()).c_str(), agreement.max_value_difference,
                agreement.input_mismatches, summary.max);
  }
}

TEST(NoiseLawsEngines, DenseSweepRefusesHostLaws) {
  const Abstraction a = from_yaml(engine_yaml("distribution: exponential, rate: [4, 6]", "dense"));
  SynthesisOptions options;
  options.compute = a.config.compute;
  try {
    synthesize(a, options);
    ADD_FAILURE() << "the dense sweep ran exponential noise";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "compute.sweep");
    EXPECT_NE(std::string(error.what()).find("reference"), std::string::npos) << error.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Monte Carlo: the abstract MDP with exponential noise under the reference policy, the adversary
// playing its worst disturbance, against V_0.

TEST(NoiseLawsMonteCarlo, ExponentialSuccessRateMatchesValue) {
  const Abstraction a = from_yaml(
      "name: exponential_monte_carlo\n"
      "states: {lb: [-3, -3], ub: [3, 3], eta: [0.5, 0.5]}\n"
      "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
      "disturbances: {lb: [-0.2], ub: [0.2], eta: [0.4]}\n"
      "dynamics: [\"x0 + u0 + w0\", \"x1 + u1\"]\n"
      "noise: {distribution: exponential, rate: [1.5, 2.5], shift: [-0.6, -0.4], truncation: cutting_probability, "
      "cutting_probability: 1.0e-2}\n"
      "spec: {type: reach_avoid, horizon: 6, target: {lb: [1.5, 1.5], ub: [2.5, 2.5]}, "
      "avoid: {lb: [-0.5, -0.5], ub: [0.5, 0.5]}}\n");
  const Policy policy = synthesize_reference(a, nullptr);
  test_support::AbstractMdpSimulator simulator(a, policy);
  std::mt19937_64 generator(11);
  constexpr int kRuns = 20000;
  int checked_nontrivial = 0;
  for (const std::vector<double>& start : {std::vector<double>{-2.5, -2.5}, {-2.0, 1.0}, {2.5, -1.0}, {0.0, 2.5}}) {
    const std::size_t start_cell = *a.states.cell_of(start.data());
    const double predicted = policy.value(0, start_cell);
    const double rate = simulator.success_rate(start_cell, kRuns, generator);
    const double standard_error = std::sqrt(std::max(predicted * (1 - predicted), 1e-4) / kRuns);
    EXPECT_NEAR(rate, predicted, kMonteCarloStandardErrors * standard_error) << start[0] << ", " << start[1];
    std::printf("exponential monte carlo from (%g, %g): V_0 = %.4f, success rate %.4f over %d runs (4 SE = %.4f)\n",
                start[0], start[1], predicted, rate, kRuns, kMonteCarloStandardErrors * standard_error);
    if (predicted > 0.05 && predicted < 0.95) ++checked_nontrivial;
  }
  EXPECT_GE(checked_nontrivial, 2) << "the Monte Carlo check needs starts with non-trivial probabilities";
}

}  // namespace
}  // namespace amytiss

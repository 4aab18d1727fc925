// Image enclosures of whole system maps (amytiss/enclosure.hpp): the shipped configurations'
// dynamics, the built-in models (their equations as expressions, checked against the C
// functions) and the integrator, over random cells; sampled images lie in the enclosure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"
#include "amytiss/enclosure.hpp"
#include "amytiss/expression.hpp"
#include "amytiss/model.hpp"
#include "enclosure_support.hpp"
#include "robust_oracle.hpp"
#include "bounds/mean_box.hpp"
#include "model/builtin_equations.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace enclosure_test;

constexpr std::uint64_t kSeed = 20261202;
constexpr int kCellsPerConfig = 40;
constexpr int kPointsPerCell = 200;
// The centred form encloses the real map; its double evaluation may lie this far (relative)
// outside. The natural form holds the double values exactly.
constexpr double kFloatingEvaluationSlack = 1e-12;
// The built-in equations as expressions against the C functions: same operations in the same order.
constexpr double kBuiltinAgreement = 1e-13;
// How much wider than the sampled images the enclosure of a cell of width 0.1 may be.
constexpr double kSmallCellOverestimation = 1.3;

Config shipped(const std::string& name) {
  return load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/" + name + ".yaml");
}

std::vector<double> random_in(const std::optional<GridSpec>& grid, std::mt19937_64& random) {
  if (!grid) return {};
  IntervalBox box;
  for (std::size_t j = 0; j < grid->lb.size(); ++j) box.push_back(Interval(grid->lb[j], grid->ub[j]));
  return random_point(box, random);
}

/// A random cell of the configuration's size eta, its centre inside the state box.
IntervalBox random_cell(const Config& config, std::mt19937_64& random) {
  return box_around(random_in(config.states, random), config.states.eta);
}

struct Widths {
  double natural = 0.0, enclosed = 0.0;  // the largest image width / cell width over bounded cells
  double overestimation = 0.0;           // the largest enclosure width / width of the sampled images
  int unbounded_cells = 0;               // cells whose enclosure has an infinite bound

  std::string describe() const {
    return "image width / cell width at most " + std::to_string(enclosed) + " (natural form " +
           std::to_string(natural) + "), enclosure / sampled image width at most " + std::to_string(overestimation) +
           ", " + std::to_string(unbounded_cells) + " unbounded cells";
  }
};

void record_widths(const IntervalBox& cell, const ImageBox& natural, const ImageBox& enclosed,
                   const std::vector<Interval>& sampled, Widths& widths) {
  bool bounded = true;
  for (const Interval& component : enclosed.box) bounded = bounded && std::isfinite(component.width());
  if (!bounded) {
    ++widths.unbounded_cells;
    return;
  }
  for (std::size_t i = 0; i < cell.size(); ++i) {
    widths.natural = std::max(widths.natural, natural.box[i].width() / cell[i].width());
    widths.enclosed = std::max(widths.enclosed, enclosed.box[i].width() / cell[i].width());
    if (sampled[i].width() > 0.0)
      widths.overestimation = std::max(widths.overestimation, enclosed.box[i].width() / sampled[i].width());
  }
}

// Samples images of random cells (the cell's corners and random points) and checks them against
// the enclosures; returns the widths seen.
Widths check_samples(const Config& config, int cells, int points, std::uint64_t seed) {
  const ImageEnclosure enclosure(config);
  const auto dynamics = make_dynamics(config);
  std::mt19937_64 random(seed);
  Widths widths;
  const std::size_t n = config.states.lb.size();
  const unsigned corners = n <= 8 ? 1u << n : 0u;
  std::vector<double> post(n);
  for (int c = 0; c < cells; ++c) {
    const IntervalBox cell = random_cell(config, random);
    const auto u = random_in(config.inputs, random), w = random_in(config.disturbances, random);
    const ImageBox natural = enclosure.natural(cell, u, w);
    const ImageBox enclosed = enclosure.enclose(cell, u, w);
    std::vector<Interval> sampled(n, Interval::empty(true));
    int failures = 0;
    for (unsigned k = 0; k < corners + points && failures < 3; ++k) {
      const auto x = k < corners ? corner(cell, k) : random_point(cell, random);
      dynamics->evaluate(x.data(), u.data(), w.data(), post.data());
      for (std::size_t i = 0; i < n; ++i) {
        sampled[i] = hull(sampled[i], Interval::point(post[i]));
        const double margin = kFloatingEvaluationSlack * (1.0 + std::fabs(post[i]));
        const bool inside = natural.box[i].contains(post[i]) && enclosed.box[i].lo - margin <= post[i] &&
                            post[i] <= enclosed.box[i].hi + margin;
        failures += !inside;
        EXPECT_TRUE(inside) << config.name << ": f_" << i << " = " << post[i] << " outside natural ["
                            << natural.box[i].lo << ", " << natural.box[i].hi << "] or enclosure ["
                            << enclosed.box[i].lo << ", " << enclosed.box[i].hi << "]";
      }
    }
    for (std::size_t i = 0; i < n; ++i) EXPECT_LE(enclosed.box[i].width(), natural.box[i].width());
    record_widths(cell, natural, enclosed, sampled, widths);
  }
  return widths;
}

TEST(Enclosure, ShippedDynamicsHoldSampledImages) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(AMYTISS_SOURCE_DIR) + "/config"))
    if (entry.path().extension() == ".yaml" && YAML::LoadFile(entry.path().string())["dynamics"])
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  int checked = 0;
  for (const auto& file : files) {
    const Config config = load_config_file(file.string());
    SCOPED_TRACE(file.filename().string());
    const Widths widths = check_samples(config, kCellsPerConfig, kPointsPerCell, kSeed + checked);
    std::cout << config.name << ": " << widths.describe() << "\n";
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

TEST(Enclosure, RobotReachAvoidImagesAreAsWideAsTheirCells) {
  // x+ = x + tau u0 (cos u1, sin u1): a translation of the cell, so the image is the cell moved.
  constexpr double kRoundingTolerance = 1e-12;
  const Widths widths = check_samples(shipped("robot_reach_avoid"), 100, 20, kSeed);
  EXPECT_LE(widths.enclosed, 1.0 + kRoundingTolerance);
  EXPECT_GE(widths.enclosed, 1.0);
  EXPECT_EQ(widths.unbounded_cells, 0);
}

// Points of each built-in's state and input space, beyond the saturation limits and around the
// kinematic switch (|x3| < 0.1) of bmw320i.
std::vector<double> builtin_sample(const std::string& model, std::size_t dims, bool input, std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> point(dims);
  for (std::size_t j = 0; j < dims; ++j) point[j] = 3.0 * unit(random);
  if (model == "vehicle3d") return point;
  if (input) {
    point[0] = 0.6 * unit(random);  // steering velocity, limit 0.4
    point[1] = 14.0 * unit(random);  // acceleration, limit 11.5 (less above 7.319 m/s)
  } else {
    point[2] = 1.2 * unit(random);  // steering angle, limit 1.066
    const int regime = static_cast<int>(random() % 3);
    point[3] = regime == 0 ? 0.12 * unit(random) : regime == 1 ? 10.0 * unit(random) : 35.0 + 20.0 * unit(random);
  }
  return point;
}

TEST(Enclosure, BuiltinEquationsAgreeWithTheCFunctions) {
  std::mt19937_64 random(kSeed);
  for (const char* name : {"bmw_paper", "bmw_parking", "vehicle3d"}) {
    const Config config = shipped(name);
    SCOPED_TRACE(config.model);
    const auto field = make_vector_field(config);
    const std::size_t n = field->state_dims(), m = field->input_dims();
    std::vector<Expression> equations;
    for (const std::string& text : builtin_rate_equations(config.model))
      equations.push_back(Expression::parse(text, {}, n, m, 0));
    ASSERT_EQ(equations.size(), n);
    int exact = 0, total = 0;
    std::vector<double> rate(n);
    for (int k = 0; k < 20000; ++k) {
      const auto x = builtin_sample(config.model, n, false, random);
      const auto u = builtin_sample(config.model, m, true, random);
      field->rate(x.data(), u.data(), nullptr, rate.data());
      for (std::size_t i = 0; i < n; ++i) {
        const double expected = rate[i], actual = equations[i].evaluate(x.data(), u.data(), nullptr);
        ++total;
        exact += expected == actual;
        EXPECT_NEAR(actual, expected, kBuiltinAgreement * (1.0 + std::fabs(expected))) << "rate " << i;
      }
    }
    std::cout << config.model << ": " << exact << " of " << total << " rates bit-identical\n";
  }
}

TEST(Enclosure, BuiltinModelsHoldSampledImages) {
  int seed = 0;
  for (const char* name : {"vehicle3d", "bmw_parking", "bmw_paper"}) {
    SCOPED_TRACE(name);
    const Widths widths = check_samples(shipped(name), kCellsPerConfig, kPointsPerCell, kSeed + ++seed);
    std::cout << name << ": " << widths.describe() << "\n";
  }
}

TEST(Enclosure, IntegratedExpressionsHoldSampledImages) {
  Config config = dynamics_config({"x1", "(1 - x0^2)*x1 - x0 + u0"}, 1);
  config.states.lb = {-3, -3};
  config.states.ub = {3, 3};
  config.states.eta = {0.1, 0.1};
  config.name = "van der Pol field";
  config.integrator.tau = 0.1;
  for (const auto method : {IntegrationMethod::Euler, IntegrationMethod::Rk4}) {
    for (const unsigned substeps : {1u, 4u}) {
      config.integrator.method = method;
      config.integrator.substeps = substeps;
      SCOPED_TRACE(to_string(method) + " x" + std::to_string(substeps));
      const Widths widths = check_samples(config, kCellsPerConfig, kPointsPerCell, kSeed + substeps);
      // Small cells: the centred form's excess is second order in the cell width.
      EXPECT_LT(widths.overestimation, kSmallCellOverestimation);
      EXPECT_EQ(widths.unbounded_cells, 0);
      std::cout << "van der Pol dx/dt, " << to_string(method) << " x" << substeps << ": " << widths.describe() << "\n";
    }
  }
}

TEST(Enclosure, JacobianOfTheIntegratedMapBoundsDifferences) {
  constexpr double kDifferenceSlack = 1e-10;
  const Config config = shipped("bmw_parking");  // RK4, two sub-steps
  const ImageEnclosure enclosure(config);
  const auto dynamics = make_dynamics(config);
  std::mt19937_64 random(kSeed);
  const std::size_t n = config.states.lb.size();
  std::vector<double> fx(n), fy(n);
  int valid_rows = 0;
  for (int c = 0; c < kCellsPerConfig; ++c) {
    const IntervalBox cell = random_cell(config, random);
    const auto u = random_in(config.inputs, random);
    const IntervalJacobian jacobian = enclosure.jacobian(cell, u, {});
    for (int k = 0; k < 50; ++k) {
      const auto x = random_point(cell, random), y = random_point(cell, random);
      dynamics->evaluate(x.data(), u.data(), nullptr, fx.data());
      dynamics->evaluate(y.data(), u.data(), nullptr, fy.data());
      for (std::size_t i = 0; i < n; ++i) {
        if (!jacobian.valid[i]) continue;
        valid_rows += k == 0;
        Interval bound = Interval::point(0.0);
        for (std::size_t j = 0; j < n; ++j)
          bound = bound + jacobian.entries[i][j] * (Interval::point(y[j]) - Interval::point(x[j]));
        const double difference = fy[i] - fx[i];
        EXPECT_TRUE(bound.lo - kDifferenceSlack <= difference && difference <= bound.hi + kDifferenceSlack)
            << "row " << i << ": " << difference << " outside [" << bound.lo << ", " << bound.hi << "]";
      }
    }
  }
  EXPECT_GT(valid_rows, 0);
}

// The robust reference fed by enclosures: on a linear map they are the hand-computed mean boxes
// (the bounds agree to rounding); on a nonlinear one the bounds stay ordered and informative.
detail::RobustValues robust_with_enclosure(const std::vector<std::string>& dynamics, const SpecConfig& spec) {
  const Grid states(test_support::grid_spec({-0.95}, {0.95}, {0.1}));
  const Grid none;
  const NoiseModel noise(test_support::normal_noise({0.15 * 0.15}), states);
  const ImageEnclosure enclosure(dynamics_config(dynamics));
  detail::RobustProblem problem{states, none, none, noise, detail::enclosure_mean_box(enclosure, states, none, none),
                                spec.type, spec.horizon,
                                detail::robust_cell_roles(states, spec, detail::Bound::Lower),
                                detail::robust_cell_roles(states, spec, detail::Bound::Upper)};
  return detail::robust_values(problem, detail::AmbiguitySet::Joint);
}

TEST(Enclosure, RobustReferenceBoundsFromEnclosures) {
  constexpr double kRoundingTolerance = 1e-12;
  const SpecConfig spec = test_support::safety_spec(6);
  const detail::RobustValues linear = robust_with_enclosure({"0.8*x0 + 0.1"}, spec);
  // The same map's mean boxes by hand: the faces' images.
  const Grid states(test_support::grid_spec({-0.95}, {0.95}, {0.1}));
  const Grid none;
  const NoiseModel noise(test_support::normal_noise({0.15 * 0.15}), states);
  detail::RobustProblem problem{states, none, none, noise,
                                [&](std::size_t cell, std::size_t, std::size_t, double* lo, double* hi, double*) {
                                  const double centre = states.coordinate(0, cell);
                                  *lo = round_down(0.8 * (centre - 0.05) + 0.1, 3);
                                  *hi = round_up(0.8 * (centre + 0.05) + 0.1, 3);
                                },
                                spec.type, spec.horizon,
                                detail::robust_cell_roles(states, spec, detail::Bound::Lower),
                                detail::robust_cell_roles(states, spec, detail::Bound::Upper)};
  const detail::RobustValues by_hand = detail::robust_values(problem, detail::AmbiguitySet::Joint);
  for (std::size_t c = 0; c < states.size(); ++c) {
    EXPECT_NEAR(linear.lower[c], by_hand.lower[c], kRoundingTolerance);
    EXPECT_NEAR(linear.upper[c], by_hand.upper[c], kRoundingTolerance);
  }
}

// The mean boxes hold the enclosures, rounded outward to a binary grid of at most 2^-40 of a
// cell; images equal in exact arithmetic then give equal boxes: 0.36 x0 + 0.18 x1 at cells
// i, j and i + 1, j - 2 of a grid of 0.1.
TEST(Enclosure, MeanBoxesAreTheEnclosuresOnABinaryGrid) {
  const Grid states(test_support::grid_spec({0.0, 0.0}, {1.6, 1.6}, {0.1, 0.1}));
  const Grid none;
  const ImageEnclosure enclosure(dynamics_config({"0.36*x0 + 0.18*x1", "x1"}));
  const detail::MeanBox mean_box = detail::enclosure_mean_box(enclosure, states, none, none);
  const double quantum = std::ldexp(0.1, -40);
  std::size_t equal_pairs = 0;
  for (std::size_t i = 0; i + 1 < states.count(0); ++i)
    for (std::size_t j = 2; j < states.count(1); ++j) {
      const std::size_t cell = i * states.count(1) + j, neighbour = (i + 1) * states.count(1) + j - 2;
      double lo[2], hi[2], other_lo[2], other_hi[2], expansion[2] = {0, 0};
      mean_box(cell, 0, 0, lo, hi, expansion);
      mean_box(neighbour, 0, 0, other_lo, other_hi, expansion);
      const std::vector<double> centre = states.point(cell);
      const ImageBox image = enclosure.enclose(
          {Interval(centre[0] - 0.05, centre[0] + 0.05), Interval(centre[1] - 0.05, centre[1] + 0.05)}, {}, {});
      for (std::size_t d = 0; d < 2; ++d) {
        EXPECT_LE(lo[d], image.box[d].lo);
        EXPECT_GE(hi[d], image.box[d].hi);
        EXPECT_LE(image.box[d].lo - lo[d], quantum);
        EXPECT_LE(hi[d] - image.box[d].hi, quantum);
      }
      equal_pairs += lo[0] == other_lo[0] && hi[0] == other_hi[0];
    }
  // 16 x 15 pairs; a box next to a point of the grid might round apart from its neighbour's.
  EXPECT_GE(equal_pairs, 16u * 15u - 2u);
}

// Safety on [-1, 1] of x+ = f(x) + N(0, sigma^2) by composite Simpson (kNodes points per cell of
// 0.1): V_T = 1, V_k(x) = integral over [-1, 1] of N(y; f(x), sigma^2) V_{k+1}(y) dy.
std::vector<std::vector<double>> continuous_safety(const Expression& f, double sigma, unsigned horizon) {
  constexpr int kIntervals = 60, kCells = 20;
  constexpr double kEta = 0.1, kStep = kEta / kIntervals;
  const auto node = [&](int cell, int j) { return -1.0 + cell * kEta + j * kStep; };
  std::vector<std::vector<double>> value(kCells, std::vector<double>(kIntervals + 1, 1.0));
  for (unsigned k = 0; k < horizon; ++k) {
    auto next = value;
    for (int c = 0; c < kCells; ++c)
      for (int i = 0; i <= kIntervals; ++i) {
        const double x = node(c, i), mean = f.evaluate(&x, nullptr, nullptr);
        double integral = 0.0;
        for (int t = 0; t < kCells; ++t)
          for (int j = 0; j <= kIntervals; ++j) {
            const double weight = (j == 0 || j == kIntervals) ? 1.0 : (j % 2 ? 4.0 : 2.0);
            const double z = (node(t, j) - mean) / sigma;
            integral += weight * std::exp(-0.5 * z * z) * value[t][j];
          }
        next[c][i] = integral * kStep / 3.0 / (sigma * std::sqrt(2 * M_PI));
      }
    value = std::move(next);
  }
  return value;
}

TEST(Enclosure, RobustBoundsFromEnclosuresBracketANonlinearSystem) {
  constexpr double kQuadratureTolerance = 1e-7;
  const std::string map = "0.8*x0 + 0.1*sin(3*x0) + 0.05";
  const SpecConfig spec = test_support::safety_spec(6);
  const detail::RobustValues bounds = robust_with_enclosure({map}, spec);
  const auto value = continuous_safety(Expression::parse(map, {}, 1, 0, 0), 0.15, spec.horizon);
  double best_lower = 0.0;
  for (std::size_t c = 0; c < value.size(); ++c) {
    for (double v : value[c]) {
      EXPECT_LE(bounds.lower[c], v + kQuadratureTolerance) << "cell " << c;
      EXPECT_GE(bounds.upper[c], v - kQuadratureTolerance) << "cell " << c;
    }
    best_lower = std::max(best_lower, bounds.lower[c]);
  }
  EXPECT_GT(best_lower, 0.5);  // informative, not the trivial [0, 1]
}

}  // namespace
}  // namespace amytiss

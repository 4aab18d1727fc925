// Disturbances over their cells under guarantee: system (bounds/mean_box.hpp, docs/semantics.md
// "What the continuous-system bounds guarantee"): the enclosure of f over a box of disturbances
// holds f at sampled disturbances in it; a disturbance dimension of one point stays that point;
// for a gust 0.3 sin(w) the coarse grid {0, pi} (which alone, as points, misses every gust) gives a
// lower bound below the one its points gave, at most a nested finer grid's, and below the
// continuous value by quadrature against the constant gusts w = pi/2 and 3 pi/2 (both covered);
// the upper bound stays above the value against the grid's points.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "amytiss/enclosure.hpp"
#include "bounds/mean_box.hpp"
#include "robust_oracle.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

constexpr unsigned kSeed = 20261207;
constexpr int kSamples = 2000;
// Nested cells give sub-boxes of the coarse cells' mean boxes: bounds at least as tight, up to
// the mass bounds' and the steps' outward rounding.
constexpr double kNestedSlack = 1e-12;
// Simpson on 4000 intervals of the safe set against sigma 0.05 (h = 2.5e-4): about 1e-10 per step.
constexpr double kQuadratureTolerance = 1e-7;
constexpr int kQuadratureIntervals = 4000;
// The coarse grid's points certified far more than any gust allows: the test fails on points.
constexpr double kPointOvershoot = 0.3;

constexpr double kPi = 3.141592653589793;
constexpr double kSigma = 0.05, kGust = 0.3, kSafe = 0.5;

std::string gust_yaml(const std::string& disturbances) {
  return "name: gust\n"
         "states: {lb: [-0.95], ub: [0.95], eta: [0.1]}\n"
         "disturbances: " + disturbances + "\n"
         "dynamics: [\"0.5*x0 + " + format_number(kGust) + "*sin(w0)\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [" + format_number(kSigma * kSigma) + "]}\n"
         "spec: {type: safety, horizon: 5, safe: {lb: [-0.5], ub: [0.5]}}\n"
         "guarantee: system\n";
}
const std::string kCoarse = "{lb: [0], ub: [3.141592653589793], eta: [3.141592653589793]}";
// Cells of pi/3 nested in the coarse cells [-pi/2, pi/2] and [pi/2, 3 pi/2].
const std::string kFine = "{lb: [-1.0471975511965976], ub: [4.1887902047863905], eta: [1.0471975511965976]}";

TEST(DisturbanceCells, TheEnclosureHoldsTheMapOverABoxOfDisturbances) {
  const Abstraction a = from_yaml(
      "name: w_box\n"
      "states: {lb: [-1, -1], ub: [1, 1], eta: [0.5, 0.5]}\n"
      "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
      "disturbances: {lb: [-1, 0], ub: [1, 2], eta: [0.5, 1]}\n"
      "dynamics: [\"x0*sin(w0) + w1*w1*u0\", \"x1*exp(-w0*w1) + cos(x0 + w0)\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [0.01, 0.01]}\n"
      "spec: {type: safety, horizon: 1}\n");
  const ImageEnclosure enclosure(a.config);
  std::mt19937_64 random(kSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t cell = 0; cell < a.states.size(); cell += 3)
    for (std::size_t w = 0; w < a.disturbances.size(); ++w) {
      const std::vector<double> centre = a.states.point(cell), u = a.inputs.point(2);
      IntervalBox box;
      for (std::size_t j = 0; j < 2; ++j) box.push_back(Interval(centre[j] - 0.25, centre[j] + 0.25));
      const IntervalBox disturbance = disturbance_cell(a.disturbances, w);
      const ImageBox image = enclosure.enclose_over(box, u, disturbance);
      for (int s = 0; s < kSamples / 10; ++s) {
        double x[2], d[2], post[2];
        for (std::size_t j = 0; j < 2; ++j) {
          x[j] = box[j].lo + unit(random) * (box[j].hi - box[j].lo);
          d[j] = disturbance[j].lo + unit(random) * (disturbance[j].hi - disturbance[j].lo);
        }
        a.dynamics->evaluate(x, u.data(), d, post);
        for (std::size_t i = 0; i < 2; ++i) EXPECT_TRUE(image.box[i].contains(post[i])) << "coordinate " << i;
      }
    }
  // A box of one point per disturbance is the point overload, bit for bit.
  const IntervalBox cell{Interval(0.0, 0.5), Interval(-0.5, 0.0)};
  const ImageBox points = enclosure.enclose(cell, {1.0}, std::vector<double>{0.25, 1.5});
  const ImageBox boxes = enclosure.enclose_over(cell, {1.0}, IntervalBox{Interval::point(0.25), Interval::point(1.5)});
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(points.box[i].lo, boxes.box[i].lo);
    EXPECT_EQ(points.box[i].hi, boxes.box[i].hi);
  }
}

TEST(DisturbanceCells, ADimensionOfOnePointIsThatPoint) {
  const Grid mixed(grid_spec({0.3, -1.0}, {0.3, 1.0}, {1.0, 1.0}));  // one point along dimension 0
  for (std::size_t w = 0; w < mixed.size(); ++w) {
    const IntervalBox cell = disturbance_cell(mixed, w);
    ASSERT_EQ(cell.size(), 2u);
    EXPECT_EQ(cell[0].lo, 0.3);
    EXPECT_EQ(cell[0].hi, 0.3);
    EXPECT_EQ(cell[1].lo, mixed.face(1, std::int64_t(w)));
    EXPECT_EQ(cell[1].hi, mixed.face(1, std::int64_t(w) + 1));
  }
  EXPECT_TRUE(disturbance_cell(Grid(), 0).empty());
}

// The value of x' = 0.5 x + kGust * gust + N(0, kSigma^2) staying in [-kSafe, kSafe] for 5 steps,
// by composite Simpson on the safe set, at its nodes (node j: -kSafe + j h).
std::vector<double> continuous_value(double gust, unsigned horizon) {
  const int n = kQuadratureIntervals;
  const double h = 2 * kSafe / n, norm = 1.0 / (kSigma * std::sqrt(2 * kPi));
  std::vector<double> value(n + 1, 1.0);
  for (unsigned k = 0; k < horizon; ++k) {
    std::vector<double> next(n + 1);
    for (int i = 0; i <= n; ++i) {
      const double mean = 0.5 * (-kSafe + i * h) + kGust * gust;
      double integral = 0;
      for (int j = 0; j <= n; ++j) {
        const double z = (-kSafe + j * h - mean) / kSigma;
        integral += (j == 0 || j == n ? 1.0 : (j % 2 ? 4.0 : 2.0)) * std::exp(-0.5 * z * z) * value[j];
      }
      next[i] = norm * h / 3 * integral;
    }
    value = std::move(next);
  }
  return value;
}

// Largest bound - value (lower) and value - bound (upper) over the nodes strictly inside cells.
double lower_excess(const Abstraction& a, const std::vector<double>& lower, const std::vector<double>& value) {
  double excess = -1;
  const double h = 2 * kSafe / kQuadratureIntervals;
  for (int i = 0; i <= kQuadratureIntervals; ++i) {
    const double x = -kSafe + i * h;
    const std::int64_t cell = a.states.nearest(0, x);
    if (std::abs(x - a.states.face(0, cell)) < 1e-9 || std::abs(x - a.states.face(0, cell + 1)) < 1e-9) continue;
    excess = std::max(excess, lower[std::size_t(cell)] - value[std::size_t(i)]);
  }
  return excess;
}

TEST(DisturbanceCells, AGustOverItsCellsIsCoveredAndNestedGridsAreTighter) {
  const Abstraction coarse = from_yaml(gust_yaml(kCoarse)), fine = from_yaml(gust_yaml(kFine));
  const RobustValues coarse_bounds = robust_values_of(coarse, AmbiguitySet::Product);
  const RobustValues fine_bounds = robust_values_of(fine, AmbiguitySet::Product);
  // The old semantics: the grid's points only.
  const ImageEnclosure enclosure(coarse.config);
  const MeanBox points = [&](std::size_t cell, std::size_t, std::size_t w, double* lo, double* hi, double*) {
    const double c = coarse.states.coordinate(0, cell), half = 0.5 * coarse.states.eta()[0];
    const ImageBox image = enclosure.enclose({Interval(c - half, c + half)}, {}, coarse.disturbances.point(w));
    *lo = image.box[0].lo;
    *hi = image.box[0].hi;
  };
  const RobustValues on_points = robust_values_of(coarse, AmbiguitySet::Product, {}, points);
  double nested = -1, overshoot = -1;
  for (std::size_t c = 0; c < coarse.states.size(); ++c) {
    nested = std::max(nested, coarse_bounds.lower[c] - fine_bounds.lower[c]);
    overshoot = std::max(overshoot, on_points.lower[c] - coarse_bounds.lower[c]);
  }
  const std::vector<double> push = continuous_value(1.0, 5), pull = continuous_value(-1.0, 5);
  const std::vector<double> calm = continuous_value(std::sin(kPi), 5);
  double sound = -1, sound_fine = -1, upper = -1;
  for (const auto* value : {&push, &pull}) {
    sound = std::max(sound, lower_excess(coarse, coarse_bounds.lower, *value));
    sound_fine = std::max(sound_fine, lower_excess(fine, fine_bounds.lower, *value));
  }
  std::vector<double> minus_upper(coarse_bounds.upper.size());
  for (std::size_t c = 0; c < minus_upper.size(); ++c) minus_upper[c] = -coarse_bounds.upper[c];
  std::vector<double> minus_calm(calm.size());
  for (std::size_t i = 0; i < calm.size(); ++i) minus_calm[i] = -calm[i];
  upper = lower_excess(coarse, minus_upper, minus_calm);  // calm value - upper bound
  std::printf("[ figures  ] gust 0.3 sin(w): coarse lower - fine lower %.3e; points' lower - coarse cells' lower "
              "%.4f; lower - value (constant gusts) coarse %.3e, fine %.3e; calm value - upper %.3e; at x = 0: "
              "points %.4f, coarse %.4f, fine %.4f, value pushed %.4f\n",
              nested, overshoot, sound, sound_fine, upper, on_points.lower[9], coarse_bounds.lower[9],
              fine_bounds.lower[9], push[kQuadratureIntervals / 2]);
  EXPECT_LE(nested, kNestedSlack);
  EXPECT_GT(overshoot, kPointOvershoot);
  EXPECT_LE(sound, kQuadratureTolerance);
  EXPECT_LE(sound_fine, kQuadratureTolerance);
  EXPECT_LE(upper, kQuadratureTolerance);
}

}  // namespace
}  // namespace amytiss::detail

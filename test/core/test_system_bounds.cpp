// Correctness of the continuous-system bounds (guarantee: system) as the robust reference computes
// them from a configuration: image enclosures of its dynamics (bounds/mean_box.hpp) fed to
// the interval MDP (bounds/cell_roles.hpp, docs/semantics.md "Interval transition bounds").
// - 1-d linear Gaussian reach-avoid whose sets cut cells (also with a disturbance, and with
//   truncated windows): the continuous value of the served controller (the lower bound's, played
//   by the cell that holds the state), by composite Simpson quadrature written here, lies between
//   the bounds at every node, the best controller's below the upper bound; the finite
//   abstraction's values fail the same check.
// - 2-d nonlinear system: Monte Carlo success rates of the continuous system under the served
//   controller lie between the bounds (4 standard errors); a mirrored controller falls below.
// - Sets aligned with cell faces: the abstraction's exact values lie between the bounds; a mean
//   box moved off the image breaks that; with the cell point's image as mean box both bounds are
//   the abstraction's values.
// - The product ambiguity set is at least as tight as the joint interval MDP (equal in 1-d).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/enclosure.hpp"
#include "amytiss/engine.hpp"
#include "robust_oracle.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/cell_roles.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

// Composite Simpson with at least 100 intervals per cell of 0.1 against sigma 0.12: the error of
// one step is below 2 (length) h^4 max|(phi V)''''| / 180 ~ 1e-9 (h = 1e-3, phi'''' ~ 3 / (sigma^5
// sqrt(2 pi)) ~ 5e4), the next value's derivatives of the same order; over 5 steps below 1e-8.
// 1e-7 leaves a margin.
constexpr double kQuadratureTolerance = 1e-9;
constexpr int kIntervalsPerCell = 100;
// Somewhere in a Free cell an informative bound comes this close to the continuous value: the
// bounds are not vacuous (cells of 0.1 against noise of 0.12 leave 0.15 to 0.2).
constexpr double kTightBound = 0.25;
// The abstraction's values overshoot the continuous value of their own controller by more than
// this somewhere (they are no bound of the continuous system): the check can fail.
constexpr double kAbstractionOvershoot = 0.01;
// Bounds and exact values computed in double: rounding differences only.
constexpr double kRoundingTolerance = 1e-12;
// Monte Carlo: standard errors allowed between the empirical success rate and a bound (a false
// alarm has probability ~3e-5 per comparison; the seed is fixed anyway).
constexpr double kStandardErrors = 4.0;
// In 2-d and 3-d the product set's lower bound exceeds the joint one by more than this somewhere.
constexpr double kProductGain = 0.01;

// ---------------------------------------------------------------------------------------------
// Shared pieces

RobustValues system_bounds(const Abstraction& a, AmbiguitySet set, MeanBox mean_box = nullptr) {
  return robust_values_of(a, set, {}, std::move(mean_box));
}

// The abstraction's controller in the robust reference's layout, [k * cells + cell].
std::vector<std::uint32_t> controller_of(const Policy& policy, std::size_t cells) {
  std::vector<std::uint32_t> controller(std::size_t(policy.horizon) * cells);
  for (unsigned k = 0; k < policy.horizon; ++k)
    for (std::size_t c = 0; c < cells; ++c) controller[k * cells + c] = policy.input(k, c);
  return controller;
}

// Where the specification stands at a state of the continuous system (closed boxes; avoid wins).
enum class Place { Undecided, Success, Failure };
Place place_of(const SpecConfig& spec, const double* x) {
  auto in = [x](const Region& region) {
    for (const Box& box : region.boxes) {
      bool inside = true;
      for (std::size_t d = 0; d < box.lb.size(); ++d) inside = inside && !(x[d] < box.lb[d] || x[d] > box.ub[d]);
      if (inside) return true;
    }
    return false;
  };
  if (spec.type == SpecType::Safety) return spec.safe && !in(*spec.safe) ? Place::Failure : Place::Undecided;
  if (spec.avoid && in(*spec.avoid)) return Place::Failure;
  return in(*spec.target) ? Place::Success : Place::Undecided;
}

std::string yaml_list(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + format_number(values[i]);
  return text + "]";
}

// ---------------------------------------------------------------------------------------------
// 1. 1-d linear Gaussian: x' = kSlope x + u + N(0, kSigma^2) on [-1, 1] (20 cells of 0.1).

constexpr double kSlope = 0.9, kSigma = 0.12;

// `noise_options`: more keys of the noise section (e.g. its truncation), each after ", ".
// `disturbance` > 0: a disturbance w0 in {-disturbance, disturbance} added to x'.
std::string linear_1d_yaml(const std::vector<double>& target, const std::vector<double>& avoid,
                           const std::string& noise_options = "", double disturbance = 0) {
  const std::string w = format_number(disturbance);
  return "name: linear_1d\n"
         "states: {lb: [-0.95], ub: [0.95], eta: [0.1]}\n"
         "inputs: {lb: [-0.1], ub: [0.1], eta: [0.1]}\n" +
         (disturbance > 0 ? "disturbances: {lb: [-" + w + "], ub: [" + w + "], eta: [" +
                                format_number(2 * disturbance) + "]}\n"
                          : "") +
         "dynamics: [\"" + format_number(kSlope) + "*x0 + u0" + (disturbance > 0 ? " + w0" : "") + "\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [" + format_number(kSigma * kSigma) + "]" +
         noise_options + "}\n"
         "spec: {type: reach_avoid, horizon: 5, target: {lb: [" + format_number(target[0]) + "], ub: [" +
         format_number(target[1]) + "]}, avoid: {lb: [" + format_number(avoid[0]) + "], ub: [" +
         format_number(avoid[1]) + "]}}\n";
}

// A piece of the covered set [lb - eta/2, last + eta/2] inside one cell and on one side of every
// set boundary (the value is smooth there), with its own Simpson nodes lo + j (hi - lo)/intervals.
struct Segment {
  double lo, hi;
  std::size_t cell;
  Place place;  ///< of its interior
  int intervals;
  double node(int j) const { return lo + (hi - lo) * j / intervals; }
};

std::vector<Segment> segments_1d(const Grid& grid, const SpecConfig& spec) {
  const double eta = grid.eta()[0], first = grid.lb()[0] - 0.5 * eta;
  std::vector<double> cuts;
  for (std::size_t i = 0; i <= grid.size(); ++i) cuts.push_back(first + double(i) * eta);
  const double last = cuts.back();
  for (const auto* set : {&spec.safe, &spec.target, &spec.avoid})
    if (*set)
      for (const Box& box : (*set)->boxes)
        for (double v : {box.lb[0], box.ub[0]})
          if (v > first && v < last) cuts.push_back(v);
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end(), [&](double a, double b) { return b - a < 1e-9 * eta; }),
             cuts.end());
  std::vector<Segment> segments;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double lo = cuts[i], hi = cuts[i + 1], mid = 0.5 * (lo + hi);
    const auto cell = std::min(grid.size() - 1, std::size_t((mid - first) / eta));
    const int intervals = 2 * std::max(1, int(std::ceil((hi - lo) / eta * kIntervalsPerCell / 2)));
    segments.push_back({lo, hi, cell, place_of(spec, &mid), intervals});
  }
  return segments;
}

// V_0 at every segment's nodes (value[s][j]) of x' = kSlope x + u + w + N(0, kSigma^2) under
// `controller`: V = 1 on the target, 0 on the avoid set; V_T = 0 elsewhere; V_k(x) = min over the
// disturbance cells' points and faces (values of the covered set, the grid's points among them) of the integral over the covered set of N(y; kSlope x + u(k, cell of x) + w,
// kSigma^2) V_{k+1}(y) dy (leaving it fails; the disturbance plays its worst, knowing x and u).
// An empty `controller`: the best input of the grid at every node (the optimum over every
// controller that plays inputs of the grid).
std::vector<std::vector<double>> continuous_value_1d(const std::vector<Segment>& segments, const Abstraction& a,
                                                     const std::vector<std::uint32_t>& controller) {
  const Grid& inputs = a.inputs;
  const std::size_t cells = a.states.size();
  // The adversary plays the disturbances' covered set: each cell's point and faces.
  std::vector<double> disturbances;
  for (std::size_t w = 0; w < a.disturbances.size(); ++w) {
    if (!a.disturbances.dims()) {
      disturbances.push_back(0.0);
      continue;
    }
    disturbances.push_back(a.disturbances.point(w)[0]);
    if (w == 0) disturbances.push_back(a.disturbances.face(0, 0));
    disturbances.push_back(a.disturbances.face(0, std::int64_t(w) + 1));
  }
  std::vector<double> nodes, weights;  // all segments' nodes, with their Simpson weights
  std::vector<std::size_t> offset;
  for (const Segment& s : segments) {
    offset.push_back(nodes.size());
    const double h = (s.hi - s.lo) / s.intervals;
    for (int j = 0; j <= s.intervals; ++j) {
      nodes.push_back(s.node(j));
      weights.push_back(h / 3 * ((j == 0 || j == s.intervals) ? 1.0 : (j % 2 ? 4.0 : 2.0)));
    }
  }
  std::vector<double> value(nodes.size());
  for (std::size_t s = 0; s < segments.size(); ++s)
    for (int j = 0; j <= segments[s].intervals; ++j) value[offset[s] + j] = segments[s].place == Place::Success;
  const double norm = 1.0 / (kSigma * std::sqrt(2 * M_PI));
  for (unsigned k = a.horizon; k-- > 0;) {
    std::vector<double> next = value;
    for (std::size_t s = 0; s < segments.size(); ++s) {
      if (segments[s].place != Place::Undecided) continue;
      std::vector<std::size_t> choices;
      if (controller.empty())
        for (std::size_t u = 0; u < inputs.size(); ++u) choices.push_back(u);
      else
        choices.push_back(controller[std::size_t(k) * cells + segments[s].cell]);
      for (int j = 0; j <= segments[s].intervals; ++j) {
        double best = 0;
        for (std::size_t u : choices) {
          double worst = 1;
          for (double w : disturbances) {
            const double mean = kSlope * segments[s].node(j) + inputs.point(u)[0] + w;
            double integral = 0;
            for (std::size_t i = 0; i < nodes.size(); ++i) {
              const double z = (nodes[i] - mean) / kSigma;
              integral += weights[i] * std::exp(-0.5 * z * z) * value[i];
            }
            worst = std::min(worst, norm * integral);
          }
          best = std::max(best, worst);
        }
        next[offset[s] + j] = best;
      }
    }
    value = std::move(next);
  }
  std::vector<std::vector<double>> per_segment;
  for (std::size_t s = 0; s < segments.size(); ++s)
    per_segment.emplace_back(value.begin() + offset[s], value.begin() + offset[s] + segments[s].intervals + 1);
  return per_segment;
}

// Largest lower - V and V - upper over the nodes: everywhere (soundness: <= 0, exactly 0 in fixed
// cells), over the cells where that bound's role is Free, and over those where it is Free and its
// value lies in [kInformative, 1 - kInformative] (how close an informative bound comes to V).
constexpr double kInformative = 0.2;
struct BracketExcess {
  double lower = -std::numeric_limits<double>::infinity(), upper = lower;
  double free_lower = lower, free_upper = lower, informative_lower = lower, informative_upper = lower;
};

BracketExcess bracket_excess(const std::vector<Segment>& segments, const std::vector<std::vector<double>>& value,
                             const std::vector<double>& lower, const std::vector<double>& upper,
                             const std::vector<CellRole>& lower_roles, const std::vector<CellRole>& upper_roles) {
  auto informative = [](double bound) { return bound >= kInformative && bound <= 1 - kInformative; };
  auto raise = [](double& to, double value) { to = std::max(to, value); };
  BracketExcess e;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const std::size_t c = segments[s].cell;
    for (double v : value[s]) {
      raise(e.lower, lower[c] - v);
      raise(e.upper, v - upper[c]);
      if (lower_roles[c] == CellRole::Free) raise(e.free_lower, lower[c] - v);
      if (upper_roles[c] == CellRole::Free) raise(e.free_upper, v - upper[c]);
      if (lower_roles[c] == CellRole::Free && informative(lower[c])) raise(e.informative_lower, lower[c] - v);
      if (upper_roles[c] == CellRole::Free && informative(upper[c])) raise(e.informative_upper, v - upper[c]);
    }
  }
  return e;
}

// The served controller's continuous value lies between the bounds at every node, the best
// controller's below the upper bound; returns the nodes' segments.
std::vector<Segment> expect_brackets_by_quadrature(const Abstraction& a) {
  const std::size_t cells = a.states.size();
  // The dynamics integrated here are the configuration's.
  for (std::size_t c = 0; c < cells; ++c)
    for (std::size_t u = 0; u < a.inputs.size(); ++u)
      for (std::size_t w = 0; w < a.disturbances.size(); ++w) {
        const std::vector<double> x = a.states.point(c), input = a.inputs.point(u), d = a.disturbances.point(w);
        double post = 0;
        a.dynamics->evaluate(x.data(), input.data(), d.data(), &post);
        EXPECT_NEAR(post, kSlope * x[0] + input[0] + (d.empty() ? 0.0 : d[0]), kRoundingTolerance);
      }
  const std::vector<Segment> segments = segments_1d(a.states, a.config.spec);
  const auto lower_roles = robust_cell_roles(a.states, a.config.spec, Bound::Lower);
  const auto upper_roles = robust_cell_roles(a.states, a.config.spec, Bound::Upper);
  const auto optimum = continuous_value_1d(segments, a, {});
  for (AmbiguitySet set : {AmbiguitySet::Joint, AmbiguitySet::Product}) {
    const RobustValues bounds = system_bounds(a, set);
    const auto served = continuous_value_1d(segments, a, bounds.controller);
    const BracketExcess e = bracket_excess(segments, served, bounds.lower, bounds.upper, lower_roles, upper_roles);
    const BracketExcess best = bracket_excess(segments, optimum, bounds.lower, bounds.upper, lower_roles, upper_roles);
    std::printf("[ figures  ] %s %s: max lower - V %.3e, max V - upper %.3e, max V_best - upper %.3e; in Free "
                "cells %.3e, %.3e, %.3e; informative bounds %.4f, %.4f\n",
                a.config.name.c_str(), set == AmbiguitySet::Joint ? "joint" : "product", e.lower, e.upper, best.upper,
                e.free_lower, e.free_upper, best.free_upper, e.informative_lower, e.informative_upper);
    EXPECT_LE(e.lower, kQuadratureTolerance);
    EXPECT_LE(e.upper, kQuadratureTolerance);
    EXPECT_LE(best.upper, kQuadratureTolerance);
    EXPECT_GT(std::max(e.informative_lower, e.informative_upper), -kTightBound);
  }
  return segments;
}

TEST(SystemBounds, LinearGaussianBracketsTheServedControllersValueByQuadrature) {
  // Target and avoid cut cells: the bounds' roles differ from the continuous sets there.
  const Abstraction a = from_yaml(linear_1d_yaml({0.43, 0.77}, {-0.52, -0.28}));
  const std::vector<Segment> segments = expect_brackets_by_quadrature(a);
  // The finite abstraction's values (cell points, exact masses) under its own controller: the
  // same check finds them above the continuous value, so it is not one that cannot fail.
  const std::size_t cells = a.states.size();
  const Policy policy = synthesize_reference(a, nullptr);
  const auto value = continuous_value_1d(segments, a, controller_of(policy, cells));
  const std::vector<double> abstraction(policy.values.begin(), policy.values.begin() + cells);
  const BracketExcess e = bracket_excess(segments, value, abstraction, abstraction, a.roles, a.roles);
  std::printf("[ figures  ] abstraction: max V_abs - V %.4f (in informative Free cells %.4f)\n", e.lower,
              e.informative_lower);
  EXPECT_GT(e.informative_lower, kAbstractionOvershoot);
}

TEST(SystemBounds, LinearGaussianWithADisturbanceBracketsByQuadrature) {
  // The disturbance plays its worst against both the bounds and the continuous system: its grid
  // {-0.015, 0.015} covers [-0.03, 0.03].
  expect_brackets_by_quadrature(from_yaml(linear_1d_yaml({0.43, 0.77}, {-0.52, -0.28}, "", 0.015)));
}

TEST(SystemBounds, LinearGaussianWithTruncatedWindowsBracketsByQuadrature) {
  // Windows of about +-3.3 sigma: the cut mass counts as failure in the lower bound and as
  // success in the upper; the continuous system cuts nothing.
  expect_brackets_by_quadrature(from_yaml(linear_1d_yaml(
      {0.43, 0.77}, {-0.52, -0.28}, ", truncation: cutting_probability, cutting_probability: 1.0e-3")));
}

// ---------------------------------------------------------------------------------------------
// 2. Monte Carlo of a 2-d nonlinear system: x0' = x0 + kDrift sin(x1), x1' = kDamping x1 + u0,
// plus N(0, kSigma2d^2) per coordinate, on [-1, 1]^2 (cells of 0.1).

constexpr double kDrift = 0.3, kDamping = 0.9, kSigma2d = 0.1;
constexpr int kRunsPerStart = 2000;
constexpr std::size_t kStartCells = 4;
constexpr double kInformativeLower = 0.2;

// `disturbance` > 0: a disturbance w0 in {-disturbance, disturbance} added to x0'.
std::string heading_2d_yaml(double disturbance = 0, unsigned horizon = 6) {
  const std::string w = format_number(disturbance);
  return "name: heading_2d\n"
         "states: {lb: [-0.95, -0.95], ub: [0.95, 0.95], eta: [0.1, 0.1]}\n"
         "inputs: {lb: [-0.3], ub: [0.3], eta: [0.15]}\n" +
         (disturbance > 0 ? "disturbances: {lb: [-" + w + "], ub: [" + w + "], eta: [" +
                                format_number(2 * disturbance) + "]}\n"
                          : "") +
         "dynamics: [\"x0 + " + format_number(kDrift) + "*sin(x1)" + (disturbance > 0 ? " + w0" : "") + "\", \"" +
         format_number(kDamping) + "*x1 + u0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: " +
         yaml_list({kSigma2d * kSigma2d, kSigma2d * kSigma2d}) + "}\n"
         "spec: {type: reach_avoid, horizon: " + std::to_string(horizon) +
         ", target: {lb: [-0.2, -0.2], ub: [0.2, 0.2]},\n"
         "       avoid: {lb: [0.4, -0.8], ub: [0.8, -0.4]}}\n";
}

// The fraction of kRunsPerStart runs of the continuous system from `start` under `controller`
// (played by the cell that holds the state) that satisfy the specification: the sets checked at
// every step 0..T, a state off the covered set fails.
double success_rate(const Abstraction& a, const std::vector<std::uint32_t>& controller,
                    const std::vector<double>& start, std::mt19937_64& random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const std::size_t cells = a.states.size();
  int successes = 0;
  for (int run = 0; run < kRunsPerStart; ++run) {
    std::vector<double> x = start;
    for (unsigned k = 0;; ++k) {
      const auto cell = a.states.cell_of(x.data());
      const Place place = cell ? place_of(a.config.spec, x.data()) : Place::Failure;
      if (place != Place::Undecided || k == a.horizon) {
        successes += place == Place::Success;
        break;
      }
      const double u = a.inputs.point(controller[std::size_t(k) * cells + *cell])[0];
      const double x0 = x[0] + kDrift * std::sin(x[1]) + kSigma2d * normal(random);
      x[1] = kDamping * x[1] + u + kSigma2d * normal(random);
      x[0] = x0;
    }
  }
  return double(successes) / kRunsPerStart;
}

double standard_error(double rate) {
  const double p = std::clamp(rate, 0.5 / kRunsPerStart, 1 - 0.5 / kRunsPerStart);
  return std::sqrt(p * (1 - p) / kRunsPerStart);
}

TEST(SystemBounds, MonteCarloOfANonlinearSystemLiesBetweenTheBounds) {
  const Abstraction a = from_yaml(heading_2d_yaml());
  const std::size_t cells = a.states.size();
  std::mt19937_64 random(20261201);
  // The dynamics simulated here are the configuration's.
  std::uniform_real_distribution<double> anywhere(-1.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const double x[2] = {anywhere(random), anywhere(random)}, u = 0.15;
    double post[2];
    a.dynamics->evaluate(x, &u, nullptr, post);
    ASSERT_NEAR(post[0], x[0] + kDrift * std::sin(x[1]), kRoundingTolerance);
    ASSERT_NEAR(post[1], kDamping * x[1] + u, kRoundingTolerance);
  }
  const auto roles = robust_cell_roles(a.states, a.config.spec, Bound::Lower);
  for (AmbiguitySet set : {AmbiguitySet::Joint, AmbiguitySet::Product}) {
    const RobustValues bounds = system_bounds(a, set);
    std::vector<std::uint32_t> mirrored = bounds.controller;  // steers the other way
    for (auto& u : mirrored) u = std::uint32_t(a.inputs.size() - 1 - u);
    // Start cells where the bounds are closest (the most demanding check), the lower bound not
    // trivial; 3 random points in each.
    std::vector<std::size_t> starts;
    for (std::size_t c = 0; c < cells; ++c)
      if (roles[c] == CellRole::Free && bounds.lower[c] > kInformativeLower) starts.push_back(c);
    ASSERT_GE(starts.size(), kStartCells);
    std::partial_sort(starts.begin(), starts.begin() + kStartCells, starts.end(), [&](std::size_t p, std::size_t q) {
      return bounds.upper[p] - bounds.lower[p] < bounds.upper[q] - bounds.lower[q];
    });
    double mirrored_shortfall = -std::numeric_limits<double>::infinity();  // max of lower - 4 SE - rate
    double closest_lower = std::numeric_limits<double>::infinity(), closest_upper = closest_lower;  // in SE
    for (std::size_t i = 0; i < kStartCells; ++i) {
      const std::size_t cell = starts[i];
      for (int point = 0; point < 3; ++point) {
        std::vector<double> x = a.states.point(cell);
        for (std::size_t d = 0; d < 2; ++d) x[d] += a.states.eta()[d] * (anywhere(random) * 0.5);
        const double rate = success_rate(a, bounds.controller, x, random);
        const double se = standard_error(rate);
        closest_lower = std::min(closest_lower, (rate - bounds.lower[cell]) / se);
        closest_upper = std::min(closest_upper, (bounds.upper[cell] - rate) / se);
        EXPECT_GE(rate, bounds.lower[cell] - kStandardErrors * se) << "cell " << cell;
        EXPECT_LE(rate, bounds.upper[cell] + kStandardErrors * se) << "cell " << cell;
        const double other = success_rate(a, mirrored, x, random);
        mirrored_shortfall =
            std::max(mirrored_shortfall, bounds.lower[cell] - kStandardErrors * standard_error(other) - other);
      }
    }
    // A wrong controller falls below the lower bound: the check can fail.
    std::printf("[ figures  ] %s: %zu start cells: min (rate - lower)/SE %.1f, min (upper - rate)/SE "
                "%.1f; "
                "mirrored controller below lower - 4 SE by up to %.3f\n",
                set == AmbiguitySet::Joint ? "joint" : "product", kStartCells, closest_lower, closest_upper,
                mirrored_shortfall);
    EXPECT_GT(mirrored_shortfall, 0.0);
  }
}

// ---------------------------------------------------------------------------------------------
// 3. Sets aligned with cell faces: the robust roles are the abstraction's, and the abstraction's
// row at the cell's point is one distribution of the interval set, so its exact value lies between
// the bounds (by induction over the steps). No truncation: a truncated abstraction drops mass that
// the interval set keeps, and its value may then fall below the lower bound by up to the cut mass.

// The largest lower - V_abs and V_abs - upper over the cells (<= 0 when bracketed), and over the
// Free cells (how close the bounds come).
struct AbstractionExcess {
  double lower = -std::numeric_limits<double>::infinity(), upper = lower, free_lower = lower, free_upper = lower;
};

AbstractionExcess abstraction_excess(const RobustValues& bounds, const std::vector<double>& abstraction,
                                     const std::vector<CellRole>& roles) {
  AbstractionExcess e;
  for (std::size_t c = 0; c < abstraction.size(); ++c) {
    e.lower = std::max(e.lower, bounds.lower[c] - abstraction[c]);
    e.upper = std::max(e.upper, abstraction[c] - bounds.upper[c]);
    if (roles[c] != CellRole::Free) continue;
    e.free_lower = std::max(e.free_lower, bounds.lower[c] - abstraction[c]);
    e.free_upper = std::max(e.free_upper, abstraction[c] - bounds.upper[c]);
  }
  return e;
}

std::vector<double> abstraction_values(const Abstraction& a) {
  const Policy policy = synthesize_reference(a, nullptr);
  return std::vector<double>(policy.values.begin(), policy.values.begin() + a.states.size());
}

void expect_brackets_the_abstraction(const std::string& yaml) {
  const Abstraction a = from_yaml(yaml);
  ASSERT_EQ(a.roles, robust_cell_roles(a.states, a.config.spec, Bound::Lower));
  ASSERT_EQ(a.roles, robust_cell_roles(a.states, a.config.spec, Bound::Upper));
  const std::vector<double> abstraction = abstraction_values(a);
  for (AmbiguitySet set : {AmbiguitySet::Joint, AmbiguitySet::Product}) {
    const AbstractionExcess e = abstraction_excess(system_bounds(a, set), abstraction, a.roles);
    std::printf("[ figures  ] %s %s: max lower - V_abs %.3e, max V_abs - upper %.3e; in Free cells %.3e, %.3e\n",
                a.config.name.c_str(), set == AmbiguitySet::Joint ? "joint" : "product", e.lower, e.upper,
                e.free_lower, e.free_upper);
    EXPECT_LE(e.lower, kRoundingTolerance);
    EXPECT_LE(e.upper, kRoundingTolerance);
  }
}

TEST(SystemBounds, AlignedSetsLinearBracketTheAbstraction) {
  expect_brackets_the_abstraction(linear_1d_yaml({0.4, 0.8}, {-0.5, -0.3}));
}

TEST(SystemBounds, AlignedSetsNonlinearWithDisturbanceBracketTheAbstraction) {
  expect_brackets_the_abstraction(heading_2d_yaml(0.05, 3));
}

TEST(SystemBounds, AlignedSetsCheckFindsAMeanBoxOffTheImage) {
  // The enclosure moved by one cell no longer holds the image of the cell's point: the bounds
  // then miss the abstraction's value somewhere (the check can fail).
  const Abstraction a = from_yaml(linear_1d_yaml({0.4, 0.8}, {-0.5, -0.3}));
  const ImageEnclosure enclosure(a.config);
  const MeanBox image = enclosure_mean_box(enclosure, a.states, a.inputs, a.disturbances);
  const double eta = a.states.eta()[0];
  const MeanBox moved = [&](std::size_t cell, std::size_t u, std::size_t w, double* lo, double* hi, double* expansion) {
    image(cell, u, w, lo, hi, expansion);
    *lo += eta;
    *hi += eta;
  };
  const AbstractionExcess e =
      abstraction_excess(system_bounds(a, AmbiguitySet::Joint, moved), abstraction_values(a), a.roles);
  std::printf("[ figures  ] moved mean box: max lower - V_abs %.4f, max V_abs - upper %.4f\n", e.lower, e.upper);
  EXPECT_GT(std::max(e.lower, e.upper), kAbstractionOvershoot);
}

// With the image of the cell's point as its mean box (lo = hi: no longer a bound for the cell) the
// interval set holds little more than the abstraction's row: both bounds are the abstraction's
// values up to the bounds' deliberate outward rounding (per step each mass widened by a few 1e-15,
// each expectation moved by (4K + 4) u for K <= 402 outcomes: about 2e-12 per step, at most 6 steps).
// The masses, windows, leaving mass and the Bellman step agree with the engine's to that.
constexpr double kOutwardRounding = 1e-10;

void expect_point_boxes_reproduce_the_abstraction(const std::string& yaml) {
  const Abstraction a = from_yaml(yaml);
  const MeanBox point = [&a](std::size_t cell, std::size_t u, std::size_t w, double* lo, double* hi, double*) {
    const std::vector<double> x = a.states.point(cell), input = a.inputs.point(u), d = a.disturbances.point(w);
    a.dynamics->evaluate(x.data(), input.data(), d.data(), lo);
    std::copy(lo, lo + a.states.dims(), hi);
  };
  const std::vector<double> abstraction = abstraction_values(a);
  for (AmbiguitySet set : {AmbiguitySet::Joint, AmbiguitySet::Product}) {
    const RobustValues bounds = system_bounds(a, set, point);
    double largest = 0;
    for (std::size_t c = 0; c < abstraction.size(); ++c)
      largest = std::max(
          {largest, std::abs(bounds.lower[c] - abstraction[c]), std::abs(bounds.upper[c] - abstraction[c])});
    std::printf("[ figures  ] %s %s, point mean boxes: max |bound - V_abs| %.3e\n", a.config.name.c_str(),
                set == AmbiguitySet::Joint ? "joint" : "product", largest);
    EXPECT_LE(largest, kOutwardRounding);
  }
}

TEST(SystemBounds, PointMeanBoxesReproduceTheAbstraction) {
  expect_point_boxes_reproduce_the_abstraction(linear_1d_yaml({0.4, 0.8}, {-0.5, -0.3}));
  expect_point_boxes_reproduce_the_abstraction(heading_2d_yaml(0.05, 3));
}

// ---------------------------------------------------------------------------------------------
// 4. Product (orthogonally decoupled) against joint ambiguity sets, without truncation: every
// distribution the product recursion considers lies in the joint interval set, so its bounds are
// at least as tight; in 1-d the two are the same set.

void expect_product_at_least_as_tight(const std::string& yaml) {
  const Abstraction a = from_yaml(yaml);
  const RobustValues joint = system_bounds(a, AmbiguitySet::Joint);
  const RobustValues product = system_bounds(a, AmbiguitySet::Product);
  double lower_gain = -std::numeric_limits<double>::infinity(), upper_gain = lower_gain;
  for (std::size_t c = 0; c < a.states.size(); ++c) {
    EXPECT_GE(product.lower[c], joint.lower[c] - kRoundingTolerance) << "cell " << c;
    EXPECT_LE(product.upper[c], joint.upper[c] + kRoundingTolerance) << "cell " << c;
    lower_gain = std::max(lower_gain, product.lower[c] - joint.lower[c]);
    upper_gain = std::max(upper_gain, joint.upper[c] - product.upper[c]);
  }
  std::printf("[ figures  ] %s: product lower above joint by up to %.4f, upper below by up to %.4f\n",
              a.config.name.c_str(), lower_gain, upper_gain);
  // Strictly tighter somewhere: in several dimensions the sets differ.
  EXPECT_GT(lower_gain, kProductGain);
}

TEST(SystemBounds, ProductAtLeastAsTightAsJointInTwoDimensions) {
  expect_product_at_least_as_tight(heading_2d_yaml(0.05, 3));
}

TEST(SystemBounds, ProductAtLeastAsTightAsJointInThreeDimensions) {
  expect_product_at_least_as_tight(
      "name: coupled_3d\n"
      "states: {lb: [-0.9, -0.9, -0.9], ub: [0.9, 0.9, 0.9], eta: [0.3, 0.3, 0.3]}\n"
      "inputs: {lb: [-0.2], ub: [0.2], eta: [0.4]}\n"
      "dynamics: [\"0.8*x0 + 0.2*sin(x1)\", \"0.7*x1 + 0.2*x0*x2\", \"0.6*x2 + 0.1*cos(x0) + u0\"]\n"
      "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04, 0.02]}\n"
      "spec: {type: reach_avoid, horizon: 3, target: {lb: [-0.15, -0.15, -0.15], ub: [0.15, 0.15, 0.15]},\n"
      "       avoid: {lb: [0.45, 0.45, -0.9], ub: [0.9, 0.9, 0.9]}}\n");
}

TEST(SystemBounds, ProductEqualsJointInOneDimension) {
  const Abstraction a = from_yaml(linear_1d_yaml({0.43, 0.77}, {-0.52, -0.28}));
  const RobustValues joint = system_bounds(a, AmbiguitySet::Joint);
  const RobustValues product = system_bounds(a, AmbiguitySet::Product);
  for (std::size_t c = 0; c < a.states.size(); ++c) {
    EXPECT_NEAR(product.lower[c], joint.lower[c], kRoundingTolerance) << "cell " << c;
    EXPECT_NEAR(product.upper[c], joint.upper[c], kRoundingTolerance) << "cell " << c;
  }
  EXPECT_EQ(product.controller, joint.controller);
}

}  // namespace
}  // namespace amytiss::detail

// Interval arithmetic (amytiss/interval.hpp) through the expression grammar: for every operator
// and function, random boxes and many random points inside them; every value lies in the natural
// enclosure and (up to the double evaluation's own rounding) in the centred one, and every
// difference f(y) - f(x) lies in the interval Jacobian times y - x.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "amytiss/enclosure.hpp"
#include "amytiss/expression.hpp"
#include "amytiss/interval.hpp"
#include "enclosure_support.hpp"

namespace amytiss {
namespace {

using namespace enclosure_test;

constexpr std::uint64_t kSeed = 20261201;
constexpr int kBoxesPerExpression = 300;
constexpr int kPointsPerBox = 60;
constexpr int kPairsPerBox = 10;
// The double evaluation of f rounds too: the centred form encloses the real f, the double value
// may lie this far (relative) outside it. The natural form holds the double values exactly.
constexpr double kFloatingEvaluationSlack = 1e-12;
constexpr double kDifferenceSlack = 1e-9;  // f(y) - f(x) from two rounded evaluations

const char* const kExpressions[] = {
    "x0 + x1", "x0 - x1", "x0 * x1", "x0 / x1", "-x0", "x0 - x0", "x0 * (1 - x0)",
    "x0 ^ 2", "x0 ^ 3", "x0 ^ -2", "x0 ^ -1", "x0 ^ 0", "x0 ^ 0.5", "x0 ^ 2.5", "2 ^ x0",
    "pow(x0, x1)", "pow(abs(x0), x1)", "pow(x0, 3)",
    "!x0", "!(x0 - x1)", "x0 < x1", "x0 <= x1", "x0 > x1", "x0 >= x1", "floor(x0) == floor(x1)",
    "floor(x0) != ceil(x1)", "x0 > 0 && x1 > 0", "x0 > 0 || x1 < 0", "x0 > x1 ? x0 * x1 : x1 - x0",
    "if(x0, sin(x1), cos(x1))", "x0 > 0 ? log(x0) : x0",
    "sin(x0)", "cos(x0)", "tan(x0)", "asin(x0)", "acos(x0)", "atan(x0)", "atan2(x0, x1)",
    "exp(x0)", "log(x0)", "sqrt(x0)", "abs(x0)", "min(x0, x1)", "max(x0, x1)", "floor(x0)", "ceil(x0)",
    "sin(x0) * cos(x1) + x0 ^ 2", "exp(-x0 * x0) / (1 + x1 * x1)", "sqrt(x0 * x0 + x1 * x1)",
    "atan2(sin(x0), cos(x0)) - x1 / 3", "tan(x0 / 2) * asin(x1 / 40)", "log(1 + exp(x0)) - max(x0, 0)",
};

// Boxes at several scales, some near the points where functions change (0, +-1, multiples of
// pi/2), widths from 1e-6 to twice the scale.
IntervalBox random_box(std::mt19937_64& random) {
  static const double kSpecial[] = {0.0, 1.0, -1.0, M_PI / 2, -M_PI / 2, M_PI, -M_PI, 2 * M_PI, 0.5, 3 * M_PI / 2};
  static const double kScales[] = {0.01, 1.0, 4.0, 30.0};
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  IntervalBox box;
  for (int j = 0; j < 2; ++j) {
    const double scale = kScales[random() % 4];
    const double centre = unit(random) < 0.3 ? kSpecial[random() % 10] + 1e-3 * (2 * unit(random) - 1)
                                              : scale * (2 * unit(random) - 1);
    const double width = scale * std::pow(10.0, -6.0 + 6.3 * unit(random));
    box.push_back(Interval(centre - 0.5 * width, centre + 0.5 * width));
  }
  return box;
}

Interval difference_bound(const IntervalJacobian& jacobian, const std::vector<double>& x, const std::vector<double>& y) {
  Interval sum = Interval::point(0.0);
  for (std::size_t j = 0; j < x.size(); ++j)
    sum = sum + jacobian.entries[0][j] * (Interval::point(y[j]) - Interval::point(x[j]));
  return sum;
}

bool within(const Interval& interval, double value, double slack) {
  const double margin = slack * (1.0 + std::fabs(value));
  return interval.lo - margin <= value && value <= interval.hi + margin;
}

TEST(Interval, EveryOperatorAndFunctionEnclosesSampledValues) {
  std::mt19937_64 random(kSeed);
  for (const char* text : kExpressions) {
    SCOPED_TRACE(text);
    const Expression expression = Expression::parse(text, {}, 2, 0, 0);
    const ImageEnclosure enclosure(dynamics_config({text, "x1"}));
    int failures = 0;
    for (int b = 0; b < kBoxesPerExpression && failures < 5; ++b) {
      const IntervalBox box = random_box(random);
      const ImageBox natural = enclosure.natural(box, {}, {});
      const ImageBox enclosed = enclosure.enclose(box, {}, {});
      const IntervalJacobian jacobian = enclosure.jacobian(box, {}, {});
      EXPECT_LE(enclosed.box[0].width(), natural.box[0].width());
      for (int k = 0; k < kPointsPerBox + 4 && failures < 5; ++k) {
        const auto x = k < 4 ? corner(box, k) : random_point(box, random);
        const double value = expression.evaluate(x.data(), nullptr, nullptr);
        if (std::isnan(value)) {
          failures += natural.defined;
          EXPECT_FALSE(natural.defined) << "undefined at (" << x[0] << ", " << x[1] << ") but not flagged";
          continue;
        }
        const bool inside = natural.box[0].contains(value) && within(enclosed.box[0], value, kFloatingEvaluationSlack);
        failures += !inside;
        EXPECT_TRUE(inside) << "f(" << x[0] << ", " << x[1] << ") = " << value << " outside natural ["
                            << natural.box[0].lo << ", " << natural.box[0].hi << "] or enclosure ["
                            << enclosed.box[0].lo << ", " << enclosed.box[0].hi << "]";
      }
      if (!jacobian.valid[0] || !natural.defined) continue;
      for (int k = 0; k < kPairsPerBox; ++k) {
        const auto x = random_point(box, random), y = random_point(box, random);
        const double difference =
            expression.evaluate(y.data(), nullptr, nullptr) - expression.evaluate(x.data(), nullptr, nullptr);
        if (!std::isfinite(difference)) continue;
        const Interval bound = difference_bound(jacobian, x, y);
        const double scale = std::fabs(expression.evaluate(x.data(), nullptr, nullptr));
        EXPECT_TRUE(bound.lo - kDifferenceSlack * (1 + scale) <= difference &&
                    difference <= bound.hi + kDifferenceSlack * (1 + scale))
            << "f(y) - f(x) = " << difference << " outside J (y - x) = [" << bound.lo << ", " << bound.hi << "]";
      }
    }
  }
}

TEST(Interval, LinearMapsAreExactUpToRounding) {
  constexpr double kRoundingTolerance = 1e-14;
  const ImageEnclosure enclosure(dynamics_config({"x0 + 0.5*x1", "2*x0 - x1 + 3"}));
  const ImageBox image = enclosure.enclose({Interval(1.0, 2.0), Interval(3.0, 5.0)}, {}, {});
  EXPECT_NEAR(image.box[0].lo, 2.5, kRoundingTolerance);
  EXPECT_NEAR(image.box[0].hi, 4.5, kRoundingTolerance);
  EXPECT_NEAR(image.box[1].lo, 0.0, kRoundingTolerance);
  EXPECT_NEAR(image.box[1].hi, 4.0, kRoundingTolerance);
  EXPECT_TRUE(image.box[0].contains(2.5) && image.box[0].contains(4.5));
}

TEST(Interval, CentredFormRemovesTheDependencyOfRepeatedVariables) {
  const ImageEnclosure enclosure(dynamics_config({"x0 - x0 + x0 * (1 - x0)"}));
  const IntervalBox cell{Interval(0.2, 0.3)};
  const double natural = enclosure.natural(cell, {}, {}).box[0].width();
  const double centred = enclosure.enclose(cell, {}, {}).box[0].width();
  const double exact = 0.3 * 0.7 - 0.2 * 0.8;  // x(1 - x) increases on [0.2, 0.3]
  EXPECT_GT(natural, 4 * exact);
  EXPECT_LT(centred, 1.5 * exact);
}

TEST(Interval, PeriodicFunctionsFindTheirExtremaInside) {
  const Interval s = sin(Interval(0.1, 3.0));
  EXPECT_EQ(s.hi, 1.0);
  EXPECT_LE(s.lo, std::sin(0.1));
  EXPECT_GT(s.lo, 0.0);
  const Interval c = cos(Interval(-0.1, 0.2));
  EXPECT_EQ(c.hi, 1.0);
  EXPECT_LE(c.lo, std::cos(0.2));
  EXPECT_EQ(cos(Interval(3.0, 3.2)).lo, -1.0);
  EXPECT_EQ(sin(Interval(-100.0, 100.0)).lo, -1.0);
}

TEST(Interval, DomainEdgesAreUnboundedOrFlagged) {
  const Interval pole = tan(Interval(1.5, 1.6));
  EXPECT_TRUE(std::isinf(pole.lo) && std::isinf(pole.hi) && pole.defined);
  const Interval half_log = log(Interval(-1.0, 2.0));
  EXPECT_FALSE(half_log.defined);
  EXPECT_TRUE(std::isinf(half_log.lo));
  EXPECT_GE(half_log.hi, std::log(2.0));
  EXPECT_TRUE(sqrt(Interval(-2.0, -1.0)).is_empty());
  EXPECT_FALSE(asin(Interval(0.5, 1.5)).defined);
  const Interval quotient = Interval(1.0, 2.0) / Interval(-1.0, 1.0);
  EXPECT_TRUE(std::isinf(quotient.lo) && std::isinf(quotient.hi) && quotient.defined);
  EXPECT_FALSE((Interval(-1.0, 2.0) / Interval(0.0, 1.0)).defined);  // 0/0 is possible
  const Interval cut = atan2(Interval(-0.1, 0.1), Interval(-2.0, -1.0));
  EXPECT_LE(cut.lo, -M_PI);
  EXPECT_GE(cut.hi, M_PI);
  // A branch that no point takes does not spoil the enclosure.
  const ImageEnclosure guarded(dynamics_config({"x0 > 0 ? log(x0) : 0"}));
  const ImageBox image = guarded.enclose({Interval(-2.0, -1.0)}, {}, {});
  EXPECT_TRUE(image.defined);
  EXPECT_EQ(image.box[0].lo, 0.0);
  EXPECT_EQ(image.box[0].hi, 0.0);
}

TEST(Interval, RoundingIsOutward) {
  const Interval third = Interval::point(1.0) / Interval::point(3.0);
  EXPECT_LT(third.lo, third.hi);
  EXPECT_LE(third.lo, 1.0 / 3.0);
  EXPECT_GE(third.hi, 1.0 / 3.0);
  const Interval sum = Interval::point(0.1) + Interval::point(0.2);
  EXPECT_LT(sum.lo, 0.1 + 0.2);
  EXPECT_GT(sum.hi, 0.1 + 0.2);
  // libm results are not correctly rounded: their bounds move outward by more than one step.
  const double x = 0.7;
  const struct {
    Interval enclosure;
    double value;
  } kFunctions[] = {{sin(Interval::point(x)), std::sin(x)},   {cos(Interval::point(x)), std::cos(x)},
                    {tan(Interval::point(x)), std::tan(x)},   {exp(Interval::point(x)), std::exp(x)},
                    {log(Interval::point(x)), std::log(x)},   {asin(Interval::point(x)), std::asin(x)},
                    {acos(Interval::point(x)), std::acos(x)}, {atan(Interval::point(x)), std::atan(x)},
                    {sqrt(Interval::point(x)), std::sqrt(x)}, {pow(Interval::point(x), Interval::point(x)), std::pow(x, x)}};
  for (const auto& function : kFunctions) {
    EXPECT_LT(function.enclosure.lo, function.value);
    EXPECT_GT(function.enclosure.hi, function.value);
    EXPECT_LT(function.enclosure.width(), 1e-14);
  }
}

TEST(Interval, JacobianOfAKnownFunction) {
  const ImageEnclosure enclosure(dynamics_config({"sin(x0) * x1", "x0"}));
  const IntervalBox cell{Interval(0.5, 0.7), Interval(2.0, 3.0)};
  const IntervalJacobian jacobian = enclosure.jacobian(cell, {}, {});
  ASSERT_TRUE(jacobian.valid[0]);
  // d/dx0 = cos(x0) x1 in [cos(0.7) 2, cos(0.5) 3]; d/dx1 = sin(x0) in [sin(0.5), sin(0.7)].
  EXPECT_LE(jacobian.entries[0][0].lo, std::cos(0.7) * 2.0);
  EXPECT_GE(jacobian.entries[0][0].hi, std::cos(0.5) * 3.0);
  EXPECT_LE(jacobian.entries[0][1].lo, std::sin(0.5));
  EXPECT_GE(jacobian.entries[0][1].hi, std::sin(0.7));
  EXPECT_LT(jacobian.entries[0][1].width(), 2 * (std::sin(0.7) - std::sin(0.5)));
  EXPECT_EQ(jacobian.entries[1][0].lo, 1.0);
  EXPECT_EQ(jacobian.entries[1][1].hi, 0.0);
}

}  // namespace
}  // namespace amytiss

TEST(Interval, OutwardRoundingStepsLikeNextafter) {
  // Every kind of double: zeros of both signs, subnormals, the extremes, infinities, NaN and
  // random bit patterns (fixed seed).
  const double infinity = std::numeric_limits<double>::infinity();
  std::vector<double> samples = {0.0, -0.0, std::numeric_limits<double>::denorm_min(),
                                 -std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::min(),
                                 std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(), infinity,
                                 -infinity, 1.0, -1.0, 0.5, 1e-310, -1e-310};
  std::mt19937_64 random(20261201);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t bits = random();
    double value;
    std::memcpy(&value, &bits, sizeof value);
    samples.push_back(value);
  }
  for (double value : samples) {
    const double down = std::nextafter(value, -infinity), up = std::nextafter(value, infinity);
    if (std::isnan(value)) {
      EXPECT_TRUE(std::isnan(amytiss::round_down(value)) && std::isnan(amytiss::round_up(value)));
      continue;
    }
    const double rounded_up = amytiss::round_up(value), rounded_down = amytiss::round_down(value);
    EXPECT_EQ(std::memcmp(&up, &rounded_up, sizeof up), 0) << value;
    EXPECT_EQ(std::memcmp(&down, &rounded_down, sizeof down), 0) << value;
    EXPECT_EQ(amytiss::round_up(value, 3), std::nextafter(std::nextafter(up, infinity), infinity)) << value;
  }
}

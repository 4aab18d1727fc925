// Every method of the bounds engine (compute.bounds_method) against the canonical oracle
// (robust_oracle.hpp: a plain serial recursion over unpacked rows), for the lower and for the upper
// bound: one typed test over the methods, as every method must give the oracle's bounds within its
// outward rounding.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "amytiss/enclosure.hpp"
#include "amytiss/engine.hpp"
#include "bounds/cell_roles.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/product/elimination.hpp"
#include "robust_oracle.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

// The methods differ from the oracle only in the order of their sums and in the O-maximisation's
// outward rounding.
constexpr double kAgreement = 1e-9;

// A 2-d system whose dynamics let the variable elimination run (x'0 reads x1).
std::string narrow_2d_yaml() {
  return "name: narrow_2d\n"
         "states: {lb: [-1.5, -1.5], ub: [1.5, 1.5], eta: [0.25, 0.25]}\n"
         "inputs: {lb: [-0.4], ub: [0.4], eta: [0.4]}\n"
         "disturbances: {lb: [-0.05], ub: [0.05], eta: [0.1]}\n"
         "dynamics: [\"0.95*x0 + 0.1*x1\", \"0.9*x1 + u0 + w0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.01, 0.01],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
         "spec: {type: reach_avoid, horizon: 3, target: {lb: [-0.375, -0.375], ub: [0.375, 0.375]},\n"
         "       avoid: {lb: [1.125, -1.5], ub: [1.5, 1.5]}}\n"
         "guarantee: system\n";
}

// A nonlinear 3-d system with a disturbance, safety.
std::string small_3d_yaml() {
  return "name: system_3d\n"
         "states: {lb: [-2, -2, -1], ub: [2, 2, 1], eta: [0.5, 0.5, 0.5]}\n"
         "inputs: {lb: [-0.5], ub: [0.5], eta: [0.5]}\n"
         "disturbances: {lb: [-0.1], ub: [0.1], eta: [0.2]}\n"
         "dynamics: [\"x0 + 0.5*x1\", \"0.9*x1 + 0.2*sin(x0) + u0 + w0\", \"0.8*x2 + 0.1*x0*x1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04, 0.02]}\n"
         "spec: {type: safety, horizon: 3, safe: {lb: [-1.75, -1.75, -0.75], ub: [1.75, 1.75, 0.75]}}\n"
         "guarantee: system\n";
}

// The oracle of `method`: the joint set for joint; the product set in the elimination's order for
// the variable elimination (a sound bound of its own, docs/semantics.md), in product_expectation()'s
// order for the others.
RobustValues oracle(const Abstraction& a, BoundsMethod method) {
  std::vector<std::size_t> order;
  if (method == BoundsMethod::Elimination) {
    const std::optional<FactoredPlan> plan = RobustFactoredSweep::plan(a, nullptr);
    EXPECT_TRUE(plan.has_value()) << a.config.name << ": the variable elimination has a plan";
    if (plan)
      for (const FactoredStage& stage : plan->stages) order.push_back(stage.dimension);
  }
  return robust_values_of(a, method == BoundsMethod::Joint ? AmbiguitySet::Joint : AmbiguitySet::Product,
                          std::move(order));
}

template <BoundsMethod M>
struct Method {
  static constexpr BoundsMethod value = M;
};

template <typename T>
class BoundsMethods : public ::testing::Test {};
using EveryMethod = ::testing::Types<Method<BoundsMethod::WholeTables>, Method<BoundsMethod::Elimination>,
                                     Method<BoundsMethod::Rows>, Method<BoundsMethod::Joint>>;
TYPED_TEST_SUITE(BoundsMethods, EveryMethod);

enum class Side { Lower, Upper };

void expect_oracles_bound(const std::string& yaml, BoundsMethod method, Side side) {
  const Abstraction a = from_yaml(yaml);
  SynthesisOptions options;
  options.compute.bounds_method = method;
  SynthesisReport report;
  const Policy policy = synthesize(a, options, &report);
  const RobustValues expected = oracle(a, method);
  bool method_noted = false;
  for (const EngineNote& note : report.notes)
    method_noted = method_noted || note.text.find("bounds_method") != std::string::npos;
  EXPECT_TRUE(method_noted) << "the plan's note names the forced method";
  const std::size_t cells = a.states.size();
  for (std::size_t x = 0; x < cells; ++x) {
    if (side == Side::Lower) {
      EXPECT_NEAR(policy.value(0, x), expected.lower[x], kAgreement) << a.config.name << " cell " << x;
      for (unsigned k = 0; k < a.horizon; ++k)
        if (expected.margin[std::size_t(k) * cells + x] > kAgreement)
          EXPECT_EQ(policy.input(k, x), expected.controller[std::size_t(k) * cells + x])
              << a.config.name << " cell " << x << " step " << k;
    } else {
      EXPECT_NEAR(policy.upper_value(0, x), expected.upper[x], kAgreement) << a.config.name << " cell " << x;
    }
  }
}

TYPED_TEST(BoundsMethods, LowerBoundIsTheOraclesWithItsController) {
  expect_oracles_bound(narrow_2d_yaml(), TypeParam::value, Side::Lower);
  expect_oracles_bound(small_3d_yaml(), TypeParam::value, Side::Lower);
}

TYPED_TEST(BoundsMethods, UpperBoundIsTheOracles) {
  expect_oracles_bound(narrow_2d_yaml(), TypeParam::value, Side::Upper);
  expect_oracles_bound(small_3d_yaml(), TypeParam::value, Side::Upper);
}

TEST(BoundsMethodChoice, AutoTakesWholeTablesOrEliminationAndSaysWhy) {
  const Abstraction a = from_yaml(narrow_2d_yaml());
  SynthesisReport report;
  synthesize(a, SynthesisOptions{}, &report);
  bool noted = false;
  for (const EngineNote& note : report.notes)
    noted = noted || note.text.find("(auto: ") != std::string::npos;
  EXPECT_TRUE(noted) << "the engine's note gives the method auto chose and why";
}

TEST(BoundsMethodChoice, AForcedMethodIsRefusedWithTheAbstractionGuarantee) {
  std::string yaml = narrow_2d_yaml();
  yaml.replace(yaml.find("guarantee: system"), std::string("guarantee: system").size(),
               "guarantee: abstraction\ncompute: {bounds_method: rows}");
  EXPECT_THROW(
      {
        try {
          from_yaml(yaml);
        } catch (const ConfigError& error) {
          EXPECT_NE(std::string(error.what()).find("compute.bounds_method"), std::string::npos) << error.what();
          throw;
        }
      },
      ConfigError);
}

}  // namespace
}  // namespace amytiss::detail

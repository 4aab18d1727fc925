// The engine of continuous-system bounds (guarantee: system): synthesize() gives the oracle's
// bounds (robust_oracle.hpp; the product set with method auto, the joint interval MDP with
// method joint) on bounded horizons, keeps lower <= upper, stores both in the policy file, answers
// unbounded specifications with sound bounds, and the plan and validation refuse what it cannot run.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "amytiss/enclosure.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/policy_file.hpp"
#include "robust_oracle.hpp"
#include "bounds/mean_box.hpp"
#include "bounds/cell_roles.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

// The engine and the oracle do the same arithmetic in the same order; they agree to this (and in
// practice bit for bit).
constexpr double kAgreement = 1e-9;
constexpr double kOrderSlack = 1e-12;

std::string with_system(std::string yaml) { return yaml + "guarantee: system\n"; }

// A nonlinear 3-d system with a disturbance: the product set's line cache, the joint rows and the
// adversary all take part.
std::string small_3d_yaml(unsigned horizon, bool truncated = true) {
  return "name: system_3d\n"
         "states: {lb: [-2, -2, -1], ub: [2, 2, 1], eta: [0.5, 0.5, 0.5]}\n"
         "inputs: {lb: [-0.5], ub: [0.5], eta: [0.5]}\n"
         "disturbances: {lb: [-0.1], ub: [0.1], eta: [0.2]}\n"
         "dynamics: [\"x0 + 0.5*x1\", \"0.9*x1 + 0.2*sin(x0) + u0 + w0\", \"0.8*x2 + 0.1*x0*x1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.04, 0.04, 0.02]" +
         std::string(truncated ? ",\n        truncation: cutting_probability, cutting_probability: 1.0e-4}\n" : "}\n") +
         "spec: {type: reach_avoid, horizon: " + std::to_string(horizon) +
         ", target: {lb: [1, -2, -1], ub: [2, 2, 1]}, avoid: {lb: [-2, -2, -1], ub: [-1.5, 2, 1]}}\n";
}

SynthesisOptions options_for(DeviceKind device) {
  SynthesisOptions options;
  options.compute.device = device;
  return options;
}

void expect_matches_oracle(const std::string& yaml, DeviceKind device, AmbiguitySet set,
                           BoundsMethod method = BoundsMethod::Auto) {
  const Abstraction a = from_yaml(with_system(yaml));
  SynthesisOptions options = options_for(device);
  options.compute.bounds_method = method;
  const Policy policy = synthesize(a, options, nullptr);
  const RobustValues expected = robust_values_of(a, set);
  ASSERT_EQ(policy.guarantee, Guarantee::System);
  ASSERT_EQ(policy.upper_values.size(), policy.values.size());
  const std::size_t cells = a.states.size();
  for (std::size_t x = 0; x < cells; ++x) {
    EXPECT_NEAR(policy.value(0, x), expected.lower[x], kAgreement) << "cell " << x;
    EXPECT_NEAR(policy.upper_value(0, x), expected.upper[x], kAgreement) << "cell " << x;
    for (unsigned k = 0; k < a.horizon; ++k) {
      EXPECT_EQ(policy.input(k, x), expected.controller[std::size_t(k) * cells + x]) << "cell " << x << " step " << k;
      EXPECT_LE(policy.value(k, x), policy.upper_value(k, x) + kOrderSlack) << "cell " << x << " step " << k;
    }
  }
}

TEST(SystemEngine, ProductEngineGivesTheOraclesBoundsAndController) {
  expect_matches_oracle(robot_disturbance_yaml(), DeviceKind::Auto, AmbiguitySet::Product);
  expect_matches_oracle(small_3d_yaml(3), DeviceKind::Auto, AmbiguitySet::Product);
}

TEST(SystemEngine, JointMethodGivesTheJointOraclesBounds) {
  expect_matches_oracle(small_3d_yaml(2), DeviceKind::Reference, AmbiguitySet::Joint, BoundsMethod::Joint);
  expect_matches_oracle(small_3d_yaml(2), DeviceKind::Auto, AmbiguitySet::Joint, BoundsMethod::Joint);
}

TEST(SystemEngine, ReferenceDeviceRunsTheProductSetOnOneThread) {
  const Abstraction a = from_yaml(with_system(small_3d_yaml(2)));
  SynthesisReport report;
  const Policy serial = synthesize(a, options_for(DeviceKind::Reference), &report);
  EXPECT_EQ(report.device, "reference");
  const Policy threaded = synthesize(a, options_for(DeviceKind::Auto), nullptr);
  EXPECT_EQ(serial.values, threaded.values);
  EXPECT_EQ(serial.upper_values, threaded.upper_values);
  EXPECT_EQ(serial.input_index, threaded.input_index);
}

TEST(SystemEngine, TheAbstractionLiesBetweenTheBoundsWhereSetsAlignWithCells) {
  // The target and avoid boxes of small_3d_yaml lie on cell faces. Without truncation: the
  // abstraction drops cut mass that the interval MDP keeps.
  const std::string yaml = small_3d_yaml(3, false);
  const Policy abstraction = synthesize(from_yaml(yaml), options_for(DeviceKind::Reference), nullptr);
  const Policy bounds = synthesize(from_yaml(with_system(yaml)), options_for(DeviceKind::Auto), nullptr);
  for (std::size_t x = 0; x < abstraction.states.size(); ++x) {
    EXPECT_LE(bounds.value(0, x), abstraction.value(0, x) + kOrderSlack) << "cell " << x;
    EXPECT_LE(abstraction.value(0, x), bounds.upper_value(0, x) + kOrderSlack) << "cell " << x;
  }
}

TEST(SystemEngine, PolicyFileKeepsBothBoundsAndTheDefaultKeepsTheHash) {
  const std::filesystem::path directory = fresh_test_directory("amytiss_system_engine_");
  const Abstraction a = from_yaml(with_system(robot_disturbance_yaml()));
  const Policy policy = synthesize(a, options_for(DeviceKind::Auto), nullptr);
  write_policy_file((directory / "bounds.h5").string(), policy, a.config);
  const LoadedPolicy loaded = read_policy_file((directory / "bounds.h5").string());
  EXPECT_EQ(loaded.policy.guarantee, Guarantee::System);
  EXPECT_EQ(loaded.policy.upper_values, policy.upper_values);
  EXPECT_EQ(loaded.policy.values, policy.values);
  // The default guarantee leaves the configuration's text, and so its hash, as it was.
  const Config plain = config_from_yaml(YAML::Load(robot_disturbance_yaml()));
  const Config explicit_default = config_from_yaml(YAML::Load(robot_disturbance_yaml() + "guarantee: abstraction\n"));
  EXPECT_EQ(config_hash(plain), config_hash(explicit_default));
  EXPECT_NE(config_hash(plain), config_hash(a.config));
  std::filesystem::remove_all(directory);
}

TEST(SystemEngine, UnboundedReachAvoidHasSoundBoundsAroundTheBoundedOnes) {
  // Reaching within 3 steps is no more likely than ever reaching: the unbounded upper bound lies
  // above the 3-step lower bound, and the certified stationary lower bound below the upper one.
  std::string unbounded = small_3d_yaml(3);
  unbounded.replace(unbounded.find("horizon: 3"), 10, "horizon: infinite, tolerance: 1.0e-4");
  const Policy stationary = synthesize(from_yaml(with_system(unbounded)), options_for(DeviceKind::Auto), nullptr);
  const Policy bounded = synthesize(from_yaml(with_system(small_3d_yaml(3))), options_for(DeviceKind::Auto), nullptr);
  ASSERT_TRUE(stationary.stationary);
  EXPECT_EQ(stationary.guarantee, Guarantee::System);
  ASSERT_EQ(stationary.upper_values.size(), stationary.states.size());
  EXPECT_GT(stationary.iterations, 0u);
  for (std::size_t x = 0; x < stationary.states.size(); ++x) {
    EXPECT_LE(stationary.value(0, x), stationary.upper_value(0, x) + kOrderSlack) << "cell " << x;
    EXPECT_LE(bounded.value(0, x), stationary.upper_value(0, x) + kOrderSlack) << "cell " << x;
  }
  EXPECT_EQ(stationary.converged, stationary.gap <= 1.0e-4);
}

TEST(SystemEngine, OpenClDevicesAndFullCovariancesAreRefusedNamingTheKey) {
  const Abstraction a = from_yaml(with_system(robot_disturbance_yaml()));
  try {
    synthesize(a, options_for(DeviceKind::Cpu), nullptr);
    FAIL() << "an OpenCL device was accepted for guarantee: system";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("compute.device"), std::string::npos) << error.what();
  }
  std::string full = with_system(robot_disturbance_yaml());
  full.replace(full.find("covariance: [0.75, 0.75]"), 24, "covariance: [0.75, 0.1, 0.1, 0.75]");
  try {
    from_yaml(full);
    FAIL() << "a full covariance was accepted for guarantee: system";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("noise.covariance"), std::string::npos) << error.what();
  }
}

std::size_t count_targets(const std::vector<CellRole>& roles) {
  return std::size_t(std::count(roles.begin(), roles.end(), CellRole::FixedOne));
}

// The lower bound counts a cell as target only when the whole cell lies inside the target. The
// demo's certified car (config/bmw_final_approach.yaml) draws its target on the cells' faces, so
// the lower bound's targets are the abstraction's; the parking problem's target asks for a speed
// of exactly 0 and no cell lies inside it, so its lower bound would be 0 everywhere.
// The final approach's target is drawn on faces: the lower bound's target cells are the
// abstraction's. The parking target (positions and yaw cut through cells, speed the speed cell of
// 0) holds a few whole cells, each also a target cell of the abstraction.
TEST(SystemEngine, TheCertifiedCarsTargetIsWholeCellsAndTheParkingTargetsWholeCellsAreTargetCells) {
  const std::string source = AMYTISS_SOURCE_DIR;
  const Config approach = load_config_file(source + "/config/bmw_final_approach.yaml");
  EXPECT_EQ(approach.guarantee, Guarantee::System);
  const Grid approach_states(approach.states);
  const std::vector<CellRole> lower = robust_cell_roles(approach_states, approach.spec, Bound::Lower);
  const std::vector<CellRole> abstraction = cell_roles(approach_states, approach.spec);
  EXPECT_GT(count_targets(lower), 0u);
  for (std::size_t x = 0; x < lower.size(); ++x)
    ASSERT_EQ(lower[x] == CellRole::FixedOne, abstraction[x] == CellRole::FixedOne) << "cell " << x;

  const Config parking = load_config_file(source + "/config/bmw_parking.yaml");
  const Grid parking_states(parking.states);
  const std::vector<CellRole> parking_lower = robust_cell_roles(parking_states, parking.spec, Bound::Lower);
  const std::vector<CellRole> parking_abstraction = cell_roles(parking_states, parking.spec);
  EXPECT_GT(count_targets(parking_lower), 0u);
  EXPECT_LT(count_targets(parking_lower), count_targets(parking_abstraction));
  for (std::size_t x = 0; x < parking_lower.size(); ++x)
    if (parking_lower[x] == CellRole::FixedOne) {
      ASSERT_EQ(parking_abstraction[x], CellRole::FixedOne) << "cell " << x;
    }
}

bool has_line(const std::vector<std::string>& lines, const std::string& text) {
  return std::any_of(lines.begin(), lines.end(), [&](const std::string& line) { return line.find(text) != line.npos; });
}

// The plan (--dry-run) and the run's notes say how many cells the lower bound counts as target,
// and warn when there is none: the lower bound is then 0 everywhere.
TEST(SystemEngine, PlanAndNotesCountTheLowerBoundsTargetCells) {
  const Abstraction a = from_yaml(with_system(small_3d_yaml(1)));
  const std::size_t inside = count_targets(robust_cell_roles(a.states, a.config.spec, Bound::Lower));
  ASSERT_GT(inside, 0u);
  ASSERT_LT(inside, count_targets(a.roles)) << "the target's edge cells hold target points but are not inside";
  const std::string counted = std::to_string(inside) + " of " + std::to_string(a.states.size()) +
                              " cells lie wholly inside the target (the lower bound's target cells)";
  EXPECT_TRUE(has_line(describe_synthesis(a, options_for(DeviceKind::Auto)), "continuous-system bounds: " + counted));
  SynthesisReport report;
  synthesize(a, options_for(DeviceKind::Auto), &report);
  EXPECT_TRUE(std::any_of(report.notes.begin(), report.notes.end(), [&](const EngineNote& note) {
    return note.text == counted && note.severity == NoteSeverity::Info;
  }));

  // A target inside one cell: no cell lies inside it.
  std::string yaml = small_3d_yaml(1);
  const std::string target = "target: {lb: [1, -2, -1], ub: [2, 2, 1]}";
  yaml.replace(yaml.find(target), target.size(), "target: {lb: [1.4, -0.1, -0.1], ub: [1.6, 0.1, 0.1]}");
  const Abstraction point = from_yaml(with_system(yaml));
  const std::string none = "0 of " + std::to_string(point.states.size()) +
                           " cells lie wholly inside the target (the lower bound's target cells): the lower bound "
                           "is 0 everywhere";
  EXPECT_TRUE(has_line(describe_synthesis(point, options_for(DeviceKind::Auto)), none));
  SynthesisReport warned;
  const Policy policy = synthesize(point, options_for(DeviceKind::Auto), &warned);
  EXPECT_TRUE(std::any_of(warned.notes.begin(), warned.notes.end(), [&](const EngineNote& note) {
    return note.text.find(none) == 0 && note.severity == NoteSeverity::Warning;
  }));
  for (std::size_t x = 0; x < point.states.size(); ++x) ASSERT_EQ(policy.value(0, x), 0.0) << "cell " << x;
}

}  // namespace
}  // namespace amytiss::detail

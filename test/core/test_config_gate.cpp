// The one gate for user input (docs/configuration.md, "Checks"): the reader only reads, the
// overrides come before the single Config::validate(), and what follows validation (Abstraction,
// a stored configuration's consumers) does not judge the values again.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"

namespace amytiss {
namespace {

const char* const kTiny = R"(
name: tiny
states: {lb: [0, 0], ub: [4, 4], eta: [1, 1]}
inputs: {lb: [-1], ub: [1], eta: [1]}
dynamics: ["x0 + u0", "x1"]
noise: {covariance: [0.2, 0.2]}
spec: {type: reach_avoid, horizon: 3, target: {lb: [3, 0], ub: [4, 4]}, avoid: {lb: [0, 0], ub: [0, 4]}}
)";

std::string error_key(const std::function<void()>& action) {
  try {
    action();
  } catch (const ConfigError& error) {
    return error.key();
  }
  return "none";
}

// Each of these values is of the right type but wrong in meaning: read_config() takes it as
// given, and validate() is the one that names its key.
TEST(ConfigGate, TheReaderDoesNotJudgeValues) {
  const std::vector<std::pair<std::string, std::string>> faults = {
      {"spec: {type: safety, horizon: 0}", "spec.horizon"},
      {"spec: {type: safety, horizon: 4000000000}", "spec.horizon"},
      {"spec: {type: safety, horizon: 5, tolerance: 1.0e-3}", "spec.tolerance"},
      {"noise: {covariance: [0.2, 0.2], cutting_probability: 0.01}", "noise.cutting_probability"},
      {"integrator: {substeps: 0, tau: 0.1}", "integrator.substeps"},
      {"states: {lb: [0, 0], ub: [4, 4], eta: [1, -1]}", "states.eta[1]"},
      {"compute: {memory_fraction: 2}", "compute.memory_fraction"},
  };
  for (const auto& [replacement, key] : faults) {
    SCOPED_TRACE(replacement);
    YAML::Node root = YAML::Load(kTiny);
    const YAML::Node section = YAML::Load(replacement);
    for (const auto& entry : section) root[entry.first.Scalar()] = entry.second;
    Config config;
    ASSERT_NO_THROW(config = read_config(root));
    EXPECT_EQ(error_key([&] { config.validate(); }), key);
    EXPECT_EQ(error_key([&] { config_from_yaml(root); }), key);
  }
}

TEST(ConfigGate, TheReaderRefusesWrongTypes) {
  YAML::Node root = YAML::Load(kTiny);
  root["spec"]["horizon"] = 2.5;
  EXPECT_EQ(error_key([&] { read_config(root); }), "spec.horizon");
  root = YAML::Load(kTiny);
  root["noise"]["covariance"] = "wide";
  EXPECT_EQ(error_key([&] { read_config(root); }), "noise.covariance");
}

// Overrides are applied before the one validation: an override can repair a configuration
// (the file's reference device beside a device list) or break it, and validation sees the result.
TEST(ConfigGate, OverridesComeBeforeTheOneValidation) {
  YAML::Node root = YAML::Load(kTiny);
  root["compute"] = YAML::Load("{device: reference, devices: [cpu:0]}");
  EXPECT_EQ(error_key([&] { config_from_yaml(root); }), "compute.devices");
  ComputeOverrides to_cpu;
  to_cpu.device = "cpu";
  EXPECT_EQ(config_from_yaml(root, to_cpu).compute.device, DeviceKind::Cpu);

  ComputeOverrides bad_devices;
  bad_devices.devices = {"gpu:x"};
  EXPECT_EQ(error_key([&] { config_from_yaml(YAML::Load(kTiny), bad_devices); }), "compute.devices[0]");

  ComputeOverrides unknown;
  unknown.key_prefix = "--";
  unknown.sweep = "sideways";
  EXPECT_EQ(error_key([&] { config_from_yaml(YAML::Load(kTiny), unknown); }), "--sweep");
}

// The guarantee (a top-level key) is overridden like the compute keys, before the one validation
// (which refuses a device the continuous-system bounds cannot use), and named without "compute.".
TEST(ConfigGate, TheGuaranteeIsOverriddenBeforeTheOneValidation) {
  ComputeOverrides system;
  system.guarantee = "system";
  EXPECT_EQ(config_from_yaml(YAML::Load(kTiny), system).guarantee, Guarantee::System);
  YAML::Node root = YAML::Load(kTiny);
  root["guarantee"] = "system";
  ComputeOverrides abstraction;
  abstraction.guarantee = "abstraction";
  EXPECT_EQ(config_from_yaml(root, abstraction).guarantee, Guarantee::Abstraction);
  ComputeOverrides on_cpu = system;
  on_cpu.device = "cpu";
  EXPECT_EQ(error_key([&] { config_from_yaml(YAML::Load(kTiny), on_cpu); }), "compute.device");

  ComputeOverrides unknown;
  unknown.guarantee = "certified";
  EXPECT_EQ(error_key([&] { config_from_yaml(YAML::Load(kTiny), unknown); }), "guarantee");
  unknown.key_prefix = "--";
  EXPECT_EQ(error_key([&] { config_from_yaml(YAML::Load(kTiny), unknown); }), "--guarantee");
}

TEST(ConfigGate, ApplyOverridesReplacesOnlyWhatIsGiven) {
  Config config = read_config(YAML::Load(kTiny));
  config.compute.platform = "pocl";
  ComputeOverrides overrides;
  overrides.transitions = "on_the_fly";
  overrides.sweep = "dense";
  apply_overrides(config, overrides);
  EXPECT_EQ(config.compute.transitions, TransitionStorage::OnTheFly);
  EXPECT_EQ(config.compute.sweep, SweepChoice::Dense);
  EXPECT_EQ(config.compute.device, DeviceKind::Auto);
  EXPECT_EQ(config.compute.platform, "pocl");
  EXPECT_EQ(config.guarantee, Guarantee::Abstraction);
}

// Abstraction::from_config builds from what validate() passed and does not judge it again: a
// configuration whose only fault is a compute key (the engine's concern, not the abstraction's)
// still builds, which it could not if from_config ran validate() a second time.
TEST(ConfigGate, TheAbstractionDoesNotValidateAgain) {
  Config config = config_from_yaml(YAML::Load(kTiny));
  config.compute.memory_fraction = 2;
  ASSERT_EQ(error_key([&] { config.validate(); }), "compute.memory_fraction");
  const Abstraction abstraction = Abstraction::from_config(config);
  EXPECT_EQ(abstraction.states.size(), 25u);
}

// A policy file's consumers read the stored configuration without the checks: the stored text
// round-trips, and a value validate() would refuse is read as stored.
TEST(ConfigGate, StoredConfigurationIsReadWithoutTheChecks) {
  const Config config = config_from_yaml(YAML::Load(kTiny));
  const Config stored = read_stored_config(to_yaml(config));
  EXPECT_EQ(config_hash(stored), config_hash(config));
  EXPECT_EQ(stored.name, "tiny");
  ASSERT_TRUE(stored.spec.target.has_value());
  ASSERT_EQ(stored.spec.target->boxes.size(), 1u);
  EXPECT_EQ(stored.spec.target->boxes[0].lb, (std::vector<double>{3, 0}));

  Config odd = config;
  odd.compute.memory_fraction = 2;
  EXPECT_EQ(read_stored_config(to_yaml(odd)).compute.memory_fraction, 2.0);
  EXPECT_EQ(error_key([] { read_stored_config("name: [unclosed"); }), "config_yaml");
}

}  // namespace
}  // namespace amytiss

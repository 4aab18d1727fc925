// Configuration: the YAML schema, every bad input that validate() refuses (docs/configuration.md), the canonical text and the hash.
#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::expect_error;

const char* const kBase = R"(
name: base
states: {lb: [-10, -10], ub: [10, 10], eta: [0.5, 0.5]}
inputs: {lb: [-1, -1], ub: [1, 1], eta: [0.2, 0.2]}
disturbances: {lb: [-1], ub: [1], eta: [0.2]}
constants: {tau: 10.0}
dynamics: ["x0 + tau*u0*cos(u1) + w0", "x1 + tau*u0*sin(u1) + w0"]
noise: {covariance: [0.75, 0.75], truncation: cutting_probability, cutting_probability: 1.0e-3}
spec: {type: safety, horizon: 8}
)";

YAML::Node base() { return YAML::Load(kBase); }


TEST(Config, BaseParsesWithDefaults) {
  const Config config = config_from_yaml(base());
  EXPECT_EQ(config.name, "base");
  EXPECT_EQ(config.states.lb, (std::vector<double>{-10, -10}));  // YAML ints read as numbers
  ASSERT_TRUE(config.inputs.has_value());
  ASSERT_TRUE(config.disturbances.has_value());
  EXPECT_EQ(config.constants.at("tau"), 10.0);
  EXPECT_EQ(config.noise.type, NoiseType::Additive);
  EXPECT_EQ(config.noise.distribution, Distribution::Normal);
  EXPECT_EQ(config.compute.device, DeviceKind::Auto);
  EXPECT_EQ(config.compute.transitions, TransitionStorage::Auto);
  EXPECT_EQ(config.compute.memory_fraction, 0.5);
  EXPECT_EQ(config.spec.horizon, 8u);
}

TEST(Config, OptionalSectionsAndDefaults) {
  YAML::Node root = base();
  root.remove("inputs");
  root.remove("disturbances");
  root.remove("constants");
  root.remove("compute");
  root["dynamics"] = YAML::Load(R"(["0.8*x0", "0.8*x1"])");
  root["noise"] = YAML::Load("{covariance: [0.2, 0.2]}");
  const Config config = config_from_yaml(root);
  EXPECT_FALSE(config.inputs.has_value());
  EXPECT_FALSE(config.disturbances.has_value());
  EXPECT_TRUE(config.constants.empty());
  EXPECT_EQ(config.noise.truncation, Truncation::None);
}

TEST(Config, MissingAndUnknownKeys) {
  YAML::Node root = base();
  root.remove("name");
  expect_error(root, "name", "missing");

  root = base();
  root["states"]["etaa"] = YAML::Load("[0.5, 0.5]");
  expect_error(root, "states.etaa", "unknown key");

  root = base();
  root["noise"]["covarience"] = YAML::Load("[1, 1]");
  expect_error(root, "noise.covarience", "unknown key");

  root = base();
  root["horizon"] = 8;
  expect_error(root, "horizon", "unknown key");

  root = base();
  root["spec"]["targets"] = YAML::Load("{lb: [0, 0], ub: [1, 1]}");
  expect_error(root, "spec.targets", "unknown key");

  root = base();
  root["compute"] = YAML::Load("{devise: cpu}");
  expect_error(root, "compute.devise", "unknown key");

  root = base();
  root.remove("spec");
  expect_error(root, "spec", "missing");

  root = base();
  root["states"].remove("eta");
  expect_error(root, "states.eta", "missing");
}

TEST(Config, WrongTypes) {
  YAML::Node root = base();
  root["states"]["eta"] = YAML::Load("[0.5, abc]");
  expect_error(root, "states.eta[1]", "got 'abc', expected a number");

  root = base();
  root["states"]["lb"] = 5;
  expect_error(root, "states.lb", "expected a list of numbers");

  root = base();
  root["spec"]["horizon"] = 2.5;
  expect_error(root, "spec.horizon", "got 2.5, expected a positive integer or infinite");

  root = base();
  root["spec"]["horizon"] = -3;
  expect_error(root, "spec.horizon", "got -3, expected a positive integer or infinite");
  root["spec"]["horizon"] = -1;
  expect_error(root, "spec.horizon", "got -1, expected a positive integer or infinite");
  root["spec"]["horizon"] = 4294967295u;
  expect_error(root, "spec.horizon", "got 4294967295, expected an integer >= 1 and <= 1000000000");
}

TEST(Config, GridErrors) {
  YAML::Node root = base();
  root["states"]["eta"] = YAML::Load("[0.5, -0.5]");
  expect_error(root, "states.eta[1]", "got -0.5, expected a number > 0 (example: eta: [0.5, 0.5])");

  root = base();
  root["inputs"]["eta"] = YAML::Load("[0, 0.2]");
  expect_error(root, "inputs.eta[0]", "got 0, expected a number > 0");

  root = base();
  root["states"]["ub"] = YAML::Load("[10, -20]");
  expect_error(root, "states.ub[1]", "got -20, expected a number >= states.lb[1] = -10");

  root = base();
  root["states"]["ub"] = YAML::Load("[10, 10, 10]");
  expect_error(root, "states.ub", "got 3 values, expected 2 values");

  root = base();
  root["states"]["eta"] = YAML::Load("[0.5]");
  expect_error(root, "states.eta", "got 1 values, expected 2 values");

  root = base();
  root["states"]["lb"] = YAML::Load("[.nan, -10]");
  expect_error(root, "states.lb[0]", "got nan, expected a finite number");

  root = base();
  root["disturbances"]["lb"] = YAML::Load("[]");
  root["disturbances"]["ub"] = YAML::Load("[]");
  root["disturbances"]["eta"] = YAML::Load("[]");
  expect_error(root, "disturbances.lb", "omit `disturbances`");
}

TEST(Config, GridTooLarge) {
  YAML::Node root = base();
  root["states"]["eta"] = YAML::Load("[1.0e-4, 1.0e-4]");  // 200001^2 = 4e10 points
  expect_error(root, "states", "grid too large");

  root = base();
  root["inputs"]["eta"] = YAML::Load("[1.0e-5, 1.0e-5]");
  expect_error(root, "inputs", "at most 4294967295");

  // 4001^2 = 16e6 states pass the 2^32 limit, but 16e6 * (1001*8 + 1000*4) bytes = 179 GiB.
  root = base();
  root["states"]["eta"] = YAML::Load("[0.005, 0.005]");
  root["spec"]["horizon"] = 1000;
  expect_error(root, "states", "GiB of policy arrays");
}

TEST(Config, DynamicsErrors) {
  YAML::Node root = base();
  root["dynamics"] = YAML::Load(R"(["x0 + tau*u0*cos(u1", "x1"])");
  expect_error(root, "dynamics[0]", "column 19: expected ')' after argument list of cos");

  root = base();
  root["dynamics"] = YAML::Load(R"(["x0", "x5"])");
  expect_error(root, "dynamics[1]", "column 1: 'x5' is out of range");

  root = base();
  root["dynamics"] = YAML::Load(R"(["x0", "x1 + speed"])");
  expect_error(root, "dynamics[1]", "unknown name 'speed'");

  root = base();
  root["dynamics"] = YAML::Load(R"(["x0"])");
  expect_error(root, "dynamics", "got 1 expressions, expected 2");

  root = base();
  root.remove("dynamics");
  expect_error(root, "dynamics", "missing");

  root = base();
  root["model"] = "bmw320i";
  expect_error(root, "model", "both `model` and `dynamics`");

  root = base();
  root.remove("dynamics");
  root["model"] = "tesla";
  expect_error(root, "model", "got 'tesla', expected one of bmw320i, bmw320i_ks, vehicle3d");

  root = base();
  root.remove("dynamics");
  root["model"] = "vehicle3d";
  expect_error(root, "states.lb", "model vehicle3d needs 3 dimensions, got 2");

  root = base();
  root["constants"]["sin"] = 1.0;
  expect_error(root, "constants.sin", "not pi, a variable");

  root = base();
  root["constants"]["x0"] = 1.0;
  expect_error(root, "constants.x0", "not pi, a variable");
}

TEST(Config, NoiseErrors) {
  YAML::Node root = base();
  root["noise"]["covariance"] = YAML::Load("[0.75, 0.75, 0.75]");
  expect_error(root, "noise.covariance", "got 3 values, expected 2 values (diagonal) or 4 values (full matrix");

  root = base();
  root["noise"]["covariance"] = YAML::Load("[0.75, -0.1]");
  expect_error(root, "noise.covariance[1]", "expected a variance >= 0 (0: no noise in that dimension)");

  // A diagonal variance of exactly 0 is a dimension without noise; a full matrix stays SPD.
  root = base();
  root["noise"]["covariance"] = YAML::Load("[0.75, 0]");
  EXPECT_NO_THROW(config_from_yaml(root));
  root = base();
  root["noise"]["covariance"] = YAML::Load("[0.75, 0, 0, 0]");
  expect_error(root, "noise.covariance", "not positive definite");

  // Full covariance beyond NoiseModel::kMaxFullCovarianceDims (4) dimensions; a full matrix with
  // zero off-diagonal entries is diagonal and stays allowed.
  {
    const char* const five_dims = R"(
name: five
states: {lb: [0, 0, 0, 0, 0], ub: [1, 1, 1, 1, 1], eta: [0.5, 0.5, 0.5, 0.5, 0.5]}
dynamics: ["x0", "x1", "x2", "x3", "x4"]
noise: {covariance: [1, 0.1, 0, 0, 0,  0.1, 1, 0, 0, 0,  0, 0, 1, 0, 0,  0, 0, 0, 1, 0,  0, 0, 0, 0, 1]}
spec: {type: safety, horizon: 2}
)";
    root = YAML::Load(five_dims);
    expect_error(root, "noise.covariance", "supported up to 4 state dimensions, got 5");
    root = YAML::Load(five_dims);
    root["noise"]["covariance"] = YAML::Load("[1, 0, 0, 0, 0,  0, 1, 0, 0, 0,  0, 0, 1, 0, 0,  0, 0, 0, 1, 0,  0, 0, 0, 0, 1]");
    EXPECT_NO_THROW(config_from_yaml(root));
  }

  root = base();
  root["noise"]["covariance"] = YAML::Load("[1, 0.5, 0.4, 1]");
  expect_error(root, "noise.covariance", "not symmetric");

  root = base();
  root["noise"]["covariance"] = YAML::Load("[1, 2, 2, 1]");
  expect_error(root, "noise.covariance", "not positive definite");

  root = base();
  root["noise"]["covariance"] = YAML::Load("[1, 0.5, 0.5, 1]");
  EXPECT_NO_THROW(config_from_yaml(root));

  root = base();
  root["noise"]["covariance"] = YAML::Load("[1, 0.5, 0.5, 1]");
  root["noise"]["type"] = "multiplicative";
  expect_error(root, "noise.covariance", "multiplicative noise is not supported");

  root = base();
  root["noise"]["type"] = "additve";
  expect_error(root, "noise.type", "got 'additve', expected one of additive, multiplicative");

  // Each distribution has its own parameters (test_noise_laws.cpp tests them); the normal's
  // covariance given with another distribution is named.
  for (const char* distribution : {"exponential", "beta", "custom"}) {
    root = base();
    root["noise"]["distribution"] = distribution;
    expect_error(root, "noise.covariance", "it is only used by distribution normal");
  }
  root = base();
  root["noise"]["distribution"] = "gaussian";
  expect_error(root, "noise.distribution", "expected one of normal, uniform, exponential, beta, custom");

  root = base();
  root["noise"] = YAML::Load("{distribution: uniform, half_width: [0.5, 0.5]}");
  EXPECT_EQ(config_from_yaml(root).noise.distribution, Distribution::Uniform);

  root = base();
  root["noise"] = YAML::Load("{distribution: uniform, half_width: [0.5, 0]}");
  expect_error(root, "noise.half_width[1]", "expected a number > 0");

  root = base();
  root["noise"] = YAML::Load("{distribution: uniform, covariance: [0.5, 0.5]}");
  expect_error(root, "noise.covariance", "distribution uniform uses noise.half_width");

  for (const char* gamma : {"0", "1", "1.5"}) {
    root = base();
    root["noise"]["cutting_probability"] = YAML::Load(gamma);
    expect_error(root, "noise.cutting_probability", "expected a probability in (0, 1)");
  }

  root = base();
  root["noise"]["truncation"] = "none";
  expect_error(root, "noise.cutting_probability", "given but noise.truncation is none");

  root = base();
  root["noise"] = YAML::Load("{covariance: [0.75, 0.75], truncation: fixed_region, fixed_region: [1]}");
  expect_error(root, "noise.fixed_region", "got 1 values, expected 2 values");

  root = base();
  root["noise"] = YAML::Load("{covariance: [0.75, 0.75], truncation: fixed_region, fixed_region: [1, 0]}");
  expect_error(root, "noise.fixed_region[1]", "expected a number > 0");

  root = base();
  root["noise"] = YAML::Load("{covariance: [0.75, 0.75], fixed_region: [1, 1]}");
  expect_error(root, "noise.fixed_region", "given but noise.truncation is none");
}

TEST(Config, SpecErrors) {
  YAML::Node root = base();
  root["spec"]["horizon"] = 0;
  expect_error(root, "spec.horizon", "got 0, expected an integer >= 1");

  root = base();
  root["spec"]["type"] = "reach_avoid";
  expect_error(root, "spec.target", "missing");

  root = base();
  root["spec"]["type"] = "reachability";
  expect_error(root, "spec.target", "missing");

  root = base();
  root["spec"]["type"] = "reach";
  expect_error(root, "spec.type", "expected one of safety, reachability, reach_avoid");

  root = base();
  root["spec"]["avoid"] = YAML::Load("{lb: [-2, -2], ub: [2, 2]}");
  expect_error(root, "spec.avoid", "given for spec.type safety");

  root = base();
  root["spec"] = YAML::Load("{type: reach_avoid, horizon: 4, target: {lb: [5, 5], ub: [7]}}");
  expect_error(root, "spec.target.ub", "got 1 values, expected 2 values");

  root = base();
  root["spec"] = YAML::Load("{type: reach_avoid, horizon: 4, target: {lb: [5, 5], ub: [7, 4]}}");
  expect_error(root, "spec.target.ub[1]", "expected a number >= spec.target.lb[1] = 5");

  // Outside the grid entirely, and inside the grid's span but between two points (eta 0.5).
  root = base();
  root["spec"] = YAML::Load("{type: reach_avoid, horizon: 4, target: {lb: [20, 5], ub: [30, 7]}}");
  expect_error(root, "spec.target", "contains no representative point");
  root = base();
  root["spec"] = YAML::Load("{type: reach_avoid, horizon: 4, target: {lb: [5.1, 5], ub: [5.4, 7]}}");
  expect_error(root, "spec.target", "dimension 0");
  root = base();
  root["spec"] = YAML::Load(
      "{type: reach_avoid, horizon: 4, target: {lb: [5, 5], ub: [7, 7]}, avoid: {lb: [-2, 11], ub: [2, 12]}}");
  expect_error(root, "spec.avoid", "contains no representative point");
  root = base();
  root["spec"]["safe"] = YAML::Load("{lb: [-30, -30], ub: [-20, -20]}");
  expect_error(root, "spec.safe", "contains no representative point");
  // Target and avoid sharing grid points (eta 0.5): target x0 5..7, avoid x0 6.6..8 share 7;
  // x1 5..7 and 4..5.2 share 5. Boxes that overlap only between grid points are fine.
  root = base();
  root["spec"] = YAML::Load(
      "{type: reach_avoid, horizon: 4, target: {lb: [5, 5], ub: [7, 7]}, avoid: {lb: [6.6, 4], ub: [8, 5.2]}}");
  expect_error(root, "spec.avoid", "share grid points, for example [7, 5]");
  root = base();
  root["spec"] = YAML::Load(
      "{type: reach_avoid, horizon: 4, target: {lb: [5, 5], ub: [7, 7]}, avoid: {lb: [7.1, 4], ub: [8, 5.2]}}");
  EXPECT_NO_THROW(config_from_yaml(root));
  // A box that touches exactly one grid point is fine.
  root = base();
  root["spec"] = YAML::Load("{type: reachability, horizon: 4, target: {lb: [5, 5], ub: [5, 5]}}");
  EXPECT_NO_THROW(config_from_yaml(root));
}

TEST(Config, ComputeErrors) {
  YAML::Node root = base();
  root["compute"] = YAML::Load("{device: tpu}");
  expect_error(root, "compute.device", "expected one of auto, cpu, gpu, reference");
  root["compute"] = YAML::Load("{transitions: sometimes}");
  expect_error(root, "compute.transitions", "expected one of auto, stored, on_the_fly");
  for (const char* fraction : {"0", "1.5", "-0.1"}) {
    root["compute"] = YAML::Load(std::string("{memory_fraction: ") + fraction + "}");
    expect_error(root, "compute.memory_fraction", "expected a fraction in (0, 1]");
  }
  root["compute"] = YAML::Load("{device: gpu, transitions: on_the_fly, platform: 1, device_name: nvidia, memory_fraction: 1}");
  const Config config = config_from_yaml(root);
  EXPECT_EQ(config.compute.device, DeviceKind::Gpu);
  EXPECT_EQ(config.compute.transitions, TransitionStorage::OnTheFly);
  EXPECT_EQ(config.compute.platform, "1");
  EXPECT_EQ(config.compute.device_name, "nvidia");
}

// output.values changes how the policy file stores the values, not the policy: the hash stays,
// the stored text (to_yaml) keeps it, and only the two storage names are accepted.
TEST(Config, OutputValuesIsStoredButNotHashed) {
  YAML::Node root = base();
  const Config exact = config_from_yaml(root);
  EXPECT_EQ(exact.output.values, ValueStorage::Exact);
  EXPECT_EQ(to_yaml(exact).find("output"), std::string::npos);
  root["output"] = YAML::Load("{values: float32_lower}");
  const Config float32 = config_from_yaml(root);
  EXPECT_EQ(float32.output.values, ValueStorage::Float32Lower);
  EXPECT_EQ(config_hash(float32), config_hash(exact));
  EXPECT_EQ(read_stored_config(to_yaml(float32)).output.values, ValueStorage::Float32Lower);
  root["output"] = YAML::Load("{values: float16}");
  expect_error(root, "output.values", "'float16'");
  expect_error(root, "output.values", "expected one of exact, float32_lower");
  expect_error(root, "output.values", "values: float32_lower");
  root["output"] = YAML::Load("{value: exact}");
  expect_error(root, "output.value", "unknown key (valid keys of output: values)");
}

TEST(Config, ValidateOnAStructBuiltInCode) {
  Config config = config_from_yaml(base());
  config.states.eta[0] = std::nan("");
  try {
    config.validate();
    FAIL() << "NaN eta accepted";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "states.eta[0]");
  }
  config = config_from_yaml(base());
  config.name.clear();
  EXPECT_THROW(config.validate(), ConfigError);
}

TEST(Config, FileErrors) {
  try {
    load_config_file("/nonexistent/amytiss.yaml");
    FAIL();
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "/nonexistent/amytiss.yaml");
    EXPECT_NE(std::string(error.what()).find("cannot read"), std::string::npos);
  }
  const std::string path = ::testing::TempDir() + "/amytiss_bad.yaml";
  std::ofstream(path) << "name: [unclosed\n";
  try {
    load_config_file(path);
    FAIL();
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("not valid YAML at line"), std::string::npos) << error.what();
  }
}

TEST(Config, CanonicalYamlRoundTrips) {
  for (const char* file : {"config/robot_safety.yaml", "config/bmw_paper.yaml", "config/stochy_14d.yaml",
                           "test/data/tiny_reach_avoid.yaml", "test/data/tiny_safety_disturbance.yaml",
                           "test/data/tiny_autonomous.yaml", "config/arch_van_der_pol_infinite.yaml",
                           "config/arch_building_automation_7d.yaml", "config/bmw_final_approach.yaml"}) {
    const Config config = load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/" + file);
    const std::string text = to_yaml(config);
    const Config again = config_from_yaml(YAML::Load(text));
    EXPECT_EQ(to_yaml(again), text) << file;
    EXPECT_EQ(config_hash(again), config_hash(config)) << file;
    EXPECT_EQ(again.states.eta, config.states.eta) << file;  // exact doubles
    EXPECT_EQ(again.noise.covariance, config.noise.covariance) << file;
    EXPECT_EQ(again.dynamics, config.dynamics) << file;
    EXPECT_EQ(again.model, config.model) << file;
    EXPECT_EQ(again.spec.target.has_value(), config.spec.target.has_value()) << file;
  }
  // Quotes, backslashes and a ':' in text values survive.
  YAML::Node root = base();
  root["name"] = "a \"quoted\" name: with \\ and #";
  const Config config = config_from_yaml(root);
  EXPECT_EQ(config_from_yaml(YAML::Load(to_yaml(config))).name, config.name);
}

TEST(Config, SetsAreABoxOrAListOfBoxes) {
  YAML::Node root = base();
  root["spec"] = YAML::Load(
      "{type: reach_avoid, horizon: 4, target: [{lb: [5, 5], ub: [7, 7]}, {lb: [-7, 5], ub: [-5, 7]}],"
      " avoid: [{lb: [-2, -2], ub: [2, 2]}, {lb: [-9, -9], ub: [-8, -8]}, {lb: [8, -9], ub: [9, -8]}]}");
  const Config config = config_from_yaml(root);
  ASSERT_EQ(config.spec.target->boxes.size(), 2u);
  ASSERT_EQ(config.spec.avoid->boxes.size(), 3u);
  EXPECT_EQ(config.spec.target->boxes[1].lb, (std::vector<double>{-7, 5}));
  EXPECT_EQ(config.spec.avoid->boxes[2].ub, (std::vector<double>{9, -8}));
  // The canonical text keeps every box and reads back to the same configuration.
  const std::string text = to_yaml(config);
  EXPECT_NE(text.find("  target: [{lb: [5, 5], ub: [7, 7]}, {lb: [-7, 5], ub: [-5, 7]}]\n"), std::string::npos) << text;
  const Config again = config_from_yaml(YAML::Load(text));
  EXPECT_EQ(to_yaml(again), text);
  EXPECT_EQ(config_hash(again), config_hash(config));
  // Another box changes the hash; a list of one box is that box.
  root["spec"]["target"] = YAML::Load("[{lb: [5, 5], ub: [7, 7]}]");
  const Config one_listed = config_from_yaml(root);
  EXPECT_NE(config_hash(one_listed), config_hash(config));
  root["spec"]["target"] = YAML::Load("{lb: [5, 5], ub: [7, 7]}");
  EXPECT_EQ(config_hash(config_from_yaml(root)), config_hash(one_listed));

  root = base();
  root["spec"]["safe"] = YAML::Load("[{lb: [-10, -10], ub: [0, 10]}, {lb: [2, -10], ub: [10, 10]}]");
  EXPECT_EQ(config_from_yaml(root).spec.safe->boxes.size(), 2u);
}

TEST(Config, SetErrorsNameTheBox) {
  YAML::Node root = base();
  root["spec"] = YAML::Load(
      "{type: reach_avoid, horizon: 4, target: {lb: [5, 5], ub: [7, 7]},"
      " avoid: [{lb: [-2, -2], ub: [2, 2]}, {lb: [-9, -9], ub: [-8, -8]}, {lb: [8, -9], ub: [9]}]}");
  expect_error(root, "spec.avoid[2].ub", "got 1 values, expected 2 values");
  root["spec"]["avoid"][2] = YAML::Load("{lb: [8, -9], ub: [9, -10]}");
  expect_error(root, "spec.avoid[2].ub[1]", "expected a number >= spec.avoid[2].lb[1] = -9");
  root["spec"]["avoid"][2] = YAML::Load("{lb: [8, -9]}");
  expect_error(root, "spec.avoid[2].ub", "missing");
  root["spec"]["avoid"][2] = YAML::Load("{lb: [8, -9], ub: [9, -8], eta: [1, 1]}");
  expect_error(root, "spec.avoid[2].eta", "unknown key");
  root["spec"]["avoid"][2] = YAML::Load("{lb: [20, -9], ub: [30, -8]}");
  expect_error(root, "spec.avoid[2]", "contains no representative point");
  root["spec"]["avoid"] = YAML::Load("[]");
  expect_error(root, "spec.avoid", "got [], expected a box or a non-empty list of boxes");
  root["spec"]["avoid"] = YAML::Load("[1, 2]");
  expect_error(root, "spec.avoid[0]", "expected a map");
  root["spec"]["avoid"] = "everywhere";
  expect_error(root, "spec.avoid", "expected a box {lb, ub} or a list of boxes");

  root = base();
  root["spec"]["safe"] = YAML::Load("[{lb: [-10, -10], ub: [0, 10]}, {lb: [-30, -30], ub: [-20, -20]}]");
  expect_error(root, "spec.safe[1]", "contains no representative point");
  root = base();
  root["spec"] =
      YAML::Load("{type: reachability, horizon: 4, target: [{lb: [5, 5], ub: [7, 7]}, {lb: [5], ub: [7, 7]}]}");
  expect_error(root, "spec.target[1].lb", "got 1 values, expected 2 values");
}

TEST(Config, EveryTargetAndAvoidBoxPairMustShareNoGridPoint) {
  // Avoid box 1 shares [7, 5] with target box 0 (the pair of the single-box rule); the others are apart.
  YAML::Node root = base();
  root["spec"] = YAML::Load(
      "{type: reach_avoid, horizon: 4, target: [{lb: [5, 5], ub: [7, 7]}, {lb: [-7, -7], ub: [-5, -5]}],"
      " avoid: [{lb: [0, 0], ub: [1, 1]}, {lb: [6.6, 4], ub: [8, 5.2]}]}");
  expect_error(root, "spec.avoid[1]",
               "and the target box spec.target[0] [5, 5] .. [7, 7] share grid points, for example [7, 5]");
  // A single avoid box against the second of two targets.
  root["spec"]["avoid"] = YAML::Load("{lb: [-5, -5], ub: [-4, -4]}");
  expect_error(root, "spec.avoid", "the avoid box [-5, -5] .. [-4, -4] and the target box spec.target[1] [-7, -7]");
  root["spec"]["avoid"] =
      YAML::Load("[{lb: [0, 0], ub: [1, 1]}, {lb: [7.1, 4], ub: [8, 5.2]}, {lb: [-4.9, -5], ub: [-4, -4]}]");
  EXPECT_NO_THROW(config_from_yaml(root));
}

// Files written before sets could be unions carry the hash of their configuration: a single box
// must keep its text (and so the hash) exactly.
TEST(Config, SingleBoxSetsKeepTheirTextAndHash) {
  const Config config = test_support::shipped_abstraction("robot_reach_avoid.yaml");
  const std::string text = to_yaml(config);
  EXPECT_NE(text.find("\n  target: {lb: [5, 5], ub: [7, 7]}\n  avoid: {lb: [-2, -2], ub: [2, 2]}\n"),
            std::string::npos) << text;
  EXPECT_EQ(config_hash(config), "de639acadc77740b");  // the hash this configuration has always had
}

TEST(Config, HashIsStableAndSensitive) {
  const Config config = config_from_yaml(base());
  const std::string hash = config_hash(config);
  ASSERT_EQ(hash.size(), 16u);
  EXPECT_EQ(hash.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(config_hash(config_from_yaml(base())), hash);

  // Changing compute does not change the hash; any result-relevant value does.
  Config other = config;
  other.compute.device = DeviceKind::Reference;
  other.compute.memory_fraction = 0.9;
  EXPECT_EQ(config_hash(other), hash);
  other = config;
  other.noise.covariance[1] = 0.7500000001;
  EXPECT_NE(config_hash(other), hash);
  other = config;
  other.spec.horizon = 9;
  EXPECT_NE(config_hash(other), hash);
  other = config;
  other.dynamics[0] = "x0 + tau*u0*cos(u1) - w0";
  EXPECT_NE(config_hash(other), hash);
}

TEST(Config, EnumNames) {
  EXPECT_EQ(to_string(SpecType::ReachAvoid), "reach_avoid");
  EXPECT_EQ(to_string(DeviceKind::Reference), "reference");
  EXPECT_EQ(to_string(TransitionStorage::OnTheFly), "on_the_fly");
  EXPECT_EQ(to_string(NoiseType::Multiplicative), "multiplicative");
  EXPECT_EQ(to_string(Distribution::Uniform), "uniform");
  EXPECT_EQ(to_string(Truncation::FixedRegion), "fixed_region");
}

std::size_t points(const GridSpec& grid) {
  std::size_t total = 1;
  for (std::size_t i = 0; i < grid.lb.size(); ++i)
    total *= static_cast<std::size_t>(std::floor((grid.ub[i] - grid.lb[i]) / grid.eta[i] + 0.5)) + 1;
  return total;
}

TEST(Config, ExamplesLoadWithThePapersSizes) {
  const std::vector<std::pair<std::string, std::size_t>> examples = {
      {"robot_safety", 203401},        {"robot_reach_avoid", 741321}, {"room_temperature_3d", 7776},
      {"room_temperature_5d", 279936}, {"traffic_3d", 2125764},       {"traffic_5d", 68841472},
      {"vehicle3d", 1528065},          {"bmw_paper", 3937500},        {"stochy_14d", 16384}};
  for (const auto& [name, pairs] : examples) {
    SCOPED_TRACE(name);
    const Config config = load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/" + name + ".yaml");
    EXPECT_EQ(config.name, name);
    const std::size_t inputs = config.inputs ? points(*config.inputs) : 1;
    EXPECT_EQ(points(config.states) * inputs, pairs);
  }
  const Config robot = load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/robot_safety.yaml");
  ASSERT_TRUE(robot.disturbances.has_value());
  EXPECT_EQ(points(*robot.disturbances), 11u);
}

// The tests' helper builds configurations that pass the one gate, like any user input must.
TEST(Config, TestSupportBuildsValidConfigs) {
  using namespace test_support;
  EXPECT_NO_THROW(make_config(grid_spec({0, 0}, {1, 1}, {0.5, 0.5}), grid_spec({-1}, {1}, {1}), std::nullopt,
                              normal_noise({0.1, 0.1}), safety_spec(2), "helper")
                      .validate());
  EXPECT_NO_THROW(make_config(grid_spec({0}, {4}, {1}), std::nullopt, grid_spec({0}, {1}, {1}),
                              uniform_noise({0.5}), reach_avoid_spec(3, box({3}, {4}), box({0}, {1})), "helper")
                      .validate());
}

}  // namespace
}  // namespace amytiss

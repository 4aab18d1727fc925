// ROS-layer conversions without a master: parameters -> Config, lookups -> messages, progress ->
// feedback, markers, the plant model and outcome texts.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <ros/serialization.h>

#include "amytiss/abstraction.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "config_from_params.hpp"
#include "conversions.hpp"
#include "plant_model.hpp"

namespace {

const std::string kTinyConfig = std::string(AMYTISS_SOURCE_DIR) + "/test/ros/tiny_reach_avoid.yaml";
constexpr double kStatisticsStandardErrors = 4.0;

XmlRpc::XmlRpcValue list(std::initializer_list<double> values) {
  XmlRpc::XmlRpcValue array;
  array.setSize(static_cast<int>(values.size()));
  int i = 0;
  for (double v : values) array[i++] = v;
  return array;
}

XmlRpc::XmlRpcValue int_list(std::initializer_list<int> values) {
  XmlRpc::XmlRpcValue array;
  array.setSize(static_cast<int>(values.size()));
  int i = 0;
  for (int v : values) array[i++] = v;
  return array;
}

// The same tree `rosparam load test/ros/tiny_reach_avoid.yaml` puts in the private namespace
// (integers stay integers), plus the node's own keys.
XmlRpc::XmlRpcValue tiny_parameter_tree() {
  XmlRpc::XmlRpcValue tree;
  tree["name"] = std::string("tiny_reach_avoid");
  tree["states"]["lb"] = int_list({-5, -5});
  tree["states"]["ub"] = int_list({5, 5});
  tree["states"]["eta"] = list({0.5, 0.5});
  tree["inputs"]["lb"] = list({0, -3.2});
  tree["inputs"]["ub"] = list({1, 3.2});
  tree["inputs"]["eta"] = list({0.5, 0.4});
  tree["constants"]["tau"] = 1.0;
  XmlRpc::XmlRpcValue dynamics;
  dynamics.setSize(2);
  dynamics[0] = std::string("x0 + tau*u0*cos(u1)");
  dynamics[1] = std::string("x1 + tau*u0*sin(u1)");
  tree["dynamics"] = dynamics;
  tree["noise"]["type"] = std::string("additive");
  tree["noise"]["distribution"] = std::string("normal");
  tree["noise"]["covariance"] = list({0.05, 0.05});
  tree["noise"]["truncation"] = std::string("cutting_probability");
  tree["noise"]["cutting_probability"] = 1.0e-4;
  tree["spec"]["type"] = std::string("reach_avoid");
  tree["spec"]["horizon"] = 14;
  tree["spec"]["target"]["lb"] = int_list({3, 3});
  tree["spec"]["target"]["ub"] = list({4.5, 4.5});
  tree["spec"]["avoid"]["lb"] = int_list({-1, -1});
  tree["spec"]["avoid"]["ub"] = int_list({1, 1});
  tree["compute"]["device"] = std::string("reference");
  tree["compute"]["transitions"] = std::string("auto");
  tree["policy_file"] = std::string("/tmp/somewhere.h5");
  tree["device"] = std::string("cpu");
  tree["synthesize_on_start"] = true;
  return tree;
}

TEST(ConfigFromParams, EqualsTheFileItWasLoadedFrom) {
  XmlRpc::XmlRpcValue tree = tiny_parameter_tree();
  const amytiss::Config from_params = amytiss_ros::config_from_params(tree);
  const amytiss::Config from_file = amytiss::load_config_file(kTinyConfig);
  EXPECT_EQ(amytiss::to_yaml(from_params), amytiss::to_yaml(from_file));
  EXPECT_EQ(amytiss::config_hash(from_params), amytiss::config_hash(from_file));
}

TEST(ConfigFromParams, DeviceOverrideReplacesComputeDeviceButNotTheHash) {
  XmlRpc::XmlRpcValue tree = tiny_parameter_tree();
  const amytiss::Config plain = amytiss_ros::config_from_params(tree);
  const amytiss::Config on_cpu = amytiss_ros::config_from_params(tree, "cpu");
  EXPECT_EQ(plain.compute.device, amytiss::DeviceKind::Reference);
  EXPECT_EQ(on_cpu.compute.device, amytiss::DeviceKind::Cpu);
  EXPECT_EQ(amytiss::config_hash(plain), amytiss::config_hash(on_cpu));
  EXPECT_THROW(amytiss_ros::config_from_params(tree, "quantum"), amytiss::ConfigError);
}

TEST(ConfigFromParams, ASetGivenAsAListOfBoxesIsAUnion) {
  XmlRpc::XmlRpcValue tree = tiny_parameter_tree();
  XmlRpc::XmlRpcValue avoid;
  avoid.setSize(2);
  avoid[0]["lb"] = int_list({-1, -1});
  avoid[0]["ub"] = int_list({1, 1});
  avoid[1]["lb"] = list({-4.5, 2});
  avoid[1]["ub"] = list({-3, 3.5});
  tree["spec"]["avoid"] = avoid;
  const amytiss::Config config = amytiss_ros::config_from_params(tree);
  ASSERT_EQ(config.spec.avoid->boxes.size(), 2u);
  EXPECT_EQ(config.spec.avoid->boxes[1].ub, (std::vector<double>{-3, 3.5}));
  avoid[1]["ub"] = list({-3});
  tree["spec"]["avoid"] = avoid;
  try {
    amytiss_ros::config_from_params(tree);
    ADD_FAILURE() << "a box with one upper bound for two states was accepted";
  } catch (const amytiss::ConfigError& error) {
    EXPECT_EQ(error.key(), "spec.avoid[1].ub") << error.what();
  }
}

TEST(ConfigFromParams, DoublesKeepFullPrecision) {
  XmlRpc::XmlRpcValue tree = tiny_parameter_tree();
  const double awkward = 0.1 + 0.2;  // 0.30000000000000004
  tree["noise"]["covariance"] = list({awkward, 0.05});
  const amytiss::Config config = amytiss_ros::config_from_params(tree);
  EXPECT_EQ(config.noise.covariance[0], awkward);
}

TEST(ConfigFromParams, BadValuesNameTheKey) {
  XmlRpc::XmlRpcValue tree = tiny_parameter_tree();
  tree["spec"]["horizon"] = 0;
  try {
    amytiss_ros::config_from_params(tree);
    FAIL() << "horizon 0 accepted";
  } catch (const amytiss::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("horizon"), std::string::npos) << error.what();
  }
  XmlRpc::XmlRpcValue empty;
  EXPECT_THROW(amytiss_ros::config_from_params(empty), amytiss::ConfigError);
}

TEST(ConfigFromYamlText, NotYamlIsAConfigErrorOnConfigYaml) {
  try {
    amytiss_ros::config_from_yaml_text("name: [unclosed");
    FAIL() << "broken YAML accepted";
  } catch (const amytiss::ConfigError& error) {
    EXPECT_EQ(error.key(), "config_yaml");
  }
}

class LookupConversions : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const amytiss::Abstraction abstraction =
        amytiss::Abstraction::from_config(amytiss::load_config_file(kTinyConfig));
    policy_ = new amytiss::Policy(amytiss::synthesize_reference(abstraction, {}));
    policy_->config_hash = "0123456789abcdef";
    policy_->run_id = "fedcba9876543210";
  }
  static void TearDownTestSuite() { delete policy_; }
  static amytiss::Policy* policy_;
};
amytiss::Policy* LookupConversions::policy_ = nullptr;

TEST_F(LookupConversions, ResponseEqualsThePolicyForEveryCellAndStep) {
  amytiss::GetInput::Response response;
  std::vector<double> expected_input(policy_->inputs.dims());
  for (unsigned step = 0; step < policy_->horizon; ++step) {
    for (std::size_t cell = 0; cell < policy_->states.size(); ++cell) {
      const std::vector<double> state = policy_->states.point(cell);
      amytiss_ros::fill_get_input_response(policy_, state, step, "", response);
      ASSERT_TRUE(response.success) << response.message;
      EXPECT_TRUE(response.message.empty());
      const std::uint32_t index = policy_->input(step, cell);
      policy_->inputs.point(index, expected_input.data());
      ASSERT_EQ(response.input, expected_input);
      ASSERT_EQ(response.probability, policy_->value(step, cell));
      // A bounded abstraction policy's values are exact for the abstract model: nothing to bound.
      ASSERT_EQ(response.probability_upper, response.probability);
      ASSERT_EQ(response.guarantee, "abstraction");
    }
  }
}

// guarantee: system, built by hand: each (step, cell) has its own lower and upper bound, so an
// answer from the wrong row, the wrong cell or the lower bound twice is caught.
TEST(SystemGuaranteeConversions, ResponseCarriesTheLowerAndUpperBoundOfTheCell) {
  amytiss::Policy policy;
  policy.states = amytiss::Grid(amytiss::GridSpec{{0.0}, {2.0}, {1.0}});
  policy.inputs = amytiss::Grid(amytiss::GridSpec{{-1.0}, {1.0}, {2.0}});
  policy.horizon = 2;
  policy.guarantee = amytiss::Guarantee::System;
  const std::size_t cells = policy.states.size();
  ASSERT_EQ(cells, 3u);
  policy.roles.assign(cells, amytiss::CellRole::Free);
  for (unsigned step = 0; step <= policy.horizon; ++step) {
    for (std::size_t cell = 0; cell < cells; ++cell) {
      policy.values.push_back(0.1 * (step + 1) + 0.01 * double(cell));
      policy.upper_values.push_back(0.5 + 0.1 * step + 0.01 * double(cell));
      if (step < policy.horizon) policy.input_index.push_back(std::uint32_t((step + cell) % 2));
    }
  }
  amytiss::GetInput::Response response;
  for (unsigned step = 0; step < policy.horizon; ++step) {
    for (std::size_t cell = 0; cell < cells; ++cell) {
      amytiss_ros::fill_get_input_response(&policy, policy.states.point(cell), step, "", response);
      ASSERT_TRUE(response.success) << response.message;
      EXPECT_EQ(response.probability, policy.values[step * cells + cell]);
      EXPECT_EQ(response.probability_upper, policy.upper_values[step * cells + cell]);
      EXPECT_EQ(response.guarantee, "system");
      EXPECT_EQ(response.input, policy.inputs.point(policy.input(step, cell)));
    }
  }
  // A refused request still names the policy's guarantee, with no probabilities.
  amytiss_ros::fill_get_input_response(&policy, {1.0}, policy.horizon, "", response);
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.probability, 0.0);
  EXPECT_EQ(response.probability_upper, 0.0);
  EXPECT_EQ(response.guarantee, "system");
}

TEST_F(LookupConversions, MalformedRequestsGetMessagesAndNoInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const struct {
    std::vector<double> state;
    unsigned step;
    const char* expected_word;
  } cases[] = {{{1.0}, 0, "expected 2"},       {{1.0, 2.0, 3.0}, 0, "expected 2"}, {{nan, 0.0}, 0, "finite"},
               {{0.0, inf}, 0, "finite"},      {{0.0, -inf}, 0, "finite"},        {{12.0, 0.0}, 0, "outside"},
               {{0.0, -5.3}, 0, "outside"},    {{0.0, 0.0}, 14, "horizon"},       {{0.0, 0.0}, 1000, "horizon"},
               {{}, 0, "expected 2"}};
  for (const auto& c : cases) {
    amytiss::GetInput::Response response;
    response.input = {42.0};
    response.probability_upper = 0.5;
    amytiss_ros::fill_get_input_response(policy_, c.state, c.step, "", response);
    EXPECT_FALSE(response.success);
    EXPECT_TRUE(response.input.empty());
    EXPECT_EQ(response.probability, 0.0);
    EXPECT_EQ(response.probability_upper, 0.0);
    EXPECT_NE(response.message.find(c.expected_word), std::string::npos) << response.message;
  }
}

// An unbounded specification's stationary policy answers any time_step with its lower and upper
// bound.
TEST_F(LookupConversions, StationaryPolicyIgnoresTheStep) {
  amytiss::Config config = amytiss::load_config_file(kTinyConfig);
  config.spec.unbounded = true;
  config.spec.horizon = 0;
  const amytiss::Policy stationary =
      amytiss::synthesize_reference(amytiss::Abstraction::from_config(config), {});
  ASSERT_TRUE(stationary.stationary);
  std::size_t cells_with_a_gap = 0;
  for (std::size_t cell = 0; cell < stationary.states.size(); ++cell)
    cells_with_a_gap += stationary.upper_values.at(cell) != stationary.value(0, cell);
  ASSERT_GT(cells_with_a_gap, 0u) << "the upper bounds must differ from the lower ones to be told apart";
  for (unsigned step : {0u, 1u, 57u, 4000000000u}) {
    for (std::size_t cell = 0; cell < stationary.states.size(); ++cell) {
      amytiss::GetInput::Response response;
      amytiss_ros::fill_get_input_response(&stationary, stationary.states.point(cell), step, "", response);
      ASSERT_TRUE(response.success) << response.message;
      ASSERT_EQ(response.probability, stationary.value(0, cell));
      // The upper bound of the optimal value from the interval iteration, not the lower bound.
      ASSERT_EQ(response.probability_upper, stationary.upper_values[cell]);
      ASSERT_EQ(response.guarantee, "abstraction");
    }
  }
}

TEST_F(LookupConversions, NoPolicyYetSaysWhy) {
  amytiss::GetInput::Response response;
  amytiss_ros::fill_get_input_response(policy_, {0.0, 0.0}, 0, "", response);  // a previous answer
  amytiss_ros::fill_get_input_response(nullptr, {0.0, 0.0}, 0, "synthesis is running (42%)", response);
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message, "no policy yet: synthesis is running (42%)");
  EXPECT_TRUE(response.input.empty());
  EXPECT_EQ(response.config_hash, "");
  EXPECT_EQ(response.run_id, "");
  EXPECT_EQ(response.guarantee, "");
  EXPECT_EQ(response.probability_upper, 0.0);
}

TEST_F(LookupConversions, AnswersNameThePolicyAndCarryTheServerNotice) {
  const std::string notice = "synthesizer not running since 2025-11-26 13:05:00 UTC (no status for 15.2 s); "
                             "serving policy 'tiny'";
  amytiss::GetInput::Response response;
  amytiss_ros::fill_get_input_response(policy_, {0.0, 0.0}, 0, notice, response);
  EXPECT_TRUE(response.success);
  EXPECT_EQ(response.message, notice);
  EXPECT_EQ(response.config_hash, "0123456789abcdef");
  EXPECT_EQ(response.run_id, "fedcba9876543210");

  amytiss::StateStamped state;
  state.state = {0.0, 0.0};
  amytiss::InputCommand command;
  amytiss_ros::fill_input_command(policy_, state, notice, command);
  EXPECT_TRUE(command.valid);
  EXPECT_EQ(command.message, notice);
  EXPECT_EQ(command.config_hash, "0123456789abcdef");
  EXPECT_EQ(command.run_id, "fedcba9876543210");
  amytiss_ros::fill_input_command(nullptr, state, "waiting", command);
  EXPECT_FALSE(command.valid);
  EXPECT_EQ(command.config_hash, "");
}

TEST_F(LookupConversions, CommandCopiesStampAndStepAndRoundTripsThroughSerialization) {
  amytiss::StateStamped state;
  state.header.stamp = ros::Time(12, 345);
  state.header.frame_id = "map";
  state.state = {-4.0, -4.1};
  state.time_step = 3;
  amytiss::InputCommand command;
  amytiss_ros::fill_input_command(policy_, state, "", command);
  ASSERT_TRUE(command.valid) << command.message;
  EXPECT_EQ(command.header.stamp, state.header.stamp);
  EXPECT_EQ(command.header.frame_id, "map");
  EXPECT_EQ(command.time_step, 3u);
  std::vector<double> expected(policy_->inputs.dims());
  double probability = -1;
  ASSERT_EQ(policy_->lookup(state.state.data(), 2, 3, expected.data(), &probability), amytiss::LookupStatus::Ok);
  EXPECT_EQ(command.input, expected);
  EXPECT_EQ(command.probability, probability);

  // Through the wire format and back.
  const uint32_t length = ros::serialization::serializationLength(command);
  std::vector<uint8_t> buffer(length);
  ros::serialization::OStream out(buffer.data(), length);
  ros::serialization::serialize(out, command);
  amytiss::InputCommand decoded;
  ros::serialization::IStream in(buffer.data(), length);
  ros::serialization::deserialize(in, decoded);
  EXPECT_EQ(decoded, command);

  state.time_step = policy_->horizon;
  amytiss_ros::fill_input_command(policy_, state, "", command);
  EXPECT_FALSE(command.valid);
  EXPECT_TRUE(command.input.empty());
  EXPECT_FALSE(command.message.empty());
}

TEST(ProgressConversions, FeedbackCarriesEveryField) {
  amytiss::Progress progress;
  progress.phase = amytiss::Phase::Synthesis;
  progress.steps_done = 7;
  progress.steps_total = 16;
  progress.device = "reference";
  progress.elapsed_s = 1.5;
  progress.remaining_s = 2.0;
  const amytiss::SynthesizeFeedback feedback = amytiss_ros::feedback_from_progress(progress);
  EXPECT_EQ(feedback.phase, "synthesis");
  EXPECT_EQ(feedback.steps_done, 7u);
  EXPECT_EQ(feedback.steps_total, 16u);
  EXPECT_DOUBLE_EQ(feedback.percent, 43.75);
  EXPECT_EQ(feedback.device, "reference");
  EXPECT_EQ(feedback.remaining_s, 2.0);
  EXPECT_EQ(amytiss_ros::describe_progress(progress),
            "synthesis 44% (step 7/16) on reference, 1.5 s elapsed, about 2.0 s left");
  EXPECT_EQ(feedback.round, 0u);
  EXPECT_EQ(feedback.max_rounds, 0u);
  // A round of refine: the feedback and the text name it.
  progress.round = 2;
  progress.max_rounds = 6;
  const amytiss::SynthesizeFeedback refined = amytiss_ros::feedback_from_progress(progress);
  EXPECT_EQ(refined.round, 2u);
  EXPECT_EQ(refined.max_rounds, 6u);
  EXPECT_EQ(amytiss_ros::describe_progress(progress),
            "refinement round 2/6: synthesis 44% (step 7/16) on reference, 1.5 s elapsed, about 2.0 s left");
}

TEST(Markers, GridBoundsTargetAndAvoid) {
  // Read as the policy server does: from the stored canonical YAML, without validating it again.
  const amytiss::Config config = amytiss::load_config_file(kTinyConfig);
  const amytiss_ros::MarkedSets sets = amytiss_ros::marked_sets_from_yaml(amytiss::to_yaml(config));
  EXPECT_EQ(sets.config_name, config.name);
  EXPECT_FALSE(sets.safe.has_value());
  const visualization_msgs::MarkerArray markers =
      amytiss_ros::make_set_markers(amytiss::Grid(config.states), sets, "map");
  ASSERT_EQ(markers.markers.size(), 3u);
  const auto& bounds = markers.markers[0];
  EXPECT_EQ(bounds.ns, "grid_bounds");
  ASSERT_EQ(bounds.points.size(), 5u);
  EXPECT_DOUBLE_EQ(bounds.points[0].x, -5.25);
  EXPECT_DOUBLE_EQ(bounds.points[2].y, 5.25);
  const auto& target = markers.markers[1];
  EXPECT_EQ(target.ns, "target");
  EXPECT_DOUBLE_EQ(target.pose.position.x, 3.75);
  EXPECT_DOUBLE_EQ(target.scale.y, 1.5);
  EXPECT_EQ(markers.markers[2].ns, "avoid");
  EXPECT_EQ(markers.markers[2].header.frame_id, "map");
}

TEST(Markers, EveryBoxOfAUnionIsAMarkerOfItsSet) {
  const std::string yaml =
      "name: unions\nstates: {lb: [-5, -5], ub: [5, 5], eta: [0.5, 0.5]}\ndynamics: [\"x0\", \"x1\"]\n"
      "noise: {covariance: [0.05, 0.05]}\n"
      "spec: {type: reach_avoid, horizon: 2, target: [{lb: [3, 3], ub: [4.5, 4.5]}, {lb: [-4.5, 3], ub: [-3, 4.5]}],\n"
      "       avoid: [{lb: [-1, -1], ub: [1, 1]}, {lb: [2, -4], ub: [3, -3]}, {lb: [-4, -4], ub: [-3, -2]}]}\n";
  const amytiss::Config config = amytiss::config_from_yaml(YAML::Load(yaml));
  const amytiss_ros::MarkedSets sets = amytiss_ros::marked_sets_from_yaml(amytiss::to_yaml(config));
  ASSERT_TRUE(sets.target && sets.avoid);
  const visualization_msgs::MarkerArray markers =
      amytiss_ros::make_set_markers(amytiss::Grid(config.states), sets, "map");
  ASSERT_EQ(markers.markers.size(), 1u + 2u + 3u);
  EXPECT_EQ(markers.markers[2].ns, "target");
  EXPECT_EQ(markers.markers[2].id, 1);
  EXPECT_DOUBLE_EQ(markers.markers[2].pose.position.x, -3.75);
  EXPECT_EQ(markers.markers[5].ns, "avoid");
  EXPECT_EQ(markers.markers[5].id, 2);
  EXPECT_DOUBLE_EQ(markers.markers[5].pose.position.y, -3.0);
  EXPECT_DOUBLE_EQ(markers.markers[5].scale.x, 1.0);
  // A stored box that is not {lb, ub} is named with its index.
  try {
    amytiss_ros::marked_sets_from_yaml("name: x\nspec: {avoid: [{lb: [0], ub: [1]}, {lb: [0]}]}\n");
    ADD_FAILURE() << "a stored box without ub was read";
  } catch (const amytiss::ConfigError& error) {
    EXPECT_EQ(error.key(), "spec.avoid[1]") << error.what();
  }
}

TEST(Convergence, APolicyWhoseGapDidNotCloseSaysSoWithTheGap) {
  amytiss::Policy policy;
  policy.stationary = true;
  policy.iterations = 5000;
  policy.gap = 3.2e-4;
  EXPECT_EQ("", amytiss_ros::convergence_notice(policy));
  policy.converged = false;
  EXPECT_EQ("policy did not converge: gap 0.00032 after 5000 iterations; probabilities are certified lower bounds",
            amytiss_ros::convergence_notice(policy));
}

TEST(Markers, AStoredBoxThatIsNotABoxIsRefusedNamingItsKey) {
  try {
    amytiss_ros::marked_sets_from_yaml("name: broken\nspec: {type: safety, horizon: 3, safe: {lb: 1}}\n");
    FAIL() << "a box without ub was read";
  } catch (const amytiss::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("spec.safe"), std::string::npos) << error.what();
  }
}

TEST(Markers, CarBodyFollowsTheState) {
  constexpr double kTolerance = 1e-12;
  // The kinematic BMW: reference point at the rear axle, 0.965 m ahead of the rear bumper.
  const auto outline = amytiss_ros::vehicle_outline(
      amytiss::load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/bmw_parking.yaml"));
  ASSERT_TRUE(outline.has_value());
  EXPECT_EQ(outline->yaw_index, 4u);
  const double yaw = M_PI / 2;  // nose along +y: the body's centre is 4.508/2 - 0.965 ahead in y
  const visualization_msgs::Marker marker = amytiss_ros::make_car_marker({1.0, -2.0, 0.3, -0.5, yaw}, *outline, "map");
  EXPECT_EQ(marker.ns, "car");
  EXPECT_EQ(marker.id, 0);
  EXPECT_EQ(marker.type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(marker.header.frame_id, "map");
  EXPECT_NEAR(marker.pose.position.x, 1.0, kTolerance);
  EXPECT_NEAR(marker.pose.position.y, -2.0 + 4.508 / 2 - 0.965, kTolerance);
  EXPECT_NEAR(marker.pose.orientation.z, std::sin(yaw / 2), kTolerance);
  EXPECT_NEAR(marker.pose.orientation.w, std::cos(yaw / 2), kTolerance);
  EXPECT_DOUBLE_EQ(marker.scale.x, 4.508);
  EXPECT_DOUBLE_EQ(marker.scale.y, 1.61);
  // Yaw 0: the centre moves along +x.
  const auto ahead = amytiss_ros::make_car_marker({1.0, -2.0, 0.0, 0.0, 0.0}, *outline, "map");
  EXPECT_NEAR(ahead.pose.position.x, 1.0 + 4.508 / 2 - 0.965, kTolerance);
  EXPECT_NEAR(ahead.pose.position.y, -2.0, kTolerance);
  // A model that is not a car has no outline.
  EXPECT_FALSE(amytiss_ros::vehicle_outline(amytiss::load_config_file(kTinyConfig)).has_value());
  EXPECT_EQ(amytiss_ros::vehicle_motion_text(*outline, {5.5, 4.25, 0, 0, 0}, {0.0, -3.5, 0, 0, M_PI / 2}),
            " (yaw changed by 90.0 degrees, moved -5.50 m along x and -7.75 m along y)");
}

TEST(PlantModel, SameSeedSameTrajectoryAndNoiseHasTheConfiguredCovariance) {
  const amytiss::Config config = amytiss::load_config_file(kTinyConfig);
  amytiss_ros::PlantModel first(config, 7), second(config, 7), other(config, 8);
  const std::vector<double> state = {1.0, -2.0}, input = {0.0, 0.0};  // speed 0: f(x) = x
  EXPECT_EQ(first.step(state, input), second.step(state, input));
  EXPECT_NE(first.step(state, input), other.step(state, input));

  constexpr int kSamples = 20000;
  double sum = 0, sum_squares = 0;
  for (int i = 0; i < kSamples; ++i) {
    const double noise = first.step(state, input)[1] - state[1];
    sum += noise;
    sum_squares += noise * noise;
  }
  const double variance = config.noise.covariance[1];
  const double mean = sum / kSamples;
  EXPECT_LT(std::abs(mean), kStatisticsStandardErrors * std::sqrt(variance / kSamples));
  // Var of the sample variance of a normal: 2 sigma^4 / N.
  EXPECT_NEAR(sum_squares / kSamples, variance, kStatisticsStandardErrors * std::sqrt(2.0 / kSamples) * variance);
}

TEST(Outcomes, TextsPerSpecification) {
  using amytiss::SetVerdict;
  using amytiss::SpecType;
  EXPECT_EQ(amytiss_ros::episode_outcome(SpecType::ReachAvoid, SetVerdict::Target, 12).description,
            "reached the target at step 12");
  EXPECT_TRUE(amytiss_ros::episode_outcome(SpecType::ReachAvoid, SetVerdict::Target, 12).success);
  EXPECT_EQ(amytiss_ros::episode_outcome(SpecType::ReachAvoid, SetVerdict::Avoid, 3).description,
            "entered the avoid set at step 3");
  EXPECT_EQ(amytiss_ros::episode_outcome(SpecType::ReachAvoid, SetVerdict::Obstacle, 4).description,
            "touched an obstacle at step 4");
  EXPECT_EQ(amytiss_ros::episode_outcome(SpecType::Safety, SetVerdict::Unsafe, 3).description,
            "left the safe set at step 3");
  EXPECT_FALSE(amytiss_ros::episode_outcome(SpecType::Safety, SetVerdict::Unsafe, 3).success);
  EXPECT_EQ(amytiss_ros::episode_outcome(SpecType::ReachAvoid, SetVerdict::OutsideGrid, 5).description,
            "left the grid at step 5");
  EXPECT_FALSE(amytiss_ros::episode_outcome(SpecType::ReachAvoid, SetVerdict::Undecided, 14).success);
  EXPECT_TRUE(amytiss_ros::episode_outcome(SpecType::Safety, SetVerdict::Undecided, 8).success);
}

TEST(Outcomes, ConsistencyOfTheRateWithV0) {
  // V_0 0.9986 over 20 episodes: standard error sqrt(0.9986 * 0.0014 / 20) = 0.00836.
  EXPECT_EQ(amytiss_ros::consistency_text(20, 20, 0.9986),
            "|rate - V_0| = 0.0014, 4 standard errors of V_0 over 20 episodes = 0.0334: consistent");
  EXPECT_EQ(amytiss_ros::consistency_text(15, 20, 0.9986),
            "|rate - V_0| = 0.2486, 4 standard errors of V_0 over 20 episodes = 0.0334: NOT consistent");
}

TEST(Outcomes, ConsistencyOfTheRateWithTheCertifiedBounds) {
  // Lower 0.7854 over 20 episodes: 4 standard errors 4 sqrt(0.7854 * 0.2146 / 20) = 0.3672; an
  // upper bound of 1 has none. Lower 0.1, upper 0.2: 0.2 + 4 sqrt(0.2 * 0.8 / 20) = 0.5578.
  const std::string limits = " against [lower - 4 standard errors, upper + 4 standard errors] = ";
  EXPECT_EQ(amytiss_ros::bounds_consistency_text(19, 20, 0.7854, 1.0),
            "rate 0.9500" + limits + "[0.4182, 1.0000] over 20 episodes: consistent");
  EXPECT_EQ(amytiss_ros::bounds_consistency_text(5, 20, 0.7854, 1.0),
            "rate 0.2500" + limits + "[0.4182, 1.0000] over 20 episodes: NOT consistent");
  EXPECT_EQ(amytiss_ros::bounds_consistency_text(20, 20, 0.1, 0.2),
            "rate 1.0000" + limits + "[0.0000, 0.5578] over 20 episodes: NOT consistent");
}

// The configuration's own sets end an episode, not the cells' roles: (2.8, 3.5) lies in the
// target cell of centre (3, 3.5) (its point is in the target [3, 4.5]^2), not in the target.
TEST(Outcomes, ClassifyOnTheConfigurationsSets) {
  const amytiss::Config config = amytiss::load_config_file(kTinyConfig);
  const amytiss::Abstraction abstraction = amytiss::Abstraction::from_config(config);
  const amytiss::SpecSets sets(config);
  using amytiss::SetVerdict;
  EXPECT_EQ(amytiss_ros::classify_state(sets, {3.5, 4.0}), SetVerdict::Target);
  const std::vector<double> near_target = {2.8, 3.5};
  const auto cell = abstraction.states.cell_of(near_target.data());
  ASSERT_TRUE(cell.has_value());
  ASSERT_EQ(abstraction.roles[*cell], amytiss::CellRole::FixedOne);
  EXPECT_EQ(amytiss_ros::classify_state(sets, near_target), SetVerdict::Undecided);
  EXPECT_EQ(amytiss_ros::classify_state(sets, {0.2, -0.9}), SetVerdict::Avoid);
  EXPECT_EQ(amytiss_ros::classify_state(sets, {-4.0, -4.0}), SetVerdict::Undecided);
  EXPECT_EQ(amytiss_ros::classify_state(sets, {-5.3, 0.0}), SetVerdict::OutsideGrid);
  EXPECT_EQ(amytiss_ros::classify_state(sets, {0.0}), SetVerdict::OutsideGrid);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

// The engine's phase names are the message constants, in PolicyStatus and in the action feedback.
TEST(ProgressConversions, PhaseNamesAreTheMessageConstants) {
  const std::pair<amytiss::Phase, std::string> status_phases[] = {
      {amytiss::Phase::Setup, amytiss::PolicyStatus::PHASE_SETUP},
      {amytiss::Phase::Construction, amytiss::PolicyStatus::PHASE_CONSTRUCTION},
      {amytiss::Phase::Synthesis, amytiss::PolicyStatus::PHASE_SYNTHESIS},
      {amytiss::Phase::Done, amytiss::PolicyStatus::PHASE_DONE}};
  for (const auto& [phase, name] : status_phases) EXPECT_EQ(amytiss::to_string(phase), name);
  const std::pair<amytiss::Phase, std::string> feedback_phases[] = {
      {amytiss::Phase::Setup, amytiss::SynthesizeFeedback::PHASE_SETUP},
      {amytiss::Phase::Construction, amytiss::SynthesizeFeedback::PHASE_CONSTRUCTION},
      {amytiss::Phase::Synthesis, amytiss::SynthesizeFeedback::PHASE_SYNTHESIS},
      {amytiss::Phase::Done, amytiss::SynthesizeFeedback::PHASE_DONE}};
  for (const auto& [phase, name] : feedback_phases) EXPECT_EQ(amytiss::to_string(phase), name);
}

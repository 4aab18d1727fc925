// The integrator (models/integrator.h) and the kinematic single-track model bmw320i_ks: default
// unchanged, configuration, accuracy against an independent fine integration, stability at
// parking speed, dependencies, and the same numbers from the OpenCL engine.
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/model.hpp"

namespace amytiss {
namespace {

constexpr double kFineVsModelTolerance = 1e-6;   // RK4 x4 per 0.5 s step against RK4 x1000 (error ~ h^4)
// RK4 x10 per 0.1 s on the stiff single-track model (h*rate near -2.2 at 1 m/s, close to RK4's
// stability edge -2.78) against RK4 x1000: measured 3.3e-5.
constexpr double kStiffFineVsModelTolerance = 1e-4;
constexpr double kOscillatorTolerance = 1e-8;    // RK4 x20 over 0.5 s on x'' = -x against cos/sin
constexpr double kEngineTolerance = 1e-5;        // OpenCL engine against the reference (docs/engine.md)
constexpr int kFineSubsteps = 1000;

const std::string kSource = AMYTISS_SOURCE_DIR;

/// A configuration with `model_yaml` (e.g. "model: bmw320i") and `integrator_yaml` (may be empty)
/// on a grid of `states` x `inputs` dimensions, states spanning [-half_width, half_width] (eta 1).
Config config_of(const std::string& model_yaml, std::size_t states, std::size_t inputs,
                 const std::string& integrator_yaml = "", double half_width = 2.0) {
  YAML::Node root = YAML::Load(model_yaml);
  if (!integrator_yaml.empty()) root["integrator"] = YAML::Load(integrator_yaml);
  root["name"] = "t";
  for (std::size_t i = 0; i < states; ++i) {
    root["states"]["lb"].push_back(-half_width);
    root["states"]["ub"].push_back(half_width);
    root["states"]["eta"].push_back(1.0);
    root["noise"]["covariance"].push_back(0.01);
  }
  for (std::size_t i = 0; i < inputs; ++i) {
    root["inputs"]["lb"].push_back(-1.0);
    root["inputs"]["ub"].push_back(1.0);
    root["inputs"]["eta"].push_back(1.0);
  }
  root["spec"]["type"] = "safety";
  root["spec"]["horizon"] = 1;
  return config_from_yaml(root);
}

std::vector<double> step(const Dynamics& dynamics, const std::vector<double>& x, const std::vector<double>& u) {
  std::vector<double> post(x.size());
  dynamics.evaluate(x.data(), u.data(), nullptr, post.data());
  return post;
}

using Rate = std::function<void(const double* x, double* rate)>;

/// Classical RK4 written here, independently of models/integrator.h.
std::vector<double> fine_rk4(const Rate& rate, std::vector<double> x, double tau, int substeps) {
  const std::size_t n = x.size();
  const double h = tau / substeps;
  std::vector<double> k1(n), k2(n), k3(n), k4(n), y(n);
  for (int s = 0; s < substeps; ++s) {
    rate(x.data(), k1.data());
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i] + h / 2 * k1[i];
    rate(y.data(), k2.data());
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i] + h / 2 * k2[i];
    rate(y.data(), k3.data());
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i] + h * k3[i];
    rate(y.data(), k4.data());
    for (std::size_t i = 0; i < n; ++i) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  }
  return x;
}

/// The kinematic single-track model written from CommonRoad's vehicleDynamics_KS (inputs within
/// the limits, so no saturation acts): wheelbase l_f + l_r = 1.156 + 1.422.
Rate independent_ks(double steering_velocity, double acceleration) {
  return [=](const double* x, double* rate) {
    rate[0] = x[3] * std::cos(x[4]);
    rate[1] = x[3] * std::sin(x[4]);
    rate[2] = steering_velocity;
    rate[3] = acceleration;
    rate[4] = x[3] / 2.578 * std::tan(x[2]);
  };
}

double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
  return worst;
}

TEST(Integrator, DefaultIsOneEulerStepOfTheModelsOwnLength) {
  const auto implicit = make_dynamics(config_of("model: bmw320i", 7, 2));
  const auto explicit_default = make_dynamics(config_of("model: bmw320i", 7, 2, "{method: euler, substeps: 1}"));
  const auto field = make_vector_field(config_of("model: bmw320i", 7, 2));
  const std::vector<double> x = {1, 2, 0.1, 1.5, 0.3, 0.1, 0.01}, u = {0.2, 1.0};
  std::vector<double> rate(7);
  field->rate(x.data(), u.data(), nullptr, rate.data());
  const auto a = step(*implicit, x, u), b = step(*explicit_default, x, u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(a[i], x[i] + 0.1 * rate[i]) << "x" << i;  // bit for bit what one Euler step gives
    EXPECT_EQ(a[i], b[i]) << "x" << i;
  }
}

TEST(Integrator, DefaultKeepsTheCanonicalTextAndHash) {
  for (const char* name : {"bmw_paper", "robot_reach_avoid", "vehicle3d"}) {
    Config config = load_config_file(kSource + "/config/" + name + ".yaml");
    const std::string text = to_yaml(config), hash = config_hash(config);
    EXPECT_EQ(text.find("integrator"), std::string::npos) << name;
    config.integrator = IntegratorConfig{};  // the same as `integrator: {method: euler, substeps: 1}`
    EXPECT_EQ(config_hash(config), hash) << name;
  }
  // The hash a policy file of test/data/cli_tiny.yaml carried before the integrator existed.
  EXPECT_EQ(config_hash(load_config_file(kSource + "/test/data/cli_tiny.yaml")), "ddf803483f1018ef");
  Config rk4 = config_of("model: bmw320i_ks", 5, 2, "{method: rk4, substeps: 4, tau: 0.5}");
  const std::string text = to_yaml(rk4);
  EXPECT_NE(text.find("integrator: {method: rk4, substeps: 4, tau: 0.5}"), std::string::npos) << text;
  const Config again = config_from_yaml(YAML::Load(text));
  EXPECT_EQ(to_yaml(again), text);
  EXPECT_NE(config_hash(again), config_hash(config_of("model: bmw320i_ks", 5, 2)));
}

TEST(Integrator, ValidationNamesTheKey) {
  const auto expect_error = [](const std::string& model, std::size_t n, const std::string& integrator,
                               const std::string& key, const std::string& fragment) {
    try {
      config_of(model, n, 1, integrator, n > 2 ? 0.0 : 2.0);
      ADD_FAILURE() << integrator << " accepted";
    } catch (const ConfigError& error) {
      EXPECT_EQ(error.key(), key) << error.what();
      EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
    }
  };
  const std::string oscillator = "dynamics: [\"x1\", \"-x0 + u0\"]";
  expect_error(oscillator, 2, "{method: rk4, substeps: 4}", "integrator.tau", "vector field dx/dt");
  expect_error(oscillator, 2, "{method: midpoint, tau: 0.1}", "integrator.method", "one of euler, rk4");
  expect_error(oscillator, 2, "{substeps: 0, tau: 0.1}", "integrator.substeps", "an integer in [1, 100000]");
  expect_error(oscillator, 2, "{substeps: 2.5, tau: 0.1}", "integrator.substeps",
               "got 2.5, expected a positive integer");
  expect_error(oscillator, 2, "{substeps: -1, tau: 0.1}", "integrator.substeps", "got -1, expected a positive integer");
  expect_error(oscillator, 2, "{tau: -0.1}", "integrator.tau", "a time step in seconds > 0");
  expect_error(oscillator, 2, "{tau: 0}", "integrator.tau", "a time step in seconds > 0");
  expect_error(oscillator, 2, "{steps: 2, tau: 0.1}", "integrator.steps", "unknown key");
  // A discrete map of any size needs no integrator; an integrated one has stage arrays of 32.
  std::string big = "dynamics: [";
  for (int i = 0; i < 33; ++i) big += std::string(i ? ", " : "") + "\"-x" + std::to_string(i) + "\"";
  EXPECT_NO_THROW(config_of(big + "]", 33, 1, "", 0.0));
  expect_error(big + "]", 33, "{tau: 0.1}", "integrator", "at most 32");
}

TEST(Integrator, ExpressionsWithTauAreTheVectorField) {
  // x0' = x1, x1' = -x0: the exact step is a rotation by tau.
  const std::string oscillator = "dynamics: [\"x1\", \"-x0 + u0\"]";
  const auto rk4 = make_dynamics(config_of(oscillator, 2, 1, "{method: rk4, substeps: 20, tau: 0.5}"));
  const auto euler = make_dynamics(config_of(oscillator, 2, 1, "{tau: 0.5}"));
  EXPECT_EQ(rk4->describe(), "expressions dx/dt (2), rk4 x20 per step of 0.5 s");
  const std::vector<double> x = {1.0, 0.5}, u = {0.0};
  const auto post = step(*rk4, x, u);
  EXPECT_NEAR(post[0], std::cos(0.5) + 0.5 * std::sin(0.5), kOscillatorTolerance);
  EXPECT_NEAR(post[1], -std::sin(0.5) + 0.5 * std::cos(0.5), kOscillatorTolerance);
  const auto once = step(*euler, x, u);
  EXPECT_EQ(once[0], 1.0 + 0.5 * 0.5);
  EXPECT_EQ(once[1], 0.5 + 0.5 * -1.0);
}

TEST(Integrator, KinematicModelAgreesWithAFineIndependentIntegration) {
  const auto model = make_dynamics(config_of("model: bmw320i_ks", 5, 2, "{method: rk4, substeps: 4, tau: 0.5}"));
  const auto euler = make_dynamics(config_of("model: bmw320i_ks", 5, 2, "{method: euler, substeps: 1, tau: 0.5}"));
  std::mt19937 generator(3);
  std::uniform_real_distribution<double> position(-10, 10), steering(-0.6, 0.6), speed(-1.5, 1.5),
      yaw(-3.1, 3.1), steering_velocity(-0.39, 0.39), acceleration(-2, 2);
  double worst = 0, worst_euler = 0;
  for (int sample = 0; sample < 200; ++sample) {
    const std::vector<double> x = {position(generator), position(generator), steering(generator),
                                   speed(generator), yaw(generator)};
    const std::vector<double> u = {steering_velocity(generator), acceleration(generator)};
    const auto fine = fine_rk4(independent_ks(u[0], u[1]), x, 0.5, kFineSubsteps);
    worst = std::max(worst, max_difference(step(*model, x, u), fine));
    worst_euler = std::max(worst_euler, max_difference(step(*euler, x, u), fine));
  }
  std::printf("bmw320i_ks, 0.5 s step: max |error| rk4 x4 %.3g, euler x1 %.3g (against rk4 x%d)\n", worst,
              worst_euler, kFineSubsteps);
  EXPECT_LE(worst, kFineVsModelTolerance);
  EXPECT_GT(worst_euler, 100 * kFineVsModelTolerance);  // why the parking example integrates with RK4
}

TEST(Integrator, Vehicle3dAgreesWithAFineIndependentIntegration) {
  const auto model = make_dynamics(config_of("model: vehicle3d", 3, 2, "{method: rk4, substeps: 4}"));
  std::mt19937 generator(4);
  std::uniform_real_distribution<double> position(-5, 5), heading(-3.1, 3.1), speed(-1, 2), steering(-0.5, 0.5);
  double worst = 0;
  for (int sample = 0; sample < 100; ++sample) {
    const std::vector<double> x = {position(generator), position(generator), heading(generator)};
    const std::vector<double> u = {speed(generator), steering(generator)};
    // Reissig et al. 2016, section IX-A, written here again.
    const double alpha = std::atan(std::tan(u[1]) / 2);
    const Rate rate = [&](const double* state, double* out) {
      out[0] = u[0] * std::cos(alpha + state[2]) / std::cos(alpha);
      out[1] = u[0] * std::sin(alpha + state[2]) / std::cos(alpha);
      out[2] = u[0] * std::tan(u[1]);
    };
    worst = std::max(worst, max_difference(step(*model, x, u), fine_rk4(rate, x, 0.3, kFineSubsteps)));
  }
  std::printf("vehicle3d, 0.3 s step: max |error| rk4 x4 %.3g (against rk4 x%d)\n", worst, kFineSubsteps);
  EXPECT_LE(worst, kFineVsModelTolerance);
}

TEST(Integrator, SingleTrackModelAgreesWithAFineIntegrationOfItsVectorField) {
  // Stiff at low speed (rates of about -216/v per second): RK4 is stable for h < 2.78/216 s at 1 m/s.
  const Config config = config_of("model: bmw320i", 7, 2, "{method: rk4, substeps: 10}");
  const auto model = make_dynamics(config);
  const auto field = make_vector_field(config);
  std::mt19937 generator(5);
  std::uniform_real_distribution<double> steering(-0.3, 0.3), speed(1, 5), yaw(-1, 1), yaw_rate(-0.3, 0.3),
      slip(-0.03, 0.03), steering_velocity(-0.39, 0.39), acceleration(-1, 1);
  double worst = 0;
  for (int sample = 0; sample < 100; ++sample) {
    const std::vector<double> x = {0, 0, steering(generator), speed(generator), yaw(generator), yaw_rate(generator),
                                   slip(generator)};
    const std::vector<double> u = {steering_velocity(generator), acceleration(generator)};
    const Rate rate = [&](const double* state, double* out) { field->rate(state, u.data(), nullptr, out); };
    worst = std::max(worst, max_difference(step(*model, x, u), fine_rk4(rate, x, 0.1, kFineSubsteps)));
  }
  std::printf("bmw320i, 0.1 s step, 1-5 m/s: max |error| rk4 x10 %.3g (against rk4 x%d)\n", worst, kFineSubsteps);
  EXPECT_LE(worst, kStiffFineVsModelTolerance);
}

/// 32 steps of a right turn at 1 m/s: steer at 0.4 rad/s for 0.5 s, then hold.
std::vector<double> turn_for_32_steps(const Dynamics& dynamics, std::vector<double> x, double* max_abs) {
  *max_abs = 0;
  for (int k = 0; k < 32; ++k) {
    x = step(dynamics, x, {k < 5 ? 0.4 : 0.0, 0.0});
    for (double value : x) *max_abs = std::max(*max_abs, std::fabs(value));
  }
  return x;
}

TEST(Integrator, TurningAtOneMetrePerSecondStaysBounded) {
  double euler_max = 0, rk4_max = 0, ks_max = 0;
  turn_for_32_steps(*make_dynamics(config_of("model: bmw320i", 7, 2)), {0, 0, 0, 1, 0, 0, 0}, &euler_max);
  const auto st = turn_for_32_steps(*make_dynamics(config_of("model: bmw320i", 7, 2, "{method: rk4, substeps: 10}")),
                                    {0, 0, 0, 1, 0, 0, 0}, &rk4_max);
  const auto ks = turn_for_32_steps(*make_dynamics(config_of("model: bmw320i_ks", 5, 2, "{method: rk4, substeps: 1}")),
                                    {0, 0, 0, 1, 0}, &ks_max);
  std::printf("32 steps of 0.1 s turning at 1 m/s: max |x| euler %.3g, rk4 x10 %.3g; yaw ST %.4f, KS %.4f rad\n",
              euler_max, rk4_max, st[4], ks[4]);
  EXPECT_GT(euler_max, 1e6);  // the paper's one Euler step diverges (docs/bmw_parking.md)
  EXPECT_LT(rk4_max, 5.0);    // 3.2 m travelled; yaw, yaw rate, slip angle small
  EXPECT_LT(std::fabs(st[5]), 0.2);
  // Steady cornering at low speed: the slip angle is the kinematic one, atan(l_r/l_wb tan(0.2)).
  EXPECT_NEAR(st[6], std::atan(1.422 / 2.578 * std::tan(0.2)), 0.01);
  // Steering angle 0.2 rad: yaw rate v/l_wb tan(0.2) = 0.0784 rad/s; both models turn by about it.
  EXPECT_NEAR(ks[4], st[4], 0.02);
  EXPECT_GT(ks[4], 0.15);
}

TEST(Integrator, DependenciesAreTheClosureOverStages) {
  // g0 = x1, g1 = x2 + u0, g2 = w0, g3 = x3.
  const std::vector<VariableUse> field = {{{1}, {}, {}}, {{2}, {0}, {}}, {{}, {}, {0}}, {{3}, {}, {}}};
  const auto euler = integrated_dependencies(field, IntegratorConfig{});
  EXPECT_EQ(euler[0].states, (std::vector<std::size_t>{0, 1}));
  EXPECT_TRUE(euler[0].inputs.empty());
  EXPECT_EQ(euler[1].states, (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(euler[1].inputs, (std::vector<std::size_t>{0}));
  EXPECT_EQ(euler[2].states, (std::vector<std::size_t>{2}));
  EXPECT_EQ(euler[2].disturbances, (std::vector<std::size_t>{0}));
  EXPECT_EQ(euler[3].states, (std::vector<std::size_t>{3}));
  for (const IntegratorConfig integrator :
       {IntegratorConfig{IntegrationMethod::Rk4, 1, std::nullopt}, IntegratorConfig{IntegrationMethod::Euler, 2, 0.1}}) {
    const auto closure = integrated_dependencies(field, integrator);
    EXPECT_EQ(closure[0].states, (std::vector<std::size_t>{0, 1, 2}));
    EXPECT_EQ(closure[0].inputs, (std::vector<std::size_t>{0}));
    EXPECT_EQ(closure[0].disturbances, (std::vector<std::size_t>{0}));
    EXPECT_EQ(closure[3].states, (std::vector<std::size_t>{3}));
    EXPECT_TRUE(closure[3].inputs.empty());
  }
}

// What dependencies() claims is checked on the function: changing a component that coordinate i
// does not list leaves post_i unchanged, and each listed state does change it somewhere.
TEST(Integrator, DependenciesHoldForTheIntegratedModels) {
  for (const std::string integrator : {"{method: euler, substeps: 1}", "{method: rk4, substeps: 3}"}) {
    for (const auto& [model, n] : {std::pair<std::string, std::size_t>{"bmw320i_ks", 5}, {"vehicle3d", 3}}) {
      SCOPED_TRACE(model + " " + integrator);
      const auto dynamics = make_dynamics(config_of("model: " + model, n, 2, integrator));
      const auto uses = dynamics->dependencies();
      ASSERT_TRUE(uses.has_value());
      std::mt19937 generator(9);
      std::uniform_real_distribution<double> value(-0.5, 0.5);
      for (int sample = 0; sample < 20; ++sample) {
        std::vector<double> x(n), u(2);
        for (auto& v : x) v = value(generator) + 1.0;
        for (auto& v : u) v = value(generator) * 0.5;
        const auto base = step(*dynamics, x, u);
        for (std::size_t j = 0; j < n + 2; ++j) {
          auto x2 = x, u2 = u;
          (j < n ? x2[j] : u2[j - n]) += 0.1;
          const auto moved = step(*dynamics, x2, u2);
          for (std::size_t i = 0; i < n; ++i) {
            const auto& listed = j < n ? (*uses)[i].states : (*uses)[i].inputs;
            const std::size_t index = j < n ? j : j - n;
            if (std::find(listed.begin(), listed.end(), index) == listed.end()) {
              EXPECT_EQ(moved[i], base[i]) << "post " << i << " changed with component " << j;
            }
          }
        }
      }
    }
  }
  EXPECT_FALSE(make_dynamics(config_of("model: bmw320i", 7, 2))->dependencies().has_value());
}

TEST(Integrator, OpenclEngineAgreesWithTheReferenceOnAnIntegratedModel) {
  // A small parking-like grid of the kinematic model, RK4 with two sub-steps of 0.25 s.
  const Config config = config_from_yaml(YAML::Load(R"(
name: ks_tiny
states: {lb: [-1, -1, -0.2, 0, -0.4], ub: [1, 1, 0.2, 1, 0.4], eta: [0.5, 0.5, 0.2, 0.5, 0.2]}
inputs: {lb: [-0.4, -1], ub: [0.4, 1], eta: [0.4, 1]}
model: bmw320i_ks
integrator: {method: rk4, substeps: 2, tau: 0.5}
noise: {covariance: [0.01, 0.01, 0, 0, 0.001]}
spec: {type: reach_avoid, horizon: 4, target: {lb: [0.5, -1, -0.2, 0, -0.4], ub: [1, 1, 0.2, 1, 0.4]}}
)"));
  const Abstraction abstraction = Abstraction::from_config(config);
  const Policy reference = synthesize_reference(abstraction, {}, nullptr);
  SynthesisOptions options;
  options.compute.device = DeviceKind::Cpu;
  const Policy opencl = synthesize(abstraction, options, nullptr);
  ASSERT_EQ(reference.values.size(), opencl.values.size());
  double worst = 0, best = 0;
  for (std::size_t i = 0; i < reference.values.size(); ++i) {
    worst = std::max(worst, std::fabs(reference.values[i] - opencl.values[i]));
    best = std::max(best, reference.values[i]);
  }
  EXPECT_LE(worst, kEngineTolerance);
  EXPECT_GT(best, 0.5);  // the example is not all zeros
}

}  // namespace
}  // namespace amytiss

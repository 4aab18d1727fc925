#pragma once
// Helpers for tests: tiny Abstractions built by hand with lambda dynamics, without expressions or
// built-in models. Other areas' tests use these; keep the interface stable.
//
//   using namespace amytiss::test_support;
//   auto dynamics = std::make_shared<LambdaDynamics>(1, 1, 0,
//       [](const double* x, const double* u, const double*, double* post) { post[0] = x[0] + u[0]; },
//       "post[0] = x[0] + u[0];");                       // optional OpenCL C body
//   Config config = make_config(grid_spec({-1}, {1}, {0.5}), grid_spec({-0.5}, {0.5}, {0.5}),
//                               std::nullopt, normal_noise({0.09}), safety_spec(2));
//   Abstraction abstraction = Abstraction::from_parts(config, dynamics);
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/footprint.hpp"
#include "amytiss/format.hpp"
#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/model.hpp"
#include "amytiss/synthesis_types.hpp"

namespace amytiss {
namespace test_support {

/// A car-like body on the pose components (x, y, yaw) = state dimensions (0, 1, 2), in metres.
inline Footprint car(double length, double width, double rear_overhang) {
  Footprint footprint;
  footprint.pose = {0, 1, 2};
  footprint.length = length;
  footprint.width = width;
  footprint.rear_overhang = rear_overhang;
  return footprint;
}

/// Dynamics from a C++ callable. `opencl_body` is the body of amytiss_dynamics in OpenCL C (the
/// statements that fill post[] from x[], u[], w[]); empty when the test never runs OpenCL.
class LambdaDynamics : public Dynamics {
 public:
  using Function = std::function<void(const double* x, const double* u, const double* w, double* post)>;
  LambdaDynamics(std::size_t state_dims, std::size_t input_dims, std::size_t disturbance_dims,
                 Function function, std::string opencl_body = "")
      : state_dims_(state_dims),
        input_dims_(input_dims),
        disturbance_dims_(disturbance_dims),
        function_(std::move(function)),
        opencl_body_(std::move(opencl_body)) {}
  std::size_t state_dims() const override { return state_dims_; }
  std::size_t input_dims() const override { return input_dims_; }
  std::size_t disturbance_dims() const override { return disturbance_dims_; }
  void evaluate(const double* x, const double* u, const double* w, double* post) const override {
    function_(x, u, w, post);
  }
  std::string opencl_source() const override {
    return "void amytiss_dynamics(const double* x, const double* u, const double* w, double* post) {\n" +
           opencl_body_ + "\n}\n";
  }
  std::string describe() const override { return "test lambda dynamics"; }
  const std::string& opencl_body() const { return opencl_body_; }

 private:
  std::size_t state_dims_, input_dims_, disturbance_dims_;
  Function function_;
  std::string opencl_body_;
};

inline GridSpec grid_spec(std::vector<double> lb, std::vector<double> ub, std::vector<double> eta) {
  GridSpec spec;
  spec.lb = std::move(lb);
  spec.ub = std::move(ub);
  spec.eta = std::move(eta);
  return spec;
}

inline Box box(std::vector<double> lb, std::vector<double> ub) {
  Box result;
  result.lb = std::move(lb);
  result.ub = std::move(ub);
  return result;
}

/// Additive normal noise; covariance: n values (diagonal) or n*n (full).
inline NoiseConfig normal_noise(std::vector<double> covariance, Truncation truncation = Truncation::None,
                                double cutting_probability = NoiseConfig::kDefaultCuttingProbability,
                                std::vector<double> fixed_region = {}) {
  NoiseConfig noise;
  noise.type = NoiseType::Additive;
  noise.distribution = Distribution::Normal;
  noise.covariance = std::move(covariance);
  noise.truncation = truncation;
  if (truncation == Truncation::CuttingProbability) noise.cutting_probability = cutting_probability;
  noise.fixed_region = std::move(fixed_region);
  return noise;
}

/// Additive uniform noise on [-h, h] per dimension.
inline NoiseConfig uniform_noise(std::vector<double> half_width, Truncation truncation = Truncation::None) {
  NoiseConfig noise;
  noise.type = NoiseType::Additive;
  noise.distribution = Distribution::Uniform;
  noise.half_width = std::move(half_width);
  noise.truncation = truncation;
  return noise;
}

inline SpecConfig safety_spec(unsigned horizon, std::optional<Region> safe = std::nullopt) {
  SpecConfig spec;
  spec.type = SpecType::Safety;
  spec.horizon = horizon;
  spec.safe = std::move(safe);
  return spec;
}

inline SpecConfig reach_avoid_spec(unsigned horizon, Region target, std::optional<Region> avoid = std::nullopt) {
  SpecConfig spec;
  spec.type = avoid ? SpecType::ReachAvoid : SpecType::Reachability;
  spec.horizon = horizon;
  spec.target = std::move(target);
  spec.avoid = std::move(avoid);
  return spec;
}

/// A valid Config for from_parts (it passes Config::validate() when the grids and the spec do).
/// `description` is its name, so that different test problems get different config hashes; its
/// dynamics is the identity x_i (from_parts runs the dynamics it is given).
inline Config make_config(GridSpec states, std::optional<GridSpec> inputs, std::optional<GridSpec> disturbances,
                          NoiseConfig noise, SpecConfig spec, const std::string& description = "test") {
  Config config;
  config.name = description;
  config.states = std::move(states);
  config.inputs = std::move(inputs);
  config.disturbances = std::move(disturbances);
  config.noise = std::move(noise);
  config.spec = std::move(spec);
  for (std::size_t i = 0; i < config.states.lb.size(); ++i) config.dynamics.push_back("x" + std::to_string(i));
  config.compute.device = DeviceKind::Reference;
  return config;
}

/// An empty directory for the running test, "<temp>/<prefix><pid>_<test name>" (any earlier one of
/// that name removed first); the caller removes it when done.
inline std::filesystem::path fresh_test_directory(const std::string& prefix) {
  const std::filesystem::path directory =
      std::filesystem::temp_directory_path() /
      (prefix + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  return directory;
}

/// A shipped configuration (config/<file>) read as the abstraction, whatever guarantee it states:
/// the OpenCL engines' tests and the abstraction's hashes run on it.
inline Config shipped_abstraction(const std::string& file) {
  ComputeOverrides overrides;
  overrides.guarantee = "abstraction";
  return load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/" + file, overrides);
}

/// The abstraction of a configuration given as YAML text (validated, like a configuration file).
inline Abstraction from_yaml(const std::string& text) {
  return Abstraction::from_config(config_from_yaml(YAML::Load(text)));
}

inline Abstraction make_abstraction(const Config& config, std::shared_ptr<const Dynamics> dynamics) {
  return Abstraction::from_parts(config, std::move(dynamics));
}

/// A random affine system post = A x + B u + C w + c (fixed seed), with its OpenCL body, on a grid
/// of `cells_per_dim` points per state dimension over [-1, 1], inputs 3 points per dimension over
/// [-0.5, 0.5], and 2 disturbance points in [-0.2, 0.2] when `with_disturbance`. Diagonal normal
/// noise with standard deviation 0.3 and the given truncation. A contraction (|A| entries small)
/// keeps mass on the grid so that the values are not trivially 0.
inline Abstraction random_affine_abstraction(std::uint64_t seed, std::size_t state_dims, std::size_t input_dims,
                                             bool with_disturbance, SpecConfig spec,
                                             std::size_t cells_per_dim = 5,
                                             Truncation truncation = Truncation::CuttingProbability) {
  std::mt19937_64 generator(seed);
  std::uniform_real_distribution<double> coefficient(-0.4, 0.4);
  const std::size_t disturbance_dims = with_disturbance ? 1 : 0;
  std::vector<double> a(state_dims * state_dims), b(state_dims * input_dims), c(state_dims * disturbance_dims),
      offset(state_dims);
  for (auto& value : a) value = coefficient(generator);
  for (std::size_t i = 0; i < state_dims; ++i) a[i * state_dims + i] += 0.5;
  for (auto& value : b) value = 2.0 * coefficient(generator);
  for (auto& value : c) value = coefficient(generator);
  for (auto& value : offset) value = 0.25 * coefficient(generator);
  auto print = [](double value) { return format_number(value); };
  std::string body;
  for (std::size_t i = 0; i < state_dims; ++i) {
    body += "post[" + std::to_string(i) + "] = " + print(offset[i]);
    for (std::size_t j = 0; j < state_dims; ++j)
      body += " + " + print(a[i * state_dims + j]) + " * x[" + std::to_string(j) + "]";
    for (std::size_t j = 0; j < input_dims; ++j)
      body += " + " + print(b[i * input_dims + j]) + " * u[" + std::to_string(j) + "]";
    for (std::size_t j = 0; j < disturbance_dims; ++j)
      body += " + " + print(c[i * disturbance_dims + j]) + " * w[" + std::to_string(j) + "]";
    body += ";\n";
  }
  auto function = [=](const double* x, const double* u, const double* w, double* post) {
    for (std::size_t i = 0; i < state_dims; ++i) {
      double sum = offset[i];
      for (std::size_t j = 0; j < state_dims; ++j) sum += a[i * state_dims + j] * x[j];
      for (std::size_t j = 0; j < input_dims; ++j) sum += b[i * input_dims + j] * u[j];
      for (std::size_t j = 0; j < disturbance_dims; ++j) sum += c[i * disturbance_dims + j] * w[j];
      post[i] = sum;
    }
  };
  auto dynamics = std::make_shared<LambdaDynamics>(state_dims, input_dims, disturbance_dims, function, body);
  const double eta = 2.0 / double(cells_per_dim - 1);
  std::optional<GridSpec> inputs;
  if (input_dims)
    inputs = grid_spec(std::vector<double>(input_dims, -0.5), std::vector<double>(input_dims, 0.5),
                       std::vector<double>(input_dims, 0.5));
  std::optional<GridSpec> disturbances;
  if (with_disturbance) disturbances = grid_spec({-0.2}, {0.2}, {0.4});
  Config config = make_config(grid_spec(std::vector<double>(state_dims, -1.0), std::vector<double>(state_dims, 1.0),
                                        std::vector<double>(state_dims, eta)),
                              inputs, disturbances,
                              normal_noise(std::vector<double>(state_dims, 0.09), truncation, 1e-3),
                              std::move(spec), "random affine seed " + std::to_string(seed) + ": " + body);
  return Abstraction::from_parts(config, dynamics);
}

/// The 3-d traffic ring of config/traffic_3d.yaml on a coarser grid of [0, upper]^3: few inputs,
/// wide windows.
inline std::string traffic_yaml(double eta, unsigned horizon, double upper = 8) {
  const std::string e = std::to_string(eta), u = std::to_string(upper);
  return "name: traffic_small\n"
         "states: {lb: [0, 0, 0], ub: [" + u + ", " + u + ", " + u + "], eta: [" + e + ", " + e + ", " + e + "]}\n"
         "inputs: {lb: [0, 0], ub: [1, 1], eta: [1, 1]}\n"
         "constants: {flow: 0.36, q: 0.5, entry1: 6.0, entry3: 8.0}\n"
         "dynamics: [\"(1 - flow)*x0 + flow*x2 + entry1*u0\", \"(1 - flow - q)*x1 + flow*x0\",\n"
         "           \"(1 - flow)*x2 + flow*x1 + entry3*u1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.7, 0.7, 0.7],\n"
         "        truncation: cutting_probability, cutting_probability: 2.0e-2}\n"
         "spec: {type: safety, horizon: " + std::to_string(horizon) + "}\n";
}

/// The robot of config/robot_reach_avoid.yaml on a coarse grid with a disturbance w0 in both
/// coordinates (the adversary's minimum matters), horizon 6.
inline std::string robot_disturbance_yaml() {
  return "name: robot_small\n"
         "states: {lb: [-10, -10], ub: [10, 10], eta: [1, 1]}\n"
         "inputs: {lb: [-1, -1], ub: [1, 1], eta: [0.4, 0.4]}\n"
         "disturbances: {lb: [-1], ub: [1], eta: [0.5]}\n"
         "constants: {tau: 10.0}\n"
         "dynamics: [\"x0 + tau*u0*cos(u1) + w0\", \"x1 + tau*u0*sin(u1) + w0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.75, 0.75],\n"
         "        truncation: cutting_probability, cutting_probability: 1.0e-3}\n"
         "spec: {type: reach_avoid, horizon: 6, target: {lb: [5, 5], ub: [7, 7]}, avoid: {lb: [-2, -2], ub: [2, 2]}}\n";
}

/// Two coupled coordinates, x1 on 101 points: the factored sweep's first stage computes rows of
/// 101 entries (13 vectors of 8 on a SIMD device, the last one partial).
inline std::string long_rows_yaml() {
  return "name: long_rows\n"
         "states: {lb: [0, 0], ub: [4, 4], eta: [0.5, 0.04]}\n"
         "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
         "dynamics: [\"0.7*x0 + 0.2*x1 + 0.5*u0\", \"0.3*x0 + 0.6*x1 + 0.4*u0\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.2, 0.1]}\n"
         "spec: {type: safety, horizon: 4, safe: {lb: [0, 0], ub: [3.5, 3.5]}}\n";
}

/// Parses `root` and expects a ConfigError for `key` whose message contains `fragment`.
inline void expect_error(const YAML::Node& root, const std::string& key, const std::string& fragment) {
  try {
    config_from_yaml(root);
    ADD_FAILURE() << "no ConfigError; expected key " << key << " with '" << fragment << "'";
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), key) << error.what();
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos)
        << "message: " << error.what() << "\nexpected fragment: " << fragment;
  }
}

/// Runs `action` and returns the PolicyFileError message; fails the test when none is thrown.
template <typename Action>
std::string refusal(Action action) {
  try {
    action();
  } catch (const PolicyFileError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no PolicyFileError was thrown";
  return "";
}

/// Whether one of the report's notes contains `fragment`.
inline bool has_note(const SynthesisReport& report, const std::string& fragment) {
  return std::any_of(report.notes.begin(), report.notes.end(),
                     [&](const EngineNote& note) { return note.text.find(fragment) != std::string::npos; });
}

}  // namespace test_support
}  // namespace amytiss

// Dynamics: expression dynamics and the built-in models (shared C/OpenCL sources).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include "amytiss/config.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/model.hpp"

namespace amytiss {
namespace {

constexpr double kHandTolerance = 1e-12;      // hand values printed with 17 digits
constexpr double kAgreementTolerance = 1e-12;  // same formula written twice, rounding only

/// A configuration on [-1, 1]^n with the built-in `model_or_dynamics`, or with the YAML list of
/// expressions it holds when it starts with '['.
Config config_with(const std::string& model_or_dynamics, std::size_t states, std::size_t inputs,
                   const std::string& constants_yaml = "") {
  YAML::Node root;
  if (!constants_yaml.empty()) root["constants"] = YAML::Load(constants_yaml);
  root["name"] = "t";
  for (const char* key : {"lb", "ub", "eta"})
    for (std::size_t i = 0; i < states; ++i) root["states"][key].push_back(std::string(key) == "lb" ? -1.0 : 1.0);
  for (const char* key : {"lb", "ub", "eta"})
    for (std::size_t i = 0; i < inputs; ++i) root["inputs"][key].push_back(std::string(key) == "lb" ? -1.0 : 1.0);
  if (model_or_dynamics.find('[') == 0) {
    root["dynamics"] = YAML::Load(model_or_dynamics);
  } else {
    root["model"] = model_or_dynamics;
  }
  for (std::size_t i = 0; i < states; ++i) root["noise"]["covariance"].push_back(0.01);
  root["spec"]["type"] = "safety";
  root["spec"]["horizon"] = 1;
  return config_from_yaml(root);
}

std::vector<double> apply(const Dynamics& dynamics, const std::vector<double>& x, const std::vector<double>& u) {
  std::vector<double> post(dynamics.state_dims(), std::nan(""));
  dynamics.evaluate(x.data(), u.data(), nullptr, post.data());
  return post;
}

TEST(Models, BuiltinList) {
  const auto& models = builtin_models();
  ASSERT_EQ(models.size(), 3u);
  EXPECT_EQ(models[0].name, "bmw320i");
  EXPECT_EQ(models[0].state_dims, 7u);
  EXPECT_EQ(models[0].input_dims, 2u);
  EXPECT_EQ(models[1].name, "bmw320i_ks");
  EXPECT_EQ(models[1].state_dims, 5u);
  EXPECT_EQ(models[1].input_dims, 2u);
  EXPECT_EQ(models[2].name, "vehicle3d");
  EXPECT_EQ(models[2].state_dims, 3u);
}

TEST(Models, Vehicle3dHandValues) {
  const auto dynamics = make_dynamics(config_with("vehicle3d", 3, 2));
  EXPECT_EQ(dynamics->describe(), "built-in vehicle3d");
  // alpha = atan(tan(0.3)/2); x+ = x + 0.3*(2 cos(alpha+0.5)/cos(alpha), 2 sin(alpha+0.5)/cos(alpha), 2 tan(0.3)).
  const auto post = apply(*dynamics, {1, 2, 0.5}, {2, 0.3});
  EXPECT_NEAR(post[0], 1.4820584277105544, kHandTolerance);
  EXPECT_NEAR(post[1], 2.3690957526879135, kHandTolerance);
  EXPECT_NEAR(post[2], 0.6856017497657739, kHandTolerance);
}

TEST(Models, Vehicle3dEqualsExpressions) {
  const auto builtin = make_dynamics(config_with("vehicle3d", 3, 2));
  const auto expressions = make_dynamics(config_with(
      R"EXPR(["x0 + 0.3*u0*cos(atan(tan(u1)/2) + x2)/cos(atan(tan(u1)/2))",
          "x1 + 0.3*u0*sin(atan(tan(u1)/2) + x2)/cos(atan(tan(u1)/2))",
          "x2 + 0.3*u0*tan(u1)"])EXPR", 3, 2));
  std::mt19937 generator(7);
  std::uniform_real_distribution<double> position(-5, 5), heading(-3.4, 3.4), speed(-1, 4), steer(-0.4, 0.4);
  for (int sample = 0; sample < 200; ++sample) {
    const std::vector<double> x = {position(generator), position(generator), heading(generator)};
    const std::vector<double> u = {speed(generator), steer(generator)};
    const auto a = apply(*builtin, x, u), b = apply(*expressions, x, u);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], kAgreementTolerance);
  }
}

TEST(Models, Bmw320iKinematicBranch) {
  const auto dynamics = make_dynamics(config_with("bmw320i", 7, 2));
  // |x3| = 0.05 < 0.1: kinematic branch; inputs inside the CommonRoad limits.
  const auto post = apply(*dynamics, {1, 2, 0.1, 0.05, 0.3, 0.01, 0.0}, {0.2, 1.0});
  const double expected[7] = {1.0047766824456281, 2.0014776010333066, 0.12000000000000001, 0.15000000000000002,
                              0.30019452997806323, 0.014282265405780585, 0.0};
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(post[i], expected[i], kHandTolerance) << "x" << i;
}

TEST(Models, Bmw320iInputSaturation) {
  const auto dynamics = make_dynamics(config_with("bmw320i", 7, 2));
  // Steering velocity 0.9 is cut to 0.4 rad/s; acceleration 20 to 11.5 m/s^2 (below v_switch).
  auto post = apply(*dynamics, {0, 0, 0, 1, 0, 0, 0}, {0.9, 20});
  EXPECT_NEAR(post[2], 0.1 * 0.4, kHandTolerance);
  EXPECT_NEAR(post[3], 1 + 0.1 * 11.5, kHandTolerance);
  // At the steering limit 1.066, steering further is blocked; above v_switch = 7.319 the positive
  // acceleration limit is 11.5 * 7.319 / v.
  post = apply(*dynamics, {0, 0, 1.066, 10, 0, 0, 0}, {0.3, 20});
  EXPECT_NEAR(post[2], 1.066, kHandTolerance);
  EXPECT_NEAR(post[3], 10 + 0.1 * 11.5 * 7.319 / 10, kHandTolerance);
  // Braking is limited to -11.5.
  post = apply(*dynamics, {0, 0, 0, 10, 0, 0, 0}, {-0.3, -20});
  EXPECT_NEAR(post[2], -0.03, kHandTolerance);
  EXPECT_NEAR(post[3], 10 - 1.15, kHandTolerance);
}

// The single-track model written independently as expressions (CommonRoad ST, section 5.1 of
// Althoff's vehicle models), within the input limits so saturation does not act.
const char* const kBmwExpressions = R"EXPR([
  "x0 + 0.1*if(abs(x3) < 0.1, x3*cos(x4), x3*cos(x4 + x6))",
  "x1 + 0.1*if(abs(x3) < 0.1, x3*sin(x4), x3*sin(x4 + x6))",
  "x2 + 0.1*u0",
  "x3 + 0.1*u1",
  "x4 + 0.1*if(abs(x3) < 0.1, x3/lwb*tan(x2), x5)",
  "x5 + 0.1*if(abs(x3) < 0.1, u1/lwb*tan(x2) + x3/(lwb*cos(x2)^2)*u0, mu*m/(iz*(lr + lf))*(lf*csf*(g*lr - u1*h)*x2 + (lr*csr*(g*lf + u1*h) - lf*csf*(g*lr - u1*h))*x6 - (lf^2*csf*(g*lr - u1*h) + lr^2*csr*(g*lf + u1*h))*x5/x3))",
  "x6 + 0.1*if(abs(x3) < 0.1, 0, mu/(x3*(lr + lf))*(csf*(g*lr - u1*h)*x2 - (csr*(g*lf + u1*h) + csf*(g*lr - u1*h))*x6 + (csr*(g*lf + u1*h)*lr - csf*(g*lr - u1*h)*lf)*x5/x3) - x5)"
]
)EXPR";

TEST(Models, Bmw320iEqualsExpressions) {
  const auto builtin = make_dynamics(config_with("bmw320i", 7, 2));
  const auto expressions = make_dynamics(config_with(
      kBmwExpressions, 7, 2,
      "{lwb: 2.5789, m: 1093.3, mu: 1.0489, lf: 1.156, lr: 1.422, h: 0.6137, iz: 1791.6, csf: 20.89, csr: 20.89, g: 9.81}"));
  std::mt19937 generator(11);
  std::uniform_real_distribution<double> position(-10, 10), steering(-0.4, 0.4), velocity(-2, 2), yaw(-0.3, 0.3),
      yaw_rate(-0.4, 0.4), slip(-0.04, 0.04), steering_velocity(-0.39, 0.39), acceleration(-4, 4);
  int kinematic = 0;
  for (int sample = 0; sample < 500; ++sample) {
    const std::vector<double> x = {position(generator), position(generator), steering(generator), velocity(generator),
                                   yaw(generator),      yaw_rate(generator), slip(generator)};
    const std::vector<double> u = {steering_velocity(generator), acceleration(generator)};
    kinematic += std::fabs(x[3]) < 0.1;
    const auto a = apply(*builtin, x, u), b = apply(*expressions, x, u);
    for (int i = 0; i < 7; ++i)
      EXPECT_NEAR(a[i], b[i], kAgreementTolerance * std::max(1.0, std::fabs(b[i]))) << "x" << i << " v=" << x[3];
  }
  EXPECT_GT(kinematic, 0);  // both branches were exercised
}

TEST(Models, Bmw320iSwitchesAtTenCentimetresPerSecond) {
  const auto dynamics = make_dynamics(config_with("bmw320i", 7, 2));
  // With slip angle 0.02 the dynamic branch moves along heading x4 + x6, the kinematic one along x4.
  const auto below = apply(*dynamics, {0, 0, 0, 0.0999, 0, 0, 0.02}, {0, 0});
  const auto above = apply(*dynamics, {0, 0, 0, 0.1, 0, 0, 0.02}, {0, 0});
  EXPECT_NEAR(below[1], 0.0, kHandTolerance);
  EXPECT_NEAR(below[6], 0.02, kHandTolerance);  // kinematic: slip angle unchanged
  EXPECT_NEAR(above[1], 0.1 * 0.1 * std::sin(0.02), kHandTolerance);
  EXPECT_NE(above[6], 0.02);
}

TEST(Models, ExpressionDynamics) {
  const Config config = load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/robot_safety.yaml");
  const auto dynamics = make_dynamics(config);
  EXPECT_EQ(dynamics->state_dims(), 2u);
  EXPECT_EQ(dynamics->input_dims(), 2u);
  EXPECT_EQ(dynamics->disturbance_dims(), 1u);
  EXPECT_EQ(dynamics->describe(), "expressions (2)");
  const double x[2] = {1, 2}, u[2] = {0.5, 0.25}, w[1] = {-0.5};
  double post[2];
  dynamics->evaluate(x, u, w, post);
  EXPECT_NEAR(post[0], 1 + 10 * 0.5 * std::cos(0.25) - 0.5, kHandTolerance);
  EXPECT_NEAR(post[1], 2 + 10 * 0.5 * std::sin(0.25) - 0.5, kHandTolerance);
  const std::string source = dynamics->opencl_source();
  EXPECT_NE(source.find("void amytiss_dynamics(const double* x, const double* u, const double* w, double* post)"),
            std::string::npos);
  EXPECT_NE(source.find("post[1] = "), std::string::npos);
}

TEST(Models, MakeDynamicsErrors) {
  Config config = config_with("vehicle3d", 3, 2);
  config.model = "tesla";
  try {
    config.validate();
    FAIL();
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "model");
  }
  EXPECT_THROW(make_dynamics(config), std::logic_error);  // validate() is the gate
  config = config_with(R"(["x0", "x1"])", 2, 1);
  config.dynamics[1] = "x1 +";
  try {
    make_dynamics(config);
    FAIL();
  } catch (const ConfigError& error) {
    EXPECT_EQ(error.key(), "dynamics[1]");
    EXPECT_NE(std::string(error.what()).find("column 5"), std::string::npos) << error.what();
  }
}

// The OpenCL source of each model is also valid C: compile it with the system compiler and check
// that it computes what evaluate() does.
TEST(Models, OpenclSourceCompilesAsCAndAgrees) {
  struct Case {
    std::unique_ptr<Dynamics> dynamics;
    std::vector<double> x, u;
  };
  std::vector<Case> cases;
  cases.push_back({make_dynamics(config_with("bmw320i", 7, 2)), {1, 2, 0.1, 1.5, 0.3, 0.1, 0.01}, {0.2, 1.0}});
  cases.push_back({make_dynamics(config_with("bmw320i", 7, 2)), {1, 2, 0.1, 0.05, 0.3, 0.1, 0.01}, {0.2, 1.0}});
  cases.push_back({make_dynamics(config_with("vehicle3d", 3, 2)), {1, 2, 0.5}, {2, 0.3}});
  Config kinematic = config_with("bmw320i_ks", 5, 2);
  kinematic.integrator = IntegratorConfig{IntegrationMethod::Rk4, 3, 0.5};
  cases.push_back({make_dynamics(kinematic), {1, 2, 0.3, 1.2, 0.4}, {-0.3, 0.5}});
  Config oscillator = config_with(R"(["x1", "-x0 + u0"])", 2, 1);
  oscillator.integrator = IntegratorConfig{IntegrationMethod::Euler, 4, 0.25};
  cases.push_back({make_dynamics(oscillator), {1, 0.5}, {0.2}});
  cases.push_back({make_dynamics(load_config_file(std::string(AMYTISS_SOURCE_DIR) + "/config/room_temperature_5d.yaml")),
                   {19.5, 20, 20.5, 21, 19}, {0.4, 1}});
  const std::string dir = ::testing::TempDir();
  for (std::size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE(cases[c].dynamics->describe());
    // Named by process: test runs of several checkouts may share the temporary folder.
    const std::string stem = dir + "/amytiss_model_check_" + std::to_string(::getpid());
    const std::string source_path = stem + ".c", binary_path = stem;
    {
      std::ofstream source(source_path);
      source << "#include <math.h>\n#include <stdio.h>\n" << cases[c].dynamics->opencl_source()
             << "int main(void) {\n  const double x[] = {";
      for (double v : cases[c].x) source << v << ", ";
      source << "}, u[] = {";
      for (double v : cases[c].u) source << v << ", ";
      source << "}, w[1] = {0};\n  double post[" << cases[c].x.size() << "];\n  amytiss_dynamics(x, u, w, post);\n"
             << "  for (int i = 0; i < " << cases[c].x.size() << "; ++i) printf(\"%.17g\\n\", post[i]);\n  return 0;\n}\n";
    }
    if (std::system(("cc -std=c99 -Wall -Werror -Wno-unused-function -o " + binary_path + " " + source_path + " -lm")
                        .c_str()) != 0)
      GTEST_SKIP() << "no C compiler (cc), or the source does not compile: " << source_path;
    FILE* pipe = popen(binary_path.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    const auto expected = apply(*cases[c].dynamics, cases[c].x, cases[c].u);
    for (double value : expected) {
      double compiled = 0;
      ASSERT_EQ(std::fscanf(pipe, "%lf", &compiled), 1);
      EXPECT_NEAR(compiled, value, kAgreementTolerance * std::max(1.0, std::fabs(value)));
    }
    pclose(pipe);
  }
}

}  // namespace
}  // namespace amytiss

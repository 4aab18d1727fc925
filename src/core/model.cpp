#include "amytiss/model.hpp"

#include <math.h>

#include <stdexcept>

#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"
#include "embedded_sources.hpp"

namespace amytiss {
namespace builtin {
// The model sources are plain C shared with the OpenCL kernels; they use the global math functions.
#include "models/model_function.h"
#include "models/bmw320i.h"
#include "models/vehicle3d.h"
}  // namespace builtin

namespace {

class ExpressionDynamics : public Dynamics {
 public:
  ExpressionDynamics(std::vector<Expression> expressions, std::size_t input_dims, std::size_t disturbance_dims)
      : expressions_(std::move(expressions)), input_dims_(input_dims), disturbance_dims_(disturbance_dims) {}

  std::size_t state_dims() const override { return expressions_.size(); }
  std::size_t input_dims() const override { return input_dims_; }
  std::size_t disturbance_dims() const override { return disturbance_dims_; }

  void evaluate(const double* x, const double* u, const double* w, double* post) const override {
    for (std::size_t i = 0; i < expressions_.size(); ++i) post[i] = expressions_[i].evaluate(x, u, w);
  }

  std::string opencl_source() const override {
    std::string source =
        "void amytiss_dynamics(const double* x, const double* u, const double* w, double* post) {\n"
        "  (void)u;\n  (void)w;\n";
    for (std::size_t i = 0; i < expressions_.size(); ++i)
      source += "  post[" + std::to_string(i) + "] = " + expressions_[i].to_c() + ";\n";
    return source + "}\n";
  }

  std::string describe() const override { return "expressions (" + std::to_string(expressions_.size()) + ")"; }

 private:
  std::vector<Expression> expressions_;
  std::size_t input_dims_, disturbance_dims_;
};

using ModelFunction = void (*)(const double*, const double*, const double*, double*);

class BuiltinDynamics : public Dynamics {
 public:
  BuiltinDynamics(const BuiltinModelInfo& info, ModelFunction function) : info_(info), function_(function) {}

  std::size_t state_dims() const override { return info_.state_dims; }
  std::size_t input_dims() const override { return info_.input_dims; }
  std::size_t disturbance_dims() const override { return info_.disturbance_dims; }

  void evaluate(const double* x, const double* u, const double* w, double* post) const override {
    function_(x, u, w, post);
  }

  std::string opencl_source() const override {
    return std::string(detail::embedded_source("model_function.h")) + detail::embedded_source(info_.name + ".h") +
           "\nvoid amytiss_dynamics(const double* x, const double* u, const double* w, double* post) {\n"
           "  amytiss_model_" + info_.name + "(x, u, w, post);\n}\n";
  }

  std::string describe() const override { return "built-in " + info_.name; }

 private:
  BuiltinModelInfo info_;
  ModelFunction function_;
};

ModelFunction builtin_function(const std::string& name) {
  if (name == "bmw320i") return &builtin::amytiss_model_bmw320i;
  if (name == "vehicle3d") return &builtin::amytiss_model_vehicle3d;
  return nullptr;
}

}  // namespace

const std::vector<BuiltinModelInfo>& builtin_models() {
  static const std::vector<BuiltinModelInfo> models = {
      {"bmw320i", 7, 2, 0,
       "BMW 320i single-track model with tire slip, tau 0.1 s: x = (px, py, steering angle, velocity, yaw, "
       "yaw rate, slip angle), u = (steering velocity, acceleration)"},
      {"vehicle3d", 3, 2, 0,
       "3-d vehicle of Reissig et al. 2016, Euler tau 0.3 s: x = (px, py, heading), u = (speed, steering "
       "angle)"},
  };
  return models;
}

std::unique_ptr<Dynamics> make_dynamics(const Config& config) {
  const std::size_t n = config.states.lb.size();
  const std::size_t m = config.inputs ? config.inputs->lb.size() : 0;
  const std::size_t p = config.disturbances ? config.disturbances->lb.size() : 0;
  // The configuration passed Config::validate(); a violation is a bug of the caller.
  const auto require = [](bool invariant, const std::string& what) {
    if (!invariant) throw std::logic_error("make_dynamics: expected a validated configuration: " + what);
  };
  if (!config.model.empty()) {
    for (const auto& info : builtin_models()) {
      if (info.name != config.model) continue;
      require(info.state_dims == n && info.input_dims == m && info.disturbance_dims == p,
              "grids with the dimensions of model " + info.name);
      return std::make_unique<BuiltinDynamics>(info, builtin_function(info.name));
    }
    require(false, "a built-in model name, got '" + config.model + "'");
  }
  require(config.dynamics.size() == n, "one dynamics expression per state dimension");
  return std::make_unique<ExpressionDynamics>(parse_dynamics(config), m, p);
}

std::vector<Expression> parse_dynamics(const Config& config) {
  const std::size_t n = config.states.lb.size();
  const std::size_t m = config.inputs ? config.inputs->lb.size() : 0;
  const std::size_t p = config.disturbances ? config.disturbances->lb.size() : 0;
  std::vector<Expression> expressions;
  for (std::size_t i = 0; i < config.dynamics.size(); ++i) {
    try {
      expressions.push_back(Expression::parse(config.dynamics[i], config.constants, n, m, p));
    } catch (const ParseError& error) {
      throw ConfigError("dynamics[" + std::to_string(i) + "]",
                        std::string(error.what()) + " in \"" + expression_excerpt(config.dynamics[i]) + "\"");
    }
  }
  return expressions;
}

}  // namespace amytiss

#include "amytiss/model.hpp"

#include <math.h>

#include <algorithm>

#include "amytiss/errors.hpp"
#include "amytiss/expression.hpp"
#include "amytiss/format.hpp"
#include "common/embedded_sources.hpp"
#include "common/require.hpp"

namespace amytiss {
namespace builtin {
// The model sources are plain C shared with the OpenCL kernels; they use the global math functions.
#include "model/models/model_function.h"
#include "model/models/commonroad_vehicle2.h"
#include "model/models/bmw320i.h"
#include "model/models/bmw320i_ks.h"
#include "model/models/vehicle3d.h"
// The integrator calls the vector field through the object it is given (OpenCL: a plain function).
#define AMYTISS_INTEGRATOR_CAPACITY 32
#define AMYTISS_VECTOR_FIELD_CONTEXT const ::amytiss::VectorField *field,
#define AMYTISS_VECTOR_FIELD(x_, u_, w_, rate_) field->rate(x_, u_, w_, rate_)
#include "model/models/integrator.h"
static_assert(AMYTISS_INTEGRATOR_CAPACITY == kMaxIntegratorStates, "stage arrays hold every integrated state");
}  // namespace builtin

namespace {

std::vector<VariableUse> expression_uses(const std::vector<Expression>& expressions) {
  std::vector<VariableUse> uses;
  for (const Expression& expression : expressions) uses.push_back(expression.variables());
  return uses;
}

void evaluate_expressions(const std::vector<Expression>& expressions, const double* x, const double* u,
                          const double* w, double* out) {
  for (std::size_t i = 0; i < expressions.size(); ++i) out[i] = expressions[i].evaluate(x, u, w);
}

/// "void <function>(const double* x, const double* u, const double* w, double* <out>)" in OpenCL C.
std::string expressions_source(const std::vector<Expression>& expressions, const std::string& function,
                               const std::string& out) {
  std::string source = "void " + function + "(const double* x, const double* u, const double* w, double* " + out +
                       ") {\n  (void)u;\n  (void)w;\n";
  for (std::size_t i = 0; i < expressions.size(); ++i)
    source += "  " + out + "[" + std::to_string(i) + "] = " + expressions[i].to_c() + ";\n";
  return source + "}\n";
}

/// `dynamics` without an integrator: the expressions are the discrete map.
class ExpressionDynamics : public Dynamics {
 public:
  ExpressionDynamics(std::vector<Expression> expressions, std::size_t input_dims, std::size_t disturbance_dims)
      : expressions_(std::move(expressions)), input_dims_(input_dims), disturbance_dims_(disturbance_dims) {}

  std::size_t state_dims() const override { return expressions_.size(); }
  std::size_t input_dims() const override { return input_dims_; }
  std::size_t disturbance_dims() const override { return disturbance_dims_; }

  void evaluate(const double* x, const double* u, const double* w, double* post) const override {
    evaluate_expressions(expressions_, x, u, w, post);
  }

  std::string opencl_source() const override { return expressions_source(expressions_, "amytiss_dynamics", "post"); }

  std::string describe() const override { return "expressions (" + std::to_string(expressions_.size()) + ")"; }

  std::optional<std::vector<VariableUse>> dependencies() const override { return expression_uses(expressions_); }

 private:
  std::vector<Expression> expressions_;
  std::size_t input_dims_, disturbance_dims_;
};

/// `dynamics` with `integrator.tau`: the expressions are dx/dt.
class ExpressionField : public VectorField {
 public:
  ExpressionField(std::vector<Expression> expressions, std::size_t input_dims, std::size_t disturbance_dims)
      : expressions_(std::move(expressions)), input_dims_(input_dims), disturbance_dims_(disturbance_dims) {}

  std::size_t state_dims() const override { return expressions_.size(); }
  std::size_t input_dims() const override { return input_dims_; }
  std::size_t disturbance_dims() const override { return disturbance_dims_; }

  void rate(const double* x, const double* u, const double* w, double* rate) const override {
    evaluate_expressions(expressions_, x, u, w, rate);
  }

  std::string opencl_source() const override {
    return expressions_source(expressions_, "amytiss_vector_field", "rate");
  }

  std::string describe() const override { return "expressions dx/dt (" + std::to_string(expressions_.size()) + ")"; }

  std::optional<std::vector<VariableUse>> dependencies() const override { return expression_uses(expressions_); }

 private:
  std::vector<Expression> expressions_;
  std::size_t input_dims_, disturbance_dims_;
};

using RateFunction = void (*)(const double*, const double*, const double*, double*);

/// What model/model.cpp knows of a built-in model beyond BuiltinModelInfo: its C function, the model
/// sources its OpenCL text needs (in order), and which components each rate reads when stated.
struct BuiltinSource {
  const char* name;
  RateFunction rate;
  std::vector<const char*> headers;
  std::optional<std::vector<VariableUse>> dependencies;
};

const std::vector<BuiltinSource>& builtin_sources() {
  static const std::vector<BuiltinSource> sources = {
      {"bmw320i", &builtin::amytiss_rate_bmw320i, {"commonroad_vehicle2.h", "bmw320i.h"}, std::nullopt},
      {"bmw320i_ks",
       &builtin::amytiss_rate_bmw320i_ks,
       {"commonroad_vehicle2.h", "bmw320i_ks.h"},
       std::vector<VariableUse>{{{3, 4}, {}, {}}, {{3, 4}, {}, {}}, {{2}, {0}, {}}, {{3}, {1}, {}}, {{2, 3}, {}, {}}}},
      {"vehicle3d",
       &builtin::amytiss_rate_vehicle3d,
       {"vehicle3d.h"},
       std::vector<VariableUse>{{{2}, {0, 1}, {}}, {{2}, {0, 1}, {}}, {{}, {0, 1}, {}}}},
  };
  return sources;
}

class BuiltinField : public VectorField {
 public:
  BuiltinField(const BuiltinModelInfo& info, const BuiltinSource& source) : info_(info), source_(source) {}

  std::size_t state_dims() const override { return info_.state_dims; }
  std::size_t input_dims() const override { return info_.input_dims; }
  std::size_t disturbance_dims() const override { return info_.disturbance_dims; }

  void rate(const double* x, const double* u, const double* w, double* rate) const override {
    source_.rate(x, u, w, rate);
  }

  std::string opencl_source() const override {
    std::string source = detail::embedded_source("model_function.h");
    for (const char* header : source_.headers) source += detail::embedded_source(header);
    return source +
           "\nvoid amytiss_vector_field(const double* x, const double* u, const double* w, double* rate) {\n"
           "  amytiss_rate_" + info_.name + "(x, u, w, rate);\n}\n";
  }

  std::string describe() const override { return "built-in " + info_.name; }

  std::optional<std::vector<VariableUse>> dependencies() const override { return source_.dependencies; }

 private:
  BuiltinModelInfo info_;
  const BuiltinSource& source_;
};

/// x(k+1) = the integrator's step of length tau applied to a vector field (models/integrator.h).
class IntegratedDynamics : public Dynamics {
 public:
  IntegratedDynamics(std::unique_ptr<VectorField> field, const IntegratorConfig& integrator, double tau)
      : field_(std::move(field)), integrator_(integrator), tau_(tau) {}

  std::size_t state_dims() const override { return field_->state_dims(); }
  std::size_t input_dims() const override { return field_->input_dims(); }
  std::size_t disturbance_dims() const override { return field_->disturbance_dims(); }

  void evaluate(const double* x, const double* u, const double* w, double* post) const override {
    builtin::amytiss_integrate(field_.get(), x, u, w, static_cast<int>(state_dims()), tau_, method_code(),
                               static_cast<int>(integrator_.substeps), post);
  }

  std::string opencl_source() const override {
    return field_->opencl_source() + detail::embedded_source("model_function.h") +
           "\n#define AMYTISS_INTEGRATOR_CAPACITY " + std::to_string(state_dims()) +
           "\n#define AMYTISS_VECTOR_FIELD_CONTEXT\n"
           "#define AMYTISS_VECTOR_FIELD(x_, u_, w_, rate_) amytiss_vector_field(x_, u_, w_, rate_)\n" +
           detail::embedded_source("integrator.h") +
           "\nvoid amytiss_dynamics(const double* x, const double* u, const double* w, double* post) {\n"
           "  amytiss_integrate(x, u, w, " + std::to_string(state_dims()) + ", " + c_double_literal(tau_) + ", " +
           std::to_string(method_code()) + ", " + std::to_string(integrator_.substeps) + ", post);\n}\n";
  }

  std::string describe() const override {
    if (integrator_.is_default()) return field_->describe();
    return field_->describe() + ", " + to_string(integrator_.method) + " x" + std::to_string(integrator_.substeps) +
           " per step of " + format_number(tau_) + " s";
  }

  std::optional<std::vector<VariableUse>> dependencies() const override {
    const auto uses = field_->dependencies();
    if (!uses) return std::nullopt;
    return integrated_dependencies(*uses, integrator_);
  }

 private:
  int method_code() const {
    return integrator_.method == IntegrationMethod::Rk4 ? AMYTISS_INTEGRATOR_RK4 : AMYTISS_INTEGRATOR_EULER;
  }

  std::unique_ptr<VectorField> field_;
  IntegratorConfig integrator_;
  double tau_;
};

std::vector<std::size_t> merged(std::vector<std::size_t> a, const std::vector<std::size_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  return a;
}

// The configuration passed Config::validate(); a violation is a bug of the caller.
constexpr detail::Require require{"make_dynamics: expected a validated configuration: "};

}  // namespace

std::vector<VariableUse> integrated_dependencies(const std::vector<VariableUse>& field,
                                                 const IntegratorConfig& integrator) {
  const bool one_stage = integrator.method == IntegrationMethod::Euler && integrator.substeps == 1;
  std::vector<VariableUse> uses(field.size());
  for (std::size_t i = 0; i < field.size(); ++i) {
    // One Euler stage: post_i = x_i + h g_i(x). Every later stage evaluates g_i at a state whose
    // coordinates j were moved by h g_j, so coordinate i reads what those g_j read, transitively.
    std::vector<std::size_t> reached{i};
    for (std::size_t next = 0; next < reached.size(); ++next) {
      const VariableUse& rate = field[reached[next]];
      uses[i].inputs = merged(uses[i].inputs, rate.inputs);
      uses[i].disturbances = merged(uses[i].disturbances, rate.disturbances);
      for (std::size_t k : rate.states)
        if (std::find(reached.begin(), reached.end(), k) == reached.end()) reached.push_back(k);
      if (one_stage) break;
    }
    uses[i].states = merged(reached, {});
  }
  return uses;
}

const std::vector<BuiltinModelInfo>& builtin_models() {
  // Body of CommonRoad vehicle 2, overhangs taken equal: (4.508 - 2.578) / 2 = 0.965 m.
  constexpr double kLength = 4.508, kWidth = 1.610, kRearOverhang = 0.965;
  static const std::vector<BuiltinModelInfo> models = {
      {"bmw320i", 7, 2, 0,
       "BMW 320i single-track model with tire slip, Euler tau 0.1 s by default: x = (px, py of the centre of "
       "gravity, steering angle, velocity, yaw, yaw rate, slip angle), u = (steering velocity, acceleration)",
       BMW320I_TAU, VehicleOutline{0, 1, 4, kLength, kWidth, kRearOverhang + BMW320I_L_R}},
      {"bmw320i_ks", 5, 2, 0,
       "BMW 320i kinematic single-track model, Euler tau 0.1 s by default: x = (px, py of the rear axle, "
       "steering angle, velocity, yaw), u = (steering velocity, acceleration)",
       BMW320I_KS_TAU, VehicleOutline{0, 1, 4, kLength, kWidth, kRearOverhang}},
      {"vehicle3d", 3, 2, 0,
       "3-d vehicle of Reissig et al. 2016, Euler tau 0.3 s by default: x = (px, py, heading), u = (speed, "
       "steering angle)",
       VEHICLE3D_TAU, std::nullopt},
  };
  return models;
}

std::unique_ptr<VectorField> make_vector_field(const Config& config) {
  const std::size_t n = config.states.lb.size();
  const std::size_t m = config.inputs ? config.inputs->lb.size() : 0;
  const std::size_t p = config.disturbances ? config.disturbances->lb.size() : 0;
  if (config.model.empty()) {
    if (!config.integrator.tau) return nullptr;
    require(config.dynamics.size() == n, "one dynamics expression per state dimension");
    return std::make_unique<ExpressionField>(parse_dynamics(config), m, p);
  }
  for (const auto& info : builtin_models()) {
    if (info.name != config.model) continue;
    require(info.state_dims == n && info.input_dims == m && info.disturbance_dims == p,
            "grids with the dimensions of model " + info.name);
    for (const auto& source : builtin_sources())
      if (source.name == info.name) return std::make_unique<BuiltinField>(info, source);
  }
  require(false, "a built-in model name, got '" + config.model + "'");
  return nullptr;
}

std::unique_ptr<Dynamics> make_dynamics(const Config& config) {
  require(config.states.lb.size() <= kMaxIntegratorStates || (config.model.empty() && !config.integrator.tau),
          "at most " + std::to_string(kMaxIntegratorStates) + " integrated states");
  if (auto field = make_vector_field(config)) {
    double tau = config.integrator.tau.value_or(0.0);
    for (const auto& info : builtin_models())
      if (info.name == config.model && !config.integrator.tau) tau = info.tau;
    return std::make_unique<IntegratedDynamics>(std::move(field), config.integrator, tau);
  }
  require(config.integrator.is_default(), "an integrator.tau for integrated expressions");
  require(config.dynamics.size() == config.states.lb.size(), "one dynamics expression per state dimension");
  return std::make_unique<ExpressionDynamics>(parse_dynamics(config), config.inputs ? config.inputs->lb.size() : 0,
                                              config.disturbances ? config.disturbances->lb.size() : 0);
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

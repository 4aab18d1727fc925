// The `dynamics` expressions as a model: evaluated on the host, and written out as OpenCL C.
#include "model/expression_models.hpp"

#include <string>

#include "amytiss/errors.hpp"

namespace amytiss {
namespace detail {
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

}  // namespace

std::unique_ptr<Dynamics> make_expression_dynamics(std::vector<Expression> expressions, std::size_t input_dims,
                                                   std::size_t disturbance_dims) {
  return std::make_unique<ExpressionDynamics>(std::move(expressions), input_dims, disturbance_dims);
}

std::unique_ptr<VectorField> make_expression_field(std::vector<Expression> expressions, std::size_t input_dims,
                                                   std::size_t disturbance_dims) {
  return std::make_unique<ExpressionField>(std::move(expressions), input_dims, disturbance_dims);
}

}  // namespace detail

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

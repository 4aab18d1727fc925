#pragma once
// The system map f(x, u, w) (the mean of the next state before noise).
#include <memory>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/expression.hpp"

namespace amytiss {

class Dynamics {
 public:
  virtual ~Dynamics() = default;
  virtual std::size_t state_dims() const = 0;
  virtual std::size_t input_dims() const = 0;
  virtual std::size_t disturbance_dims() const = 0;
  /// post[i] = f_i(x, u, w), arrays of the dims above (u, w may be null when their dims are 0).
  virtual void evaluate(const double* x, const double* u, const double* w, double* post) const = 0;
  /// OpenCL C source defining
  ///   void amytiss_dynamics(const double* x, const double* u, const double* w, double* post)
  /// (private-memory arrays), the same function as evaluate().
  virtual std::string opencl_source() const = 0;
  /// A short description for logs, e.g. "expressions (2)" or "built-in bmw320i".
  virtual std::string describe() const = 0;
};

/// Builds the dynamics of a validated configuration (Config::validate()): expressions, or the
/// built-in `model`. A configuration validate() would refuse is a caller bug: std::logic_error
/// (ConfigError "dynamics[i]" from parse_dynamics() for an expression that does not parse).
std::unique_ptr<Dynamics> make_dynamics(const Config& config);
/// The dynamics expressions of `config` parsed, one per state dimension: the one place they are
/// parsed (Config::validate() and make_dynamics() both call it). Throws ConfigError naming
/// dynamics[i] with the parser's message.
std::vector<Expression> parse_dynamics(const Config& config);

/// Names of the built-in models ("bmw320i", "vehicle3d") and their dimensions.
struct BuiltinModelInfo {
  std::string name;
  std::size_t state_dims, input_dims, disturbance_dims;
  std::string description;
};
const std::vector<BuiltinModelInfo>& builtin_models();

}  // namespace amytiss

#pragma once
// The system map f(x, u, w) (the mean of the next state before noise), and the continuous-time
// vector fields that an integrator turns into such a map (docs/configuration.md, `integrator`).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/expression.hpp"

namespace amytiss {

/// Limits of the integrator (checked by Config::validate()).
constexpr std::size_t kMaxIntegratorStates = 32;
constexpr unsigned kMaxIntegratorSubsteps = 100000;

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
  /// For each post coordinate i, the components f_i reads (f_i depends on no other), when known;
  /// nullopt when the model does not say (every coordinate may read every component).
  virtual std::optional<std::vector<VariableUse>> dependencies() const { return std::nullopt; }
};

/// A continuous-time model dx/dt = g(x, u, w): what an integrator steps (built-in models, and
/// `dynamics` expressions when the configuration gives `integrator.tau`).
class VectorField {
 public:
  virtual ~VectorField() = default;
  virtual std::size_t state_dims() const = 0;
  virtual std::size_t input_dims() const = 0;
  virtual std::size_t disturbance_dims() const = 0;
  /// rate[i] = g_i(x, u, w) in state units per second.
  virtual void rate(const double* x, const double* u, const double* w, double* rate) const = 0;
  /// OpenCL C source defining
  ///   void amytiss_vector_field(const double* x, const double* u, const double* w, double* rate)
  /// and everything it needs: the same function as rate().
  virtual std::string opencl_source() const = 0;
  virtual std::string describe() const = 0;
  /// For each rate coordinate i, the components g_i reads, when known (see Dynamics).
  virtual std::optional<std::vector<VariableUse>> dependencies() const { return std::nullopt; }
};

/// Builds the dynamics of a validated configuration (Config::validate()): expressions, or the
/// built-in `model`, stepped by the configuration's `integrator`. A configuration validate() would
/// refuse is a caller bug: std::logic_error (ConfigError "dynamics[i]" from parse_dynamics() for an
/// expression that does not parse).
std::unique_ptr<Dynamics> make_dynamics(const Config& config);
/// The continuous-time vector field of a validated configuration that has one: a built-in model,
/// or expressions with `integrator.tau`; nullptr for expressions that are the discrete map.
std::unique_ptr<VectorField> make_vector_field(const Config& config);
/// The dynamics expressions of `config` parsed, one per state dimension: the one place they are
/// parsed (Config::validate() and make_dynamics() both call it). Throws ConfigError naming
/// dynamics[i] with the parser's message.
std::vector<Expression> parse_dynamics(const Config& config);

/// The components each coordinate of the integrated map reads, from the vector field's
/// dependencies: one Euler step reads x_i and what g_i reads; several sub-steps or RK4 stages
/// read, transitively, what the coordinates g_i reads read (the closure).
std::vector<VariableUse> integrated_dependencies(const std::vector<VariableUse>& field, const IntegratorConfig& integrator);

/// A car's body as a rectangle, for pictures and markers: the state coordinates of the reference
/// point and the heading, and where the body lies around the reference point.
struct VehicleOutline {
  std::size_t x_index, y_index, yaw_index;  ///< state coordinates: position x, y [m], yaw [rad]
  double length, width;                     ///< body length and width [m]
  double rear_to_reference;                 ///< rear bumper to the reference point along the heading [m]
};

/// The built-in models (docs/configuration.md, `model`): their dimensions and own time step.
struct BuiltinModelInfo {
  std::string name;
  std::size_t state_dims, input_dims, disturbance_dims;
  std::string description;
  double tau;                             ///< the model's own time step in seconds (one Euler step by default)
  std::optional<VehicleOutline> outline;  ///< the vehicle's body, for models of a car
};
const std::vector<BuiltinModelInfo>& builtin_models();

}  // namespace amytiss

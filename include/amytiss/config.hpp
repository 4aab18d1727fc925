#pragma once
// The one configuration of a synthesis problem (docs/configuration.md). The same schema is read from a
// YAML file (CLI) and from ROS parameters (the ROS layer converts its XmlRpc tree to YAML::Node).
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace amytiss {

/// An axis-aligned box {lb, ub}; bounds in the units of the space it lives in.
struct Box {
  std::vector<double> lb;
  std::vector<double> ub;
};

/// A set of the specification: a union of axis-aligned boxes, given as one box {lb, ub} or a list
/// of boxes [{lb, ub}, {lb, ub}] (docs/configuration.md). A point belongs to it when it lies in one
/// of its boxes. A list of one box is the same set as that box, and prints as the box.
struct Region {
  std::vector<Box> boxes;  ///< at least one after validate(); units of the state space
  Region() = default;
  Region(Box box) : boxes{std::move(box)} {}  // NOLINT(google-explicit-constructor): a box is a region
  explicit Region(std::vector<Box> list) : boxes(std::move(list)) {}
};

/// A rectilinear grid: per dimension either uniform, points lb + k*eta, k = 0..n-1,
/// n = floor((ub-lb)/eta + 0.5) + 1, cell k = [lb + (k - 1/2)*eta, lb + (k + 1/2)*eta]; or given
/// by its cell faces (states only), cell k = [faces[k], faces[k+1]] with its midpoint as point.
struct GridSpec {
  std::vector<double> lb;
  std::vector<double> ub;
  std::vector<double> eta;  ///< spacing per dimension, > 0
  /// Cell faces per dimension (state units): empty when every dimension is uniform, else one entry
  /// per dimension, empty for a uniform one or n + 1 strictly increasing faces. A dimension with
  /// faces holds NaN (`null` in the file) in lb, ub and eta.
  std::vector<std::vector<double>> faces = {};
  bool has_faces(std::size_t dim) const { return dim < faces.size() && !faces[dim].empty(); }
};

enum class NoiseType { Additive, Multiplicative };
enum class Distribution { Normal, Uniform, Exponential, Beta, Custom };
enum class Truncation { None, FixedRegion, CuttingProbability };

struct NoiseConfig {
  NoiseType type = NoiseType::Additive;
  Distribution distribution = Distribution::Normal;
  /// normal: covariance, either n values (diagonal) or n*n values (full, row-major, symmetric
  /// positive definite). Units: state units squared.
  std::vector<double> covariance;
  /// uniform: half-width of the support per dimension (noise uniform on [-h, h]).
  std::vector<double> half_width;
  /// exponential: noise_i = shift_i + Exp(rate_i); rate in 1/state units (> 0), shift in state
  /// units (empty: 0).
  std::vector<double> rate;
  std::vector<double> shift;
  /// beta: noise_i = support.lb_i + (support.ub_i - support.lb_i) * Beta(alpha_i, beta_i), alpha,
  /// beta > 0 (dimensionless).
  std::vector<double> alpha;
  std::vector<double> beta;
  /// custom: the density of noise_i as an expression of the variable z (state units), one per
  /// dimension, in the whitelisted expression grammar; it must be >= 0 and integrate to 1 over
  /// `support`.
  std::vector<std::string> density;
  /// beta and custom: the interval [lb_i, ub_i] the noise lives in (state units, lb < ub).
  std::optional<Box> support;
  Truncation truncation = Truncation::None;  ///< default: nothing cut (exact)
  /// cutting_probability: total probability mass that may be cut per transition, in (0, 1).
  /// Absent: kDefaultCuttingProbability; it may only be given with truncation cutting_probability.
  std::optional<double> cutting_probability;
  static constexpr double kDefaultCuttingProbability = 1e-3;
  double cutting_probability_or_default() const {
    return cutting_probability.value_or(kDefaultCuttingProbability);
  }
  /// fixed_region: half-widths of the kept box around the post mean, per dimension (state units).
  std::vector<double> fixed_region;
};

/// How one time step of a continuous-time model is integrated (docs/configuration.md, `integrator`).
enum class IntegrationMethod { Euler, Rk4 };

struct IntegratorConfig {
  IntegrationMethod method = IntegrationMethod::Euler;  ///< explicit Euler or classical Runge-Kutta 4
  unsigned substeps = 1;  ///< equal sub-steps of length tau/substeps per time step, >= 1
  /// Length of one time step in seconds, > 0. Absent: a built-in model's own step; for `dynamics`
  /// expressions, absent means the expressions are the discrete map x(k+1) itself (no integration).
  std::optional<double> tau;
  /// The default: one Euler step of the model's own length (expressions: the discrete map).
  bool is_default() const { return method == IntegrationMethod::Euler && substeps == 1 && !tau; }
};

enum class SpecType { Safety, Reachability, ReachAvoid };

/// The car's body for `spec.obstacles` (docs/configuration.md): which state components are the
/// reference point's position and heading, and the body, a rectangle in the car's frame.
struct Footprint {
  std::vector<unsigned> pose;  ///< [ix, iy, iyaw]: state indices of x (m), y (m), heading (rad)
  double length = 0.0;         ///< m along the heading, > rear_overhang
  double width = 0.0;          ///< m across the heading, centred on the heading line, > 0
  double rear_overhang = 0.0;  ///< m the body reaches behind the reference point, >= 0
};

/// What the values guarantee (docs/semantics.md): `abstraction`, exact values of the finite MDP built
/// from the cells' points; `system`, a lower and an upper bound of the probability for the
/// continuous system from every state of a cell, through the interval MDP of the cells.
enum class Guarantee { Abstraction, System };

struct SpecConfig {
  SpecType type = SpecType::Safety;
  unsigned horizon = 0;       ///< T_d, number of steps, >= 1 (0 when unbounded)
  /// `horizon: infinite`: the unbounded specification, solved by interval iteration until the
  /// upper and the lower bound differ by at most `tolerance` everywhere; the policy is stationary.
  bool unbounded = false;
  /// Unbounded only: in (0, 1). Absent: kDefaultTolerance; it may only be given with `horizon: infinite`.
  std::optional<double> tolerance;
  static constexpr double kDefaultTolerance = 1e-6;
  double tolerance_or_default() const { return tolerance.value_or(kDefaultTolerance); }
  std::optional<Region> safe;    ///< safety; absent: the whole grid
  std::optional<Region> target;  ///< reachability, reach_avoid
  std::optional<Region> avoid;   ///< reach_avoid (absent: empty)
  /// Safety and reach_avoid, with `footprint`: 2-d boxes {lb: [x, y], ub: [x, y]} in the world
  /// frame (m); a cell whose body may touch one of them is avoided (docs/semantics.md).
  std::optional<Region> obstacles;
  std::optional<Footprint> footprint;  ///< given exactly when `obstacles` is
};

/// `refine` (docs/refinement.md): rounds of continuous-system bounds, each on a grid whose cells
/// are halved where the gap at the `at` states comes from, until the gap is reached or a budget
/// ends. Guarantee system only.
struct RefineConfig {
  /// State points (state units, one value per state dimension) whose gap upper - lower at step 0
  /// decides; empty: the mean gap over the free cells.
  std::vector<std::vector<double>> at;
  double gap = 0.05;             ///< stop when the gap is at most this, in (0, 1)
  /// Most state cells a round's grid may have; 0: kDefaultStatesFactor times the first round's.
  std::uint64_t max_states = 0;
  unsigned max_rounds = 6;       ///< most rounds, the first (unrefined) one included, >= 1
  double max_seconds = 600;      ///< wall seconds all rounds together may take (s), > 0
  static constexpr std::uint64_t kDefaultStatesFactor = 16;
};

enum class DeviceKind { Auto, Cpu, Gpu, Reference };
enum class TransitionStorage { Auto, Stored, OnTheFly };
/// How the OpenCL engine computes the expected next values (docs/engine.md, "Two sweeps").
enum class SweepChoice { Auto, Dense, Factored };

/// How the continuous-system bounds (guarantee: system) compute each row's robust expectation
/// (docs/engine.md, "The bounds' methods"). auto: whole tables where they pay, else variable
/// elimination where it has a plan of one slice, else row by row; the others force that method.
/// All product methods give the same bounds within their outward rounding; joint gives the looser
/// bounds of the joint interval MDP (the oracle's set).
enum class BoundsMethod { Auto, WholeTables, Elimination, Rows, Joint };

struct ComputeConfig {
  DeviceKind device = DeviceKind::Auto;
  TransitionStorage transitions = TransitionStorage::Auto;
  /// auto: the factored sweep where the dynamics allow it and it saves at least half the
  /// multiply-adds, else dense; dense / factored: that one (factored that cannot run: error).
  SweepChoice sweep = SweepChoice::Auto;
  /// guarantee: system only: the bounds' method (auto unless a test or a benchmark forces one).
  BoundsMethod bounds_method = BoundsMethod::Auto;
  /// Optional OpenCL platform/device selection: a 0-based index ("1") or a case-insensitive
  /// substring of the platform or device name ("nvidia"). Empty: any.
  std::string platform;
  std::string device_name;
  /// Fraction of the device's reported global memory the engine may use, in (0, 1].
  double memory_fraction = 0.5;
  /// Several devices working on one synthesis (docs/scale_out.md): empty, the one device above;
  /// ["all"], every OpenCL device with double precision; else a list of DeviceSelector texts
  /// ("gpu:0", "gpu:1", "cpu:0", "0.1", "cpu:0/1"). platform / device_name / device then do not apply.
  std::vector<std::string> devices;
};

/// One entry of compute.devices: "gpu:N" / "cpu:N" is the N-th (0-based) GPU / CPU device with
/// double precision; "P.D" is device D of platform P as `amytiss_synth --list-devices` numbers
/// them. A suffix "/C" splits that device into sub-devices of C compute units each
/// (clCreateSubDevices, equally), each of which works as a device of its own.
struct DeviceSelector {
  enum class Kind { Gpu, Cpu, Index };
  Kind kind = Kind::Gpu;
  std::size_t platform = 0;       ///< Index only
  std::size_t index = 0;          ///< among the devices of that kind (Gpu, Cpu) or of the platform
  unsigned units_per_part = 0;    ///< 0: the whole device
};
/// The selector a compute.devices entry names, or nullopt when the text is not one.
std::optional<DeviceSelector> parse_device_selector(const std::string& text);

/// How the policy file stores the value arrays (docs/policy_file.md): `exact`, float64 as
/// computed; `float32_lower`, float32 rounded outward (lower bounds down, upper bounds up: each
/// stays a bound) at half the size.
enum class ValueStorage { Exact, Float32Lower };

/// How results are written; like `compute`, not part of the configuration hash (the same policy,
/// stored differently).
struct OutputConfig {
  ValueStorage values = ValueStorage::Exact;
};

struct Config {
  std::string name;
  GridSpec states;
  /// states.fit_sets: under guarantee system, insert a face at every face of the target, avoid,
  /// safe and obstacle boxes inside the grid's range (fitted_states(), grid_rules.hpp), so that no
  /// cell straddles a set's boundary. Refused under guarantee abstraction. Default false, true
  /// with `refine`.
  bool fit_sets = false;
  std::optional<GridSpec> inputs;        ///< absent: autonomous system (one empty input)
  std::optional<GridSpec> disturbances;  ///< absent: no adversary
  std::map<std::string, double> constants;
  std::vector<std::string> dynamics;     ///< one expression per state dimension, or empty with model
  std::string model;                     ///< built-in model name ("bmw320i", "bmw320i_ks", "vehicle3d"), or empty
  /// Integration of one time step. Default: built-in models take one Euler step of their own length,
  /// expressions are the discrete map; with a tau, expressions are the vector field dx/dt.
  IntegratorConfig integrator;
  NoiseConfig noise;
  SpecConfig spec;
  Guarantee guarantee = Guarantee::Abstraction;
  /// Gap-guided refinement of the state grid (guarantee system); absent: one synthesis on the
  /// grid as given.
  std::optional<RefineConfig> refine;
  ComputeConfig compute;
  OutputConfig output;

  /// The only place that judges user input (docs/configuration.md, "Checks"). Throws
  /// ConfigError for the first problem found: dimensions that disagree,
  /// eta <= 0, lb > ub, covariance not symmetric positive definite, expression that does not
  /// parse (with column), unknown model, set outside the grid, horizon 0, grid too large.
  void validate() const;
};

/// Values given beside a configuration that replace its `compute` keys: the CLI's --device,
/// --transitions, --sweep, --platform and --devices, the ROS synthesizer's ~device. An empty
/// text (list) keeps the configuration's value.
struct ComputeOverrides {
  /// How errors name an override: key_prefix + key, e.g. "--" + "device" for the CLI's option;
  /// the default names the configuration key ("compute.device").
  std::string key_prefix = "compute.";
  std::string device;       ///< auto | cpu | gpu | reference
  std::string transitions;  ///< auto | stored | on_the_fly
  std::string sweep;        ///< auto | dense | factored
  std::string bounds_method;  ///< auto | whole_tables | elimination | rows | joint
  std::string platform;     ///< as compute.platform
  std::vector<std::string> devices;  ///< as compute.devices
  /// abstraction | system: the top-level key `guarantee` (errors name key_prefix + "guarantee",
  /// or "guarantee" with the default prefix).
  std::string guarantee;
  /// Replaces the configuration's refine section (the CLI's --refine); where the configuration
  /// had none, states.fit_sets turns on, refine's default. Judged by validate() as `refine`.
  std::optional<RefineConfig> refine;
};

/// Replaces the compute keys (the guarantee, the refine section) the overrides give. The configuration is read
/// but not yet validated: the caller validates after (config_from_yaml and load_config_file do).
/// Throws ConfigError (key_prefix + key) for a device, transitions, sweep or guarantee text that
/// names no value.
void apply_overrides(Config& config, const ComputeOverrides& overrides);

/// Reads a YAML tree of the schema without judging the values: throws ConfigError naming the key
/// only on a missing key, a wrong type (a text for a number, a fraction or a negative number for
/// a count), an unknown enum value, an unknown key or a key given twice (naming both lines).
/// Meaning is judged by Config::validate().
Config read_config(const YAML::Node& root);
/// The one gate for user input: read_config, then apply_overrides, then Config::validate() once.
Config config_from_yaml(const YAML::Node& root, const ComputeOverrides& overrides = {});
/// The largest configuration file load_config_file reads: 16 MiB (the shipped examples are a few
/// KiB).
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t(16) << 20;
/// config_from_yaml of a YAML file (ConfigError with key "<file>" when it cannot be read, is a
/// directory, is larger than kMaxConfigFileBytes, or is not YAML).
Config load_config_file(const std::string& path, const ComputeOverrides& overrides = {});
/// A configuration this program stored beside its result (a policy file's configuration text,
/// to_yaml()), read without judging it again: it was validated before the result was computed,
/// and the file's config hash ties the two. Cheap (no grid, expression or density checks): for
/// consumers that need the name, the spec boxes or the model of a policy. Throws ConfigError
/// (key "config_yaml") for text that is not YAML or not of the schema.
Config read_stored_config(const std::string& yaml_text);
/// Canonical YAML text of the configuration: all keys, fixed order, full precision. Parsing it
/// again gives an equal Config.
std::string to_yaml(const Config& config);
/// Hash of the parts that determine the result (everything but `compute` and `output`), as 16 hex
/// digits.
std::string config_hash(const Config& config);

/// Names used in messages and files: "safety", "reach_avoid", "normal", "auto", ...
std::string to_string(SpecType);
std::string to_string(DeviceKind);
std::string to_string(TransitionStorage);
std::string to_string(SweepChoice);
std::string to_string(BoundsMethod);
std::string to_string(NoiseType);
std::string to_string(Distribution);
std::string to_string(Truncation);
std::string to_string(IntegrationMethod);
std::string to_string(Guarantee);
std::string to_string(ValueStorage);

}  // namespace amytiss

#include "opencl/sweep_choice.hpp"

#include <string>

#include "amytiss/errors.hpp"

namespace amytiss::detail {
namespace {

// The factored sweep runs where it does at most this share of the dense sweep's multiply-adds:
// its stage tensors cost memory traffic and index arithmetic that the dense records do not.
constexpr double kFactoredShareLimit = 0.5;

void note(std::vector<EngineNote>& notes, const std::string& text) {
  notes.push_back({NoteSeverity::Info, NoteKind::Sweep, text});
}

}  // namespace

void check_opencl_supported(const Abstraction& a) {
  if (!a.noise->separable())
    throw ConfigError("noise.covariance",
                      "a full (non-diagonal) covariance is supported by device: reference only; "
                      "use a diagonal covariance (n values, example: covariance: [0.75, 0.75]) or "
                      "compute.device: reference");
  if (a.states.size() >= (std::size_t(1) << 32))
    throw ConfigError("states", "the OpenCL engine supports fewer than 2^32 state cells (got " +
                                    std::to_string(a.states.size()) + ")");
}

// The dense sweep's padded value array is indexed with 32 bits.
void check_dense_supported(const Layout& layout) {
  if (layout.padded_size >= (std::size_t(1) << 32))
    throw ConfigError("states", "the dense sweep supports fewer than 2^32 padded value cells (got " +
                                    std::to_string(layout.padded_size) + "); narrow the noise window "
                                    "(noise.truncation) or use dynamics expressions, whose factored sweep "
                                    "has no padding");
}

std::optional<FactoredPlan> choose_sweep(const Abstraction& a, const DeviceInfo& device, const ComputeConfig& compute,
                                         std::vector<EngineNote>& notes) {
  const SweepChoice decomposition = compute.sweep;
  // The dense sweep computes normal and uniform masses on the device; the other laws' masses come
  // from the host's NoiseModel, which only the factored sweep's tables use.
  const bool host_masses = !a.noise->device_masses();
  const std::string law = to_string(a.noise->distribution());
  if (host_masses && decomposition == SweepChoice::Dense)
    throw ConfigError("compute.sweep", "got dense, but the dense sweep computes normal and uniform noise only; " + law +
                                           " noise runs on the factored sweep (compute.sweep: auto or factored, "
                                           "with dynamics expressions) or on compute.device: reference");
  if (decomposition == SweepChoice::Dense) {
    note(notes, "dense sweep (requested)");
    return std::nullopt;
  }
  std::string reason;
  const double budget = compute.memory_fraction * double(device.global_memory);
  std::optional<FactoredPlan> plan = plan_factored_sweep(a, budget, double(device.max_allocation), &reason);
  if (decomposition == SweepChoice::Factored) {
    if (!plan)
      throw ConfigError("compute.sweep", "got factored, but the factored sweep cannot run: " + reason +
                                             " (example: sweep: auto)");
    note(notes, plan->describe() + " (requested)");
    return plan;
  }
  if (!plan && host_masses)
    throw ConfigError("noise.distribution", law + " noise needs the factored sweep on OpenCL devices (the dense sweep "
                                              "computes normal and uniform noise only), which cannot run: " + reason +
                                              "; use dynamics expressions or compute.device: reference");
  if (!plan) {
    note(notes, "dense sweep: the factored sweep cannot run: " + reason);
    return std::nullopt;
  }
  if (host_masses) {
    note(notes, plan->describe() + " (" + law + " noise: host masses)");
    return plan;
  }
  if (plan->multiply_adds > kFactoredShareLimit * plan->dense_multiply_adds) {
    note(notes, "dense sweep: the factored sweep would save too little (" + plan->describe() + ")");
    return std::nullopt;
  }
  note(notes, plan->describe());
  return plan;
}

}  // namespace amytiss::detail

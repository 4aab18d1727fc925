#pragma once
// The plant simulator node's plant and the texts of its episodes. The plant is the core's
// amytiss::Plant (x+ = f(x, u, w) + noise, noise by amytiss::NoiseSampler, docs/semantics.md)
// with its own seeded random numbers; the disturbance w, when the configuration has one, is drawn
// uniformly from its box each step (the synthesis assumed the worst case, so a random one can only
// do better).
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/model.hpp"
#include "amytiss/plant.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/spec_sets.hpp"

namespace amytiss_ros {

class PlantModel {
 public:
  /// `config` passed validate() when its policy was computed. Throws ConfigError from
  /// make_dynamics.
  PlantModel(const amytiss::Config& config, std::uint64_t seed);

  std::size_t state_dims() const { return plant_.state_dims(); }
  /// One step from `state` under `input` (input dims of the configuration, empty if none).
  std::vector<double> step(const std::vector<double>& state, const std::vector<double>& input);

 private:
  amytiss::Plant plant_;
  std::mt19937_64 random_;
};

/// Where a concrete state stands, judged on the configuration's own sets (amytiss::SpecSets: the
/// target and avoid boxes, the safe set, the car's body against the obstacles), not on the cells'
/// roles: a state in a target cell's box need not lie in the target. A state of the wrong length
/// is outside the grid.
amytiss::SetVerdict classify_state(const amytiss::SpecSets& sets, const std::vector<double>& state);

/// The outcome of one episode.
struct EpisodeOutcome {
  bool success = false;
  std::string description;  ///< "reached the target at step 12", "entered the avoid set at step 3", ...
};
/// The body of the configuration's vehicle (a built-in model of a car), or nothing.
std::optional<amytiss::VehicleOutline> vehicle_outline(const amytiss::Config& config);
/// " (yaw changed by 90.2 degrees, moved 5.9 m along x and -7.6 m along y)": how a vehicle's
/// episode from `first` to `last` (states) turned and moved, appended to its outcome.
std::string vehicle_motion_text(const amytiss::VehicleOutline& outline, const std::vector<double>& first,
                                const std::vector<double>& last);

/// "|rate - V_0| = 0.0014, 4 standard errors of V_0 over 20 episodes = 0.0334: consistent" (or
/// "NOT consistent"): the empirical success rate against the prediction, with the binomial
/// standard error sqrt(V_0 (1 - V_0) / episodes) of a rate whose true value is V_0.
std::string consistency_text(unsigned successes, unsigned episodes, double predicted);
/// "rate 0.9500 against [lower - 4 standard errors, upper + 4 standard errors] = [0.4182, 1.0000]
/// over 20 episodes: consistent" (or "NOT consistent"): the empirical success rate against the
/// continuous-system bounds of the start state's cell (guarantee: system), each widened by four
/// binomial standard errors of a rate whose true value is that bound.
std::string bounds_consistency_text(unsigned successes, unsigned episodes, double lower, double upper);

/// Outcome of an episode that ended at `step` in a state of verdict `verdict` (for Undecided: the
/// horizon is over). Reach specs succeed on Target; safety succeeds when the horizon is over.
EpisodeOutcome episode_outcome(amytiss::SpecType spec, amytiss::SetVerdict verdict, unsigned step);

}  // namespace amytiss_ros

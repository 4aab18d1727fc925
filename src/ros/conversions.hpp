#pragma once
// Conversions between core types and amytiss messages. Pure functions: no node, no master.
#include <optional>
#include <string>

#include <amytiss/GetInput.h>
#include <amytiss/InputCommand.h>
#include <amytiss/PolicyStatus.h>
#include <amytiss/StateStamped.h>
#include <amytiss/SynthesizeFeedback.h>
#include <visualization_msgs/MarkerArray.h>

#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/model.hpp"
#include "amytiss/policy.hpp"

namespace amytiss_ros {

/// Answers a GetInput request from `policy` (nullptr: no policy loaded yet, answered with
/// success false and "no policy yet: " + server_notice). On success `input` has the policy's
/// input dimensions, `probability` is V_k of the state's cell, `probability_upper` its upper bound
/// (Policy::upper_value) and `message` is server_notice (a warning such as "synthesizer not
/// running since ...", usually empty); otherwise success is false, `message` is
/// Policy::describe()'s sentence, `input` is empty and both probabilities 0. config_hash, run_id
/// and guarantee ("abstraction" or "system") name the answering policy (empty without one).
/// Allocation: only the response's vector and strings (they reuse their capacity).
void fill_get_input_response(const amytiss::Policy* policy, const std::vector<double>& state,
                             unsigned time_step, const std::string& server_notice,
                             amytiss::GetInput::Response& response);

/// The same for the closed loop: answers `state` into `command` (header and time_step copied).
void fill_input_command(const amytiss::Policy* policy, const amytiss::StateStamped& state,
                        const std::string& server_notice, amytiss::InputCommand& command);

/// "" for a converged policy (Policy::converged: an unbounded specification's interval iteration
/// may stop before the gap between its bounds closes to the tolerance), otherwise the warning every answer of it carries: "policy did not
/// converge: gap 3.2e-04 after 5000 iterations; probabilities are certified lower bounds".
std::string convergence_notice(const amytiss::Policy& policy);

/// Action feedback from engine progress.
amytiss::SynthesizeFeedback feedback_from_progress(const amytiss::Progress& progress);

/// "synthesis 42% (step 7/16) on reference, about 3.1 s left" for status and logs.
std::string describe_progress(const amytiss::Progress& progress);

/// What the markers show of a configuration: its name and its specification's sets (absent: not
/// in the specification), in state units.
struct MarkedSets {
  std::string config_name;
  std::optional<amytiss::Region> safe, target, avoid;
};

/// Reads the name and the spec's safe, target and avoid sets (one box or a list of boxes each) from
/// a policy file's stored configuration (canonical YAML, see docs/policy_file.md) without parsing
/// and validating the rest: the file's checksums vouch for it. Throws amytiss::ConfigError naming
/// the key (spec.avoid[1]) when a box is not {lb: [...], ub: [...]}.
MarkedSets marked_sets_from_yaml(const std::string& config_yaml);

/// Latched RViz markers over the x0/x1 projection (x1 = 0 for a one-dimensional state):
/// the covered set's outline (grid bounds: outermost cells' edges of `states`), and one box for
/// every box of the target (green), avoid (red) and safe (blue outline) sets, in the namespace of
/// its set with the box's index as id. Units: state units, in `frame_id`.
visualization_msgs::MarkerArray make_set_markers(const amytiss::Grid& states, const MarkedSets& sets,
                                                 const std::string& frame_id);

/// RViz marker of a car's body at `state` (configuration order, state units): a blue box of the
/// outline's length x width x 1.4 m, centred (length/2 - rear_to_reference) ahead of the
/// reference point (state[x_index], state[y_index]) along the yaw state[yaw_index] (rad), in
/// `frame_id` (m), namespace "car", id 0, so each new state replaces the last.
visualization_msgs::Marker make_car_marker(const std::vector<double>& state, const amytiss::VehicleOutline& outline,
                                           const std::string& frame_id);

}  // namespace amytiss_ros

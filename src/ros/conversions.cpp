#include "conversions.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "amytiss/errors.hpp"
#include "amytiss/grid.hpp"

namespace amytiss_ros {

namespace {

// The one answer behind both GetInput and InputCommand: on success `input` holds the policy's
// input, `probability` V_k of the state's cell and `*upper` (when not null) its upper bound;
// otherwise `input` is empty, `probability` and `*upper` 0 and `message` says why.
bool answer_state(const amytiss::Policy* policy, const std::vector<double>& state, unsigned time_step,
                  const std::string& server_notice, std::vector<double>& input, double& probability,
                  double* upper, std::string& message) {
  probability = 0.0;
  if (upper != nullptr) *upper = 0.0;
  message.clear();
  if (policy == nullptr) {
    input.clear();
    message = "no policy yet: " + server_notice;
    return false;
  }
  input.resize(policy->inputs.dims());
  double value = 0.0;
  const amytiss::LookupStatus status =
      policy->lookup(state.data(), state.size(), time_step, input.data(), &value, upper);
  if (status != amytiss::LookupStatus::Ok) {
    input.clear();
    message = policy->describe(status, state.data(), state.size(), time_step);
    return false;
  }
  probability = value;
  message = server_notice;
  return true;
}

template <typename Answer>
void name_policy(const amytiss::Policy* policy, Answer& answer) {
  answer.config_hash = policy ? policy->config_hash : std::string();
  answer.run_id = policy ? policy->run_id : std::string();
}

}  // namespace

void fill_get_input_response(const amytiss::Policy* policy, const std::vector<double>& state,
                             unsigned time_step, const std::string& server_notice,
                             amytiss::GetInput::Response& response) {
  response.success = answer_state(policy, state, time_step, server_notice, response.input, response.probability,
                                  &response.probability_upper, response.message);
  name_policy(policy, response);
  // Both names fit in std::string's inline buffer: no allocation on the request path.
  response.guarantee = policy ? amytiss::to_string(policy->guarantee) : std::string();
}

void fill_input_command(const amytiss::Policy* policy, const amytiss::StateStamped& state,
                        const std::string& server_notice, amytiss::InputCommand& command) {
  command.header.stamp = state.header.stamp;
  command.header.frame_id = state.header.frame_id;
  command.time_step = state.time_step;
  command.valid = answer_state(policy, state.state, state.time_step, server_notice, command.input,
                               command.probability, nullptr, command.message);
  name_policy(policy, command);
}

std::string convergence_notice(const amytiss::Policy& policy) {
  if (policy.converged) return "";
  char text[160];
  std::snprintf(text, sizeof text,
                "policy did not converge: gap %.3g after %u iterations; probabilities are certified lower bounds",
                policy.gap, policy.iterations);
  return text;
}

amytiss::SynthesizeFeedback feedback_from_progress(const amytiss::Progress& progress) {
  amytiss::SynthesizeFeedback feedback;
  feedback.phase = amytiss::to_string(progress.phase);
  feedback.percent = progress.percent();
  feedback.steps_done = progress.steps_done;
  feedback.steps_total = progress.steps_total;
  feedback.device = progress.device;
  feedback.remaining_s = progress.remaining_s;
  feedback.round = progress.round;
  feedback.max_rounds = progress.max_rounds;
  return feedback;
}

std::string describe_progress(const amytiss::Progress& progress) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(0);
  if (progress.max_rounds) text << "refinement round " << progress.round << "/" << progress.max_rounds << ": ";
  text << amytiss::to_string(progress.phase) << " " << progress.percent() << "% (step " << progress.steps_done << "/"
       << progress.steps_total << ") on " << progress.device;
  text.precision(1);
  text << ", " << progress.elapsed_s << " s elapsed";
  if (progress.remaining_s >= 0) text << ", about " << progress.remaining_s << " s left";
  return text.str();
}

namespace {

struct PlaneBox {
  double x_min, x_max, y_min, y_max;
};

PlaneBox project(const std::vector<double>& lb, const std::vector<double>& ub) {
  const bool two_d = lb.size() >= 2;
  return {lb[0], ub[0], two_d ? lb[1] : -0.5, two_d ? ub[1] : 0.5};
}

visualization_msgs::Marker colored_marker(const std::string& frame_id, const std::string& ns, int type, float r,
                                          float g, float b, float a) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame_id;
  marker.ns = ns;
  marker.id = 0;
  marker.type = type;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  marker.color.r = r;
  marker.color.g = g;
  marker.color.b = b;
  marker.color.a = a;
  return marker;
}

visualization_msgs::Marker filled_box(const PlaneBox& box, const std::string& frame_id,
                                      const std::string& ns, float r, float g, float b) {
  visualization_msgs::Marker marker =
      colored_marker(frame_id, ns, visualization_msgs::Marker::CUBE, r, g, b, 0.5f);
  marker.pose.position.x = 0.5 * (box.x_min + box.x_max);
  marker.pose.position.y = 0.5 * (box.y_min + box.y_max);
  marker.scale.x = std::max(box.x_max - box.x_min, 1e-3);
  marker.scale.y = std::max(box.y_max - box.y_min, 1e-3);
  marker.scale.z = 0.05;
  return marker;
}

visualization_msgs::Marker outline(const PlaneBox& box, const std::string& frame_id,
                                   const std::string& ns, float r, float g, float b) {
  visualization_msgs::Marker marker =
      colored_marker(frame_id, ns, visualization_msgs::Marker::LINE_STRIP, r, g, b, 1.0f);
  marker.scale.x = 0.05;
  const double corners[5][2] = {{box.x_min, box.y_min}, {box.x_max, box.y_min}, {box.x_max, box.y_max},
                                {box.x_min, box.y_max}, {box.x_min, box.y_min}};
  for (const auto& corner : corners) {
    geometry_msgs::Point point;
    point.x = corner[0];
    point.y = corner[1];
    marker.points.push_back(point);
  }
  return marker;
}

}  // namespace

visualization_msgs::Marker make_car_marker(const std::vector<double>& state, const amytiss::VehicleOutline& outline,
                                           const std::string& frame_id) {
  constexpr double kCarHeight = 1.4;  // m, for the picture only
  visualization_msgs::Marker marker = colored_marker(frame_id, "car", visualization_msgs::Marker::CUBE, 0.1f, 0.3f, 0.9f, 0.8f);
  const double yaw = state.at(outline.yaw_index);
  const double ahead = 0.5 * outline.length - outline.rear_to_reference;
  marker.pose.position.x = state.at(outline.x_index) + ahead * std::cos(yaw);
  marker.pose.position.y = state.at(outline.y_index) + ahead * std::sin(yaw);
  marker.pose.position.z = 0.5 * kCarHeight;
  marker.pose.orientation.z = std::sin(0.5 * yaw);
  marker.pose.orientation.w = std::cos(0.5 * yaw);
  marker.scale.x = outline.length;
  marker.scale.y = outline.width;
  marker.scale.z = kCarHeight;
  return marker;
}

namespace {

amytiss::Box stored_box(const YAML::Node& box, const std::string& key) {
  try {
    return amytiss::Box{box["lb"].as<std::vector<double>>(), box["ub"].as<std::vector<double>>()};
  } catch (const YAML::Exception& error) {
    throw amytiss::ConfigError(key, std::string("the stored box is not {lb: [..], ub: [..]}: ") + error.what());
  }
}

// One box {lb, ub} or a list of boxes, as the canonical text writes a set.
std::optional<amytiss::Region> stored_region(const YAML::Node& spec, const std::string& key) {
  const YAML::Node region = spec[key];
  if (!region || region.IsNull()) return std::nullopt;
  if (!region.IsSequence()) return amytiss::Region(stored_box(region, "spec." + key));
  std::vector<amytiss::Box> boxes;
  for (std::size_t i = 0; i < region.size(); ++i)
    boxes.push_back(stored_box(region[i], "spec." + key + "[" + std::to_string(i) + "]"));
  return amytiss::Region(std::move(boxes));
}

}  // namespace

MarkedSets marked_sets_from_yaml(const std::string& config_yaml) {
  const YAML::Node root = YAML::Load(config_yaml);
  MarkedSets sets;
  if (root["name"]) sets.config_name = root["name"].as<std::string>();
  const YAML::Node spec = root["spec"];
  if (!spec) return sets;
  sets.safe = stored_region(spec, "safe");
  sets.target = stored_region(spec, "target");
  sets.avoid = stored_region(spec, "avoid");
  return sets;
}

visualization_msgs::MarkerArray make_set_markers(const amytiss::Grid& states, const MarkedSets& sets,
                                                 const std::string& frame_id) {
  visualization_msgs::MarkerArray markers;
  // The covered set is the union of cells: from the lowest to the highest face.
  std::vector<double> covered_lb(states.dims()), covered_ub(states.dims());
  for (std::size_t i = 0; i < states.dims(); ++i) {
    covered_lb[i] = states.covered_low(i);
    covered_ub[i] = states.covered_high(i);
  }
  markers.markers.push_back(outline(project(covered_lb, covered_ub), frame_id, "grid_bounds", 0.2f, 0.2f, 0.2f));
  // One marker per box of a set: the set's namespace, the box's index as id.
  auto add_boxes = [&](const std::optional<amytiss::Region>& set, auto make) {
    if (!set) return;
    for (std::size_t i = 0; i < set->boxes.size(); ++i) {
      visualization_msgs::Marker marker = make(project(set->boxes[i].lb, set->boxes[i].ub));
      marker.id = static_cast<int>(i);
      markers.markers.push_back(marker);
    }
  };
  add_boxes(sets.target, [&](const PlaneBox& box) { return filled_box(box, frame_id, "target", 0.1f, 0.8f, 0.1f); });
  add_boxes(sets.avoid, [&](const PlaneBox& box) { return filled_box(box, frame_id, "avoid", 0.9f, 0.1f, 0.1f); });
  add_boxes(sets.safe, [&](const PlaneBox& box) { return outline(box, frame_id, "safe", 0.1f, 0.3f, 0.9f); });
  return markers;
}

}  // namespace amytiss_ros

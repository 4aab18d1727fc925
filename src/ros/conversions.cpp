#include "conversions.hpp"

#include <cmath>
#include <sstream>

#include "amytiss/grid.hpp"

namespace amytiss_ros {

void fill_get_input_response(const amytiss::Policy* policy, const std::vector<double>& state,
                             unsigned time_step, const std::string& no_policy_reason,
                             amytiss::GetInput::Response& response) {
  response.success = false;
  response.probability = 0.0;
  response.message.clear();
  if (policy == nullptr) {
    response.input.clear();
    response.message = "no policy yet: " + no_policy_reason;
    return;
  }
  response.input.resize(policy->inputs.dims());
  double probability = 0.0;
  const amytiss::LookupStatus status =
      policy->lookup(state.data(), state.size(), time_step, response.input.data(), &probability);
  if (status != amytiss::LookupStatus::Ok) {
    response.input.clear();
    response.message = policy->describe(status, state.data(), state.size(), time_step);
    return;
  }
  response.success = true;
  response.probability = probability;
}

void fill_input_command(const amytiss::Policy* policy, const amytiss::StateStamped& state,
                        const std::string& no_policy_reason, amytiss::InputCommand& command) {
  command.header.stamp = state.header.stamp;
  command.header.frame_id = state.header.frame_id;
  command.time_step = state.time_step;
  command.valid = false;
  command.probability = 0.0;
  command.message.clear();
  if (policy == nullptr) {
    command.input.clear();
    command.message = "no policy yet: " + no_policy_reason;
    return;
  }
  command.input.resize(policy->inputs.dims());
  double probability = 0.0;
  const amytiss::LookupStatus status = policy->lookup(state.state.data(), state.state.size(),
                                                      state.time_step, command.input.data(), &probability);
  if (status != amytiss::LookupStatus::Ok) {
    command.input.clear();
    command.message = policy->describe(status, state.state.data(), state.state.size(), state.time_step);
    return;
  }
  command.valid = true;
  command.probability = probability;
}

amytiss::SynthesizeFeedback feedback_from_progress(const amytiss::Progress& progress) {
  amytiss::SynthesizeFeedback feedback;
  feedback.phase = progress.phase;
  feedback.percent = progress.percent();
  feedback.steps_done = progress.steps_done;
  feedback.steps_total = progress.steps_total;
  feedback.device = progress.device;
  feedback.remaining_s = progress.remaining_s;
  return feedback;
}

std::string describe_progress(const amytiss::Progress& progress) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(0);
  text << progress.phase << " " << progress.percent() << "% (step " << progress.steps_done << "/"
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

visualization_msgs::Marker filled_box(const PlaneBox& box, const std::string& frame_id,
                                      const std::string& ns, float r, float g, float b) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame_id;
  marker.ns = ns;
  marker.id = 0;
  marker.type = visualization_msgs::Marker::CUBE;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.position.x = 0.5 * (box.x_min + box.x_max);
  marker.pose.position.y = 0.5 * (box.y_min + box.y_max);
  marker.pose.orientation.w = 1.0;
  marker.scale.x = std::max(box.x_max - box.x_min, 1e-3);
  marker.scale.y = std::max(box.y_max - box.y_min, 1e-3);
  marker.scale.z = 0.05;
  marker.color.r = r;
  marker.color.g = g;
  marker.color.b = b;
  marker.color.a = 0.5f;
  return marker;
}

visualization_msgs::Marker outline(const PlaneBox& box, const std::string& frame_id,
                                   const std::string& ns, float r, float g, float b) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame_id;
  marker.ns = ns;
  marker.id = 0;
  marker.type = visualization_msgs::Marker::LINE_STRIP;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  marker.scale.x = 0.05;
  marker.color.r = r;
  marker.color.g = g;
  marker.color.b = b;
  marker.color.a = 1.0f;
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

visualization_msgs::MarkerArray make_set_markers(const amytiss::Config& config, const std::string& frame_id) {
  visualization_msgs::MarkerArray markers;
  const amytiss::Grid states(config.states);
  // The covered set is the union of cells: half a cell beyond the outermost points.
  std::vector<double> covered_lb = states.lb(), covered_ub = states.last_point();
  for (std::size_t i = 0; i < states.dims(); ++i) {
    covered_lb[i] -= 0.5 * states.eta()[i];
    covered_ub[i] += 0.5 * states.eta()[i];
  }
  markers.markers.push_back(outline(project(covered_lb, covered_ub), frame_id, "grid_bounds", 0.2f, 0.2f, 0.2f));
  if (config.spec.target)
    markers.markers.push_back(
        filled_box(project(config.spec.target->lb, config.spec.target->ub), frame_id, "target", 0.1f, 0.8f, 0.1f));
  if (config.spec.avoid)
    markers.markers.push_back(
        filled_box(project(config.spec.avoid->lb, config.spec.avoid->ub), frame_id, "avoid", 0.9f, 0.1f, 0.1f));
  if (config.spec.safe)
    markers.markers.push_back(
        outline(project(config.spec.safe->lb, config.spec.safe->ub), frame_id, "safe", 0.1f, 0.3f, 0.9f));
  return markers;
}

}  // namespace amytiss_ros

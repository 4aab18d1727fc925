#include "amytiss/enum_names.hpp"

namespace amytiss {

template <>
const std::vector<std::pair<const char*, SpecType>>& enum_names() {
  static const std::vector<std::pair<const char*, SpecType>> names = {
      {"safety", SpecType::Safety}, {"reachability", SpecType::Reachability}, {"reach_avoid", SpecType::ReachAvoid}};
  return names;
}
template <>
const std::vector<std::pair<const char*, DeviceKind>>& enum_names() {
  static const std::vector<std::pair<const char*, DeviceKind>> names = {
      {"auto", DeviceKind::Auto}, {"cpu", DeviceKind::Cpu}, {"gpu", DeviceKind::Gpu}, {"reference", DeviceKind::Reference}};
  return names;
}
template <>
const std::vector<std::pair<const char*, TransitionStorage>>& enum_names() {
  static const std::vector<std::pair<const char*, TransitionStorage>> names = {
      {"auto", TransitionStorage::Auto}, {"stored", TransitionStorage::Stored}, {"on_the_fly", TransitionStorage::OnTheFly}};
  return names;
}
template <>
const std::vector<std::pair<const char*, SweepChoice>>& enum_names() {
  static const std::vector<std::pair<const char*, SweepChoice>> names = {
      {"auto", SweepChoice::Auto}, {"dense", SweepChoice::Dense}, {"factored", SweepChoice::Factored}};
  return names;
}
template <>
const std::vector<std::pair<const char*, BoundsMethod>>& enum_names() {
  static const std::vector<std::pair<const char*, BoundsMethod>> names = {{"auto", BoundsMethod::Auto},
                                                                          {"whole_tables", BoundsMethod::WholeTables},
                                                                          {"elimination", BoundsMethod::Elimination},
                                                                          {"rows", BoundsMethod::Rows},
                                                                          {"joint", BoundsMethod::Joint}};
  return names;
}
template <>
const std::vector<std::pair<const char*, NoiseType>>& enum_names() {
  static const std::vector<std::pair<const char*, NoiseType>> names = {{"additive", NoiseType::Additive},
                                                                       {"multiplicative", NoiseType::Multiplicative}};
  return names;
}
template <>
const std::vector<std::pair<const char*, Distribution>>& enum_names() {
  static const std::vector<std::pair<const char*, Distribution>> names = {
      {"normal", Distribution::Normal},
      {"uniform", Distribution::Uniform},
      {"exponential", Distribution::Exponential},
      {"beta", Distribution::Beta},
      {"custom", Distribution::Custom}};
  return names;
}
template <>
const std::vector<std::pair<const char*, Truncation>>& enum_names() {
  static const std::vector<std::pair<const char*, Truncation>> names = {
      {"none", Truncation::None}, {"fixed_region", Truncation::FixedRegion},
      {"cutting_probability", Truncation::CuttingProbability}};
  return names;
}
template <>
const std::vector<std::pair<const char*, IntegrationMethod>>& enum_names() {
  static const std::vector<std::pair<const char*, IntegrationMethod>> names = {{"euler", IntegrationMethod::Euler},
                                                                               {"rk4", IntegrationMethod::Rk4}};
  return names;
}
template <>
const std::vector<std::pair<const char*, Guarantee>>& enum_names() {
  static const std::vector<std::pair<const char*, Guarantee>> names = {{"abstraction", Guarantee::Abstraction},
                                                                       {"system", Guarantee::System}};
  return names;
}
template <>
const std::vector<std::pair<const char*, ValueStorage>>& enum_names() {
  static const std::vector<std::pair<const char*, ValueStorage>> names = {{"exact", ValueStorage::Exact},
                                                                          {"float32_lower", ValueStorage::Float32Lower}};
  return names;
}
template <>
const std::vector<std::pair<const char*, Phase>>& enum_names() {
  static const std::vector<std::pair<const char*, Phase>> names = {
      {"setup", Phase::Setup}, {"construction", Phase::Construction}, {"synthesis", Phase::Synthesis}, {"done", Phase::Done}};
  return names;
}
template <>
const std::vector<std::pair<const char*, NoteSeverity>>& enum_names() {
  static const std::vector<std::pair<const char*, NoteSeverity>> names = {{"info", NoteSeverity::Info},
                                                                          {"warning", NoteSeverity::Warning}};
  return names;
}
template <>
const std::vector<std::pair<const char*, NoteKind>>& enum_names() {
  static const std::vector<std::pair<const char*, NoteKind>> names = {
      {"device_choice", NoteKind::DeviceChoice}, {"device_fallback", NoteKind::DeviceFallback},
      {"transitions", NoteKind::Transitions},    {"sweep", NoteKind::Sweep},
      {"chunking", NoteKind::Chunking},          {"device_memory", NoteKind::DeviceMemory},
      {"kernel_build", NoteKind::KernelBuild},    {"convergence", NoteKind::Convergence},
      {"refinement", NoteKind::Refinement}};
  return names;
}

namespace {
template <typename Enum>
std::string name_of(Enum value) {
  for (const auto& [text, candidate] : enum_names<Enum>())
    if (candidate == value) return text;
  return "?";
}
}  // namespace

std::string to_string(SpecType value) { return name_of(value); }
std::string to_string(DeviceKind value) { return name_of(value); }
std::string to_string(TransitionStorage value) { return name_of(value); }
std::string to_string(SweepChoice value) { return name_of(value); }
std::string to_string(BoundsMethod value) { return name_of(value); }
std::string to_string(NoiseType value) { return name_of(value); }
std::string to_string(Distribution value) { return name_of(value); }
std::string to_string(Truncation value) { return name_of(value); }
std::string to_string(IntegrationMethod value) { return name_of(value); }
std::string to_string(Guarantee value) { return name_of(value); }
std::string to_string(ValueStorage value) { return name_of(value); }
std::string to_string(Phase value) { return name_of(value); }
std::string to_string(NoteSeverity value) { return name_of(value); }
std::string to_string(NoteKind value) { return name_of(value); }

}  // namespace amytiss

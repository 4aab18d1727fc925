// Export of the finite abstraction: the files are read back by a reader written here (not the
// writer's code), every row sums to 1, and the bounded-horizon value recomputed from the files
// equals the reference engine's. A write that fails part-way leaves the previous export intact.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/config.hpp"
#include "amytiss/engine.hpp"
#include "amytiss/errors.hpp"
#include "amytiss/model_export.hpp"

#include "child_process.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;

constexpr double kRowSumTolerance = 1e-12;
// The files print probabilities with 17 digits: the recomputed value differs by rounding only.
constexpr double kValueTolerance = 1e-12;
// A file size limit the large export's model.tra exceeds, and a transition limit no test reaches.
constexpr std::uintmax_t kFileSizeLimit = 64 * 1024;
constexpr std::size_t kNoTransitionLimit = 1000000;

struct ReadModel {
  // choices[state][choice] = (target, probability) list
  std::vector<std::vector<std::vector<std::pair<std::size_t, double>>>> choices;
  std::vector<std::set<std::string>> labels;
};

fs::path scratch(const std::string& name) {
  const fs::path path = fs::temp_directory_path() / ("amytiss_export_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(path);
  return path;
}

ReadModel read_prism(const fs::path& folder) {
  ReadModel model;
  std::ifstream tra(folder / "model.tra");
  std::size_t states = 0, choices = 0, transitions = 0;
  tra >> states >> choices >> transitions;
  model.choices.resize(states);
  model.labels.resize(states);
  std::size_t source, choice, target, read = 0;
  double probability;
  while (tra >> source >> choice >> target >> probability) {
    auto& list = model.choices.at(source);
    if (list.size() <= choice) list.resize(choice + 1);
    list[choice].push_back({target, probability});
    ++read;
  }
  EXPECT_EQ(read, transitions);
  std::size_t counted_choices = 0;
  for (const auto& list : model.choices) counted_choices += list.size();
  EXPECT_EQ(counted_choices, choices);
  std::ifstream lab(folder / "model.lab");
  std::string header;
  std::getline(lab, header);
  std::map<int, std::string> names;
  std::istringstream header_stream(header);
  std::string entry;
  while (header_stream >> entry) {
    const auto equals = entry.find('=');
    names[std::stoi(entry.substr(0, equals))] = entry.substr(equals + 2, entry.size() - equals - 3);
  }
  std::string line;
  while (std::getline(lab, line)) {
    std::istringstream stream(line);
    std::string state_text;
    stream >> state_text;
    const std::size_t state = std::stoul(state_text.substr(0, state_text.size() - 1));
    int index;
    while (stream >> index) model.labels.at(state).insert(names.at(index));
  }
  return model;
}

ReadModel read_drn(const fs::path& folder) {
  ReadModel model;
  std::ifstream drn(folder / "model.drn");
  std::string line;
  std::size_t states = 0;
  while (std::getline(drn, line) && line != "@model")
    if (line == "@nr_states") {
      std::getline(drn, line);
      states = std::stoul(line);
    }
  model.choices.resize(states);
  model.labels.resize(states);
  std::size_t state = 0;
  while (std::getline(drn, line)) {
    std::istringstream stream(line);
    std::string word;
    stream >> word;
    if (word == "state") {
      stream >> state;
      while (stream >> word) model.labels[state].insert(word);
    } else if (word == "action") {
      model.choices[state].emplace_back();
    } else {
      std::string colon;
      double probability;
      stream >> colon >> probability;
      model.choices[state].back().push_back({std::stoul(word), probability});
    }
  }
  return model;
}

// The game value over `steps` model steps: max over choices, min at adversary states; sink and
// avoid/unsafe count 0, target 1 (absorbing).
std::vector<double> bounded_value(const ReadModel& model, SpecType spec, unsigned steps) {
  const std::size_t n = model.choices.size();
  auto has = [&](std::size_t s, const char* label) { return model.labels[s].count(label) > 0; };
  std::vector<double> value(n);
  for (std::size_t s = 0; s < n; ++s) {
    const bool failed = has(s, "sink") || has(s, "avoid") || has(s, "unsafe");
    value[s] = failed ? 0.0 : has(s, "target") ? 1.0 : (spec == SpecType::Safety && !has(s, "adversary")) ? 1.0 : 0.0;
  }
  for (unsigned k = 0; k < steps; ++k) {
    std::vector<double> next(n);
    for (std::size_t s = 0; s < n; ++s) {
      if (has(s, "sink") || has(s, "avoid") || has(s, "unsafe") || has(s, "target")) {
        next[s] = value[s];
        continue;
      }
      const bool minimize = has(s, "adversary");
      double best = minimize ? 2.0 : -1.0;
      for (const auto& choice : model.choices[s]) {
        double sum = 0;
        for (const auto& [target, probability] : choice) sum += probability * value[target];
        best = minimize ? std::min(best, sum) : std::max(best, sum);
      }
      next[s] = best;
    }
    value.swap(next);
  }
  return value;
}

void expect_export_matches_engine(const std::string& yaml, const std::string& name) {
  const Abstraction a = Abstraction::from_config(config_from_yaml(YAML::Load(yaml)));
  const Policy policy = synthesize_reference(a, nullptr);
  const bool adversary = a.disturbances.dims() > 0;
  for (ExportFormat format : {ExportFormat::Prism, ExportFormat::Drn}) {
    const fs::path folder = scratch(name);
    const ExportSummary summary = export_model(a, format, folder.string(), kNoTransitionLimit);
    const ReadModel model = format == ExportFormat::Prism ? read_prism(folder) : read_drn(folder);
    ASSERT_EQ(model.choices.size(), summary.states);
    EXPECT_TRUE(fs::exists(folder / "README.md"));
    double worst_row = 0;
    for (const auto& state : model.choices)
      for (const auto& choice : state) {
        double sum = 0;
        for (const auto& entry : choice) sum += entry.second;
        worst_row = std::max(worst_row, std::fabs(sum - 1.0));
      }
    EXPECT_LE(worst_row, kRowSumTolerance) << name;
    const std::vector<double> value = bounded_value(model, a.spec, adversary ? 2 * a.horizon : a.horizon);
    double largest_difference = 0, largest_value = 0;
    for (std::size_t cell = 0; cell < a.states.size(); ++cell) {
      largest_difference = std::max(largest_difference, std::fabs(value[cell] - policy.value(0, cell)));
      largest_value = std::max(largest_value, value[cell]);
    }
    EXPECT_LE(largest_difference, kValueTolerance) << name;
    EXPECT_GT(largest_value, 0.1) << "a trivial model tests nothing";
    std::printf("%s (%s): %zu states, %zu choices, %zu transitions, max row |sum - 1| %.2g, "
                "max |V_0(files) - V_0(engine)| %.2g\n",
                name.c_str(), format == ExportFormat::Prism ? "prism" : "drn", summary.states, summary.choices,
                summary.transitions, worst_row, largest_difference);
    fs::remove_all(folder);
  }
}

constexpr const char* kReachAvoidYaml =
    "name: export_reach_avoid\n"
    "states: {lb: [-2, -2], ub: [2, 2], eta: [0.5, 0.5]}\n"
    "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
    "dynamics: [\"x0 + 0.5*u0\", \"x1 + 0.5*u1\"]\n"
    "noise: {covariance: [0.04, 0.09], truncation: cutting_probability, cutting_probability: 1.0e-2}\n"
    "spec: {type: reach_avoid, horizon: 4, target: {lb: [1, 1], ub: [2, 2]}, avoid: {lb: [-0.5, -0.5], ub: [0.5, "
    "0.5]}}\n";
constexpr const char* kOneDimensionalYaml =
    "name: export_limit\nstates: {lb: [-2], ub: [2], eta: [0.25]}\ndynamics: [\"x0\"]\n"
    "noise: {covariance: [0.1]}\nspec: {type: safety, horizon: 1}\n";

TEST(ModelExport, ReachAvoidWithTruncationAndOffGridMass) {
  expect_export_matches_engine(kReachAvoidYaml, "reach_avoid");
}

TEST(ModelExport, SafetyWithDisturbanceAsAdversary) {
  expect_export_matches_engine(
      "name: export_safety\n"
      "states: {lb: [-1], ub: [1], eta: [0.2]}\n"
      "inputs: {lb: [-0.2], ub: [0.2], eta: [0.2]}\n"
      "disturbances: {lb: [-0.1], ub: [0.1], eta: [0.1]}\n"
      "dynamics: [\"0.9*x0 + u0 + w0\"]\n"
      "noise: {covariance: [0.01], truncation: cutting_probability, cutting_probability: 1.0e-4}\n"
      "spec: {type: safety, horizon: 3, safe: {lb: [-0.8], ub: [0.8]}}\n",
      "safety_adversary");
}

TEST(ModelExport, ExponentialNoise) {
  expect_export_matches_engine(
      "name: export_exponential\n"
      "states: {lb: [-2], ub: [2], eta: [0.25]}\n"
      "inputs: {lb: [-0.5], ub: [0.5], eta: [0.5]}\n"
      "dynamics: [\"0.8*x0 + u0\"]\n"
      "noise: {distribution: exponential, rate: [3], shift: [-0.3], truncation: cutting_probability}\n"
      "spec: {type: reachability, horizon: 5, target: {lb: [1], ub: [1.5]}}\n",
      "exponential");
}

TEST(ModelExport, UnionsOfBoxesLabelEveryBoxsCells) {
  expect_export_matches_engine(
      "name: export_unions\n"
      "states: {lb: [-2, -2], ub: [2, 2], eta: [0.5, 0.5]}\n"
      "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
      "dynamics: [\"x0 + 0.5*u0\", \"x1 + 0.5*u1\"]\n"
      "noise: {covariance: [0.04, 0.09], truncation: cutting_probability, cutting_probability: 1.0e-2}\n"
      "spec: {type: reach_avoid, horizon: 4, target: [{lb: [1, 1], ub: [2, 2]}, {lb: [-2, 1.5], ub: [-1.5, 2]}],\n"
      "       avoid: [{lb: [-0.5, -0.5], ub: [0.5, 0.5]}, {lb: [1, -2], ub: [2, -1.5]}, {lb: [-2, -2], ub: [-2, -1]}]}\n",
      "unions");
}

TEST(ModelExport, RefusesModelsAboveTheLimit) {
  const Abstraction a = Abstraction::from_config(config_from_yaml(YAML::Load(kOneDimensionalYaml)));
  const fs::path folder = scratch("limit");
  const std::size_t bound = export_transition_bound(a);
  EXPECT_EQ(bound, 17u * 18u + 1u);  // 17 rows of 17 cells and the sink, the sink's self-loop
  EXPECT_THROW(export_model(a, ExportFormat::Prism, folder.string(), bound - 1), ExportTooLarge);
  EXPECT_FALSE(fs::exists(folder));
  EXPECT_NO_THROW(export_model(a, ExportFormat::Prism, folder.string(), bound));
  fs::remove_all(folder);
}

// The export writes the abstraction built from the cells' centre points: under guarantee: system
// its values would pass for continuous-system bounds they are not, so it is refused, and the
// README says which value the files give.
TEST(ModelExport, RefusesGuaranteeSystemNamingTheKey) {
  const Abstraction a =
      Abstraction::from_config(config_from_yaml(YAML::Load(std::string(kReachAvoidYaml) + "guarantee: system\n")));
  const fs::path folder = scratch("system");
  try {
    export_model(a, ExportFormat::Drn, folder.string(), kNoTransitionLimit);
    ADD_FAILURE() << "guarantee: system was exported";
  } catch (const ConfigError& error) {
    EXPECT_EQ("guarantee", error.key());
    const std::string message = error.what();
    EXPECT_NE(std::string::npos, message.find("got system")) << message;
    EXPECT_NE(std::string::npos, message.find("example: guarantee: abstraction")) << message;
  }
  EXPECT_FALSE(fs::exists(folder)) << "a refused export writes nothing";
  fs::remove_all(folder);
}

TEST(ModelExport, ReadmeSaysTheValueIsTheCentrePointAbstractions) {
  const Abstraction a = Abstraction::from_config(config_from_yaml(YAML::Load(kReachAvoidYaml)));
  const fs::path folder = scratch("readme");
  export_model(a, ExportFormat::Prism, folder.string(), kNoTransitionLimit);
  std::ifstream file(folder / "README.md");
  const std::string readme((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  for (const char* part : {"The bounded-horizon value V_0 of this finite MDP from each cell is",
                           "Pmax=? [ !(\"avoid\" | \"sink\") U<=4 \"target\" ]",
                           "the value amytiss computes with `guarantee: abstraction`",
                           "from each cell's centre point", "not a bound of the continuous system's probability"})
    EXPECT_NE(std::string::npos, readme.find(part)) << part << "\n" << readme;
  EXPECT_EQ(std::string::npos, readme.find("value V_0 of amytiss")) << readme;
  fs::remove_all(folder);
}

std::map<std::string, std::string> folder_contents(const fs::path& folder) {
  std::map<std::string, std::string> contents;
  for (const auto& entry : fs::directory_iterator(folder)) {
    std::ifstream file(entry.path(), std::ios::binary);
    contents[entry.path().filename().string()].assign(std::istreambuf_iterator<char>(file), {});
  }
  return contents;
}

std::string file_sizes(const std::map<std::string, std::string>& contents) {
  std::string text;
  for (const auto& [name, bytes] : contents) text += name + " (" + std::to_string(bytes.size()) + " bytes) ";
  return text;
}

// A write that fails part-way (here at a file size limit, as on a full disk) leaves the previous
// export as it was: no truncated model.tra, no temporary file.
TEST(ModelExport, AFailedWriteLeavesThePreviousExportIntact) {
  const Abstraction small = Abstraction::from_config(config_from_yaml(YAML::Load(kOneDimensionalYaml)));
  const Abstraction large = Abstraction::from_config(config_from_yaml(YAML::Load(kReachAvoidYaml)));
  const fs::path unlimited = scratch("unlimited"), folder = scratch("file_size_limit");
  export_model(large, ExportFormat::Prism, unlimited.string(), kNoTransitionLimit);
  ASSERT_GT(fs::file_size(unlimited / "model.tra"), kFileSizeLimit) << "the limit must cut the large export";
  fs::remove_all(unlimited);
  export_model(small, ExportFormat::Prism, folder.string(), kNoTransitionLimit);
  const auto previous = folder_contents(folder);
  const test_support::ChildOutcome outcome = test_support::run_in_child([&] {
    ::signal(SIGXFSZ, SIG_IGN);  // then a write past the limit fails with EFBIG
    const rlimit limit{kFileSizeLimit, kFileSizeLimit};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      export_model(large, ExportFormat::Prism, folder.string(), kNoTransitionLimit);
    } catch (const std::runtime_error& error) {
      return std::string(error.what());
    }
    return std::string("exported");
  });
  EXPECT_TRUE(outcome.exited_normally()) << outcome.describe();
  EXPECT_NE(std::string::npos, outcome.message.find(std::strerror(EFBIG))) << outcome.message;
  const auto now = folder_contents(folder);
  EXPECT_TRUE(previous == now) << "the previous export changed; the folder holds " << file_sizes(now);
  fs::remove_all(folder);
}

}  // namespace
}  // namespace amytiss

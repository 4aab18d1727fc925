// The warnings of the continuous-system bounds when their lower bound keeps no cell (it is then 0
// everywhere): they say why, whether no cell lies wholly inside the set or the footprint may touch
// an obstacle in every cell that does.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <string>

#include "amytiss/engine.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;

// 5 x 5 x 3 cells; the spec's lines are appended.
std::string car_yaml(const std::string& spec) {
  return "name: role_notes\n"
         "states: {lb: [0, 0, -0.5], ub: [4, 4, 0.5], eta: [1, 1, 0.5]}\n"
         "inputs: {lb: [-1], ub: [1], eta: [1]}\n"
         "dynamics: [\"x0 + 0.5*u0*cos(x2)\", \"x1 + 0.5*u0*sin(x2)\", \"x2\"]\n"
         "noise: {covariance: [0.01, 0.01, 0.01]}\n"
         "guarantee: system\n"
         "spec:\n" + spec;
}

// An obstacle beside the target's cells (x = 0..1): a 4 m body reaches it from all of them.
const char* const kObstacleNearTarget =
    "  obstacles: {lb: [2.5, -1], ub: [3, 5]}\n"
    "  footprint: {pose: [0, 1, 2], length: 4, width: 1, rear_overhang: 0}\n";

const EngineNote* warning(const SynthesisReport& report) {
  const auto found = std::find_if(report.notes.begin(), report.notes.end(),
                                  [](const EngineNote& note) { return note.severity == NoteSeverity::Warning; });
  return found == report.notes.end() ? nullptr : &*found;
}

SynthesisReport run(const std::string& yaml) {
  SynthesisReport report;
  synthesize(from_yaml(yaml), SynthesisOptions{}, &report);
  return report;
}

TEST(RoleNotes, ATargetAvoidedByTheFootprintEverywhereSaysSo) {
  const SynthesisReport report = run(car_yaml("  type: reach_avoid\n  horizon: 2\n"
                                              "  target: {lb: [-0.5, -0.5, -0.75], ub: [1.5, 4.5, 0.75]}\n" +
                                              std::string(kObstacleNearTarget)));
  const EngineNote* note = warning(report);
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->text.find("the lower bound is 0 everywhere"), std::string::npos) << note->text;
  EXPECT_NE(note->text.find("the 30 cells wholly inside the target are all avoided: the footprint may touch"),
            std::string::npos)
      << note->text;
  EXPECT_EQ(note->text.find("draw the target"), std::string::npos) << note->text;
}

TEST(RoleNotes, ASafetySpecWithNoCellInsideTheSafeSetIsWarned) {
  // The safe set is thinner than a cell: no cell lies wholly inside it.
  const SynthesisReport report =
      run(car_yaml("  type: safety\n  horizon: 2\n  safe: {lb: [0, 0, -0.5], ub: [4, 0.2, 0.5]}\n"));
  const EngineNote* note = warning(report);
  ASSERT_NE(note, nullptr);
  EXPECT_EQ(note->text.find("0 of 75 cells lie wholly inside the safe set (the lower bound's safe cells): the "
                            "lower bound is 0 everywhere; draw the safe set on the cells' faces"),
            0u)
      << note->text;
}

TEST(RoleNotes, ASafetySpecWhoseFootprintTouchesEverywhereSaysSo) {
  const SynthesisReport report = run(car_yaml("  type: safety\n  horizon: 2\n"
                                              "  obstacles: {lb: [-2, -2], ub: [6, 6]}\n"
                                              "  footprint: {pose: [0, 1, 2], length: 4, width: 1, rear_overhang: 0}\n"));
  const EngineNote* note = warning(report);
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->text.find("the 75 cells wholly inside the safe set are all avoided: the footprint may touch"),
            std::string::npos)
      << note->text;
  // With room to stay clear, no warning.
  EXPECT_EQ(warning(run(car_yaml("  type: safety\n  horizon: 2\n"))), nullptr);
}

}  // namespace
}  // namespace amytiss

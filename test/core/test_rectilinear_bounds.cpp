// Rectilinear state grids beyond the abstraction's values (see test_rectilinear.cpp):
// - Continuous-system bounds on a 1-d grid with faces enclose the continuous system's values:
//   the served controller's by a recursion over a grid kFineCellsPerCell times finer, aligned with
//   the cells and the sets, above the lower bound; the best input's below the upper bound.
// - states.fit_sets inserts the sets' faces inside the grid's range (and only there), and the
//   lower bound at a start state does not drop against the unfitted grid.
// - Config validation of states.faces and states.fit_sets; the canonical text reads back.
// - Policy files: faces round trip; a file without /states/faces (older files) still reads.
#include <gtest/gtest.h>

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "amytiss/engine.hpp"
#include "amytiss/grid_rules.hpp"
#include "amytiss/policy_file.hpp"
#include "io/hdf5_handle.hpp"
#include "fine_recursion.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using test_support::expect_error;
using test_support::from_yaml;

const char* const kFaced1dSystem =
    "name: faced_1d_system\n"
    "states: {faces: [[-1, -0.8, -0.65, -0.5, -0.3, -0.2, -0.1, 0, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0]]}\n"
    "inputs: {lb: [-0.2], ub: [0.2], eta: [0.1]}\n"
    "dynamics: [\"0.9*x0 + u0\"]\n"
    "noise: {type: additive, distribution: normal, covariance: [0.0144]}\n"
    "spec: {type: reach_avoid, horizon: 5, target: {lb: [0.3], ub: [0.6]}, avoid: {lb: [-1], ub: [-0.7]}}\n"
    "guarantee: system\n";

TEST(RectilinearBounds, SystemBoundsOnFacesEncloseTheContinuousValues) {
  const Abstraction a = from_yaml(kFaced1dSystem);
  SynthesisOptions options;
  options.compute.device = DeviceKind::Auto;
  const Policy policy = synthesize(a, options, nullptr);
  EXPECT_LT(test_support::expect_encloses_fine_values(a, policy), 0.25);  // the lower bound is informative somewhere
}

// ------------------------------------------------------------------------------------------
// fit_sets

std::string robot_yaml(bool fit) {
  return std::string("name: robot_fit\n") + "states: {lb: [-3, -3], ub: [3, 3], eta: [1, 1]" +
         (fit ? ", fit_sets: true" : "") +
         "}\n"
         "inputs: {lb: [-1, -1], ub: [1, 1], eta: [1, 1]}\n"
         "dynamics: [\"x0 + u0\", \"x1 + u1\"]\n"
         "noise: {type: additive, distribution: normal, covariance: [0.25, 0.25]}\n"
         "spec: {type: reach_avoid, horizon: 4, target: {lb: [1.2, 1.2], ub: [2.7, 3.5]},\n"
         "       avoid: {lb: [-2.7, -2.7], ub: [-1.2, -1.2]}}\n"
         "guarantee: system\n";
}

TEST(RectilinearBounds, FitSetsInsertsTheSetsFacesInsideTheGrid) {
  const Config config = config_from_yaml(YAML::Load(robot_yaml(true)));
  const GridSpec fitted = fitted_states(config);
  ASSERT_EQ(fitted.faces.size(), 2u);
  // 3.5 is the grid's own top face: not inserted again.
  const std::vector<double> expected0{-3.5, -2.7, -2.5, -1.5, -1.2, -0.5, 0.5, 1.2, 1.5, 2.5, 2.7, 3.5};
  const std::vector<double> expected1{-3.5, -2.7, -2.5, -1.5, -1.2, -0.5, 0.5, 1.2, 1.5, 2.5, 3.5};
  EXPECT_EQ(fitted.faces[0], expected0);
  EXPECT_EQ(fitted.faces[1], expected1);
  EXPECT_TRUE(std::isnan(fitted.lb[0]));
  const Abstraction a = from_yaml(robot_yaml(true));
  EXPECT_EQ(a.states.counts(), (std::vector<std::size_t>{11, 10}));
  // Without fit_sets the grid is the configuration's.
  EXPECT_TRUE(fitted_states(config_from_yaml(YAML::Load(robot_yaml(false)))).faces.empty());
}

TEST(RectilinearBounds, FitSetsDoesNotLowerTheBoundAtAStartState) {
  SynthesisOptions options;
  options.compute.device = DeviceKind::Auto;
  const Abstraction plain = from_yaml(robot_yaml(false)), fit = from_yaml(robot_yaml(true));
  const Policy p = synthesize(plain, options, nullptr), q = synthesize(fit, options, nullptr);
  const double start[] = {0.0, 0.3};
  const double before = p.value(0, *plain.states.cell_of(start)), after = q.value(0, *fit.states.cell_of(start));
  EXPECT_GT(before, 0.0);
  EXPECT_GE(after, before);
}

// ------------------------------------------------------------------------------------------
// Config

const char* const kRest =
    "inputs: {lb: [-0.2], ub: [0.2], eta: [0.1]}\n"
    "dynamics: [\"0.9*x0 + u0\"]\n"
    "noise: {covariance: [0.0144]}\n"
    "spec: {type: reach_avoid, horizon: 3, target: {lb: [0.3], ub: [0.6]}}\n";

YAML::Node with_states(const std::string& states, const std::string& more = "") {
  return YAML::Load("name: faces\nstates: " + states + "\n" + kRest + more);
}

TEST(RectilinearBounds, ValidationRefusesBadFacesAndNamesTheKey) {
  expect_error(with_states("{faces: [[0, 1, 1]]}"), "states.faces[0]", "strictly increasing");
  expect_error(with_states("{faces: [[0.5, 0.2]]}"), "states.faces[0]", "strictly increasing");
  expect_error(with_states("{faces: [[0.4]]}"), "states.faces[0]", "at least 2 faces");
  expect_error(with_states("{faces: [[0, .inf]]}"), "states.faces[0][1]", "a finite number");
  expect_error(with_states("{faces: [[0, 1], ~]}"), "states.lb[1]", "a finite number");
  expect_error(with_states("{lb: [0], ub: [1], eta: [0.5], faces: [[0, 0.5, 1]]}"), "states.lb[0]", "null");
  expect_error(with_states("{lb: [~], ub: [~], eta: [0.5], faces: [[0, 0.5, 1]]}"), "states.eta[0]", "null");
  expect_error(with_states("{lb: [~, 0], ub: [~, 1], eta: [~, 0.5], faces: [[0, 0.5, 1]]}"), "states.lb",
               "as many as states.faces");
  expect_error(with_states("{faces: [0, 1]}"), "states.faces[0]", "a list of numbers");
  expect_error(with_states("{lb: [0], ub: [1], eta: [0.1], fit_sets: true}"), "states.fit_sets",
               "guarantee: abstraction");
  expect_error(with_states("{lb: [0], ub: [1], eta: [0.1], fit_sets: yes}"), "states.fit_sets", "true or false");
  // A box must still hold a point of the grid with faces.
  expect_error(YAML::Load(std::string("name: f\nstates: {faces: [[0, 0.2, 1]]}\n") +
                          "inputs: {lb: [0], ub: [0], eta: [1]}\ndynamics: [\"x0\"]\nnoise: {covariance: [0.01]}\n"
                          "spec: {type: reachability, horizon: 2, target: {lb: [0.15], ub: [0.5]}}\n"),
               "spec.target", "no representative point");
}

TEST(RectilinearBounds, CanonicalTextOfFacesReadsBackAndUniformTextHasNoFaces) {
  const Config config = config_from_yaml(with_states("{lb: [~], ub: [~], eta: [~], faces: [[0, 0.25, 0.5, 1]]}"));
  const std::string text = to_yaml(config);
  EXPECT_NE(text.find("faces: [[0, 0.25, 0.5, 1]]"), std::string::npos) << text;
  const Config again = read_stored_config(text);
  EXPECT_EQ(config_hash(again), config_hash(config));
  EXPECT_EQ(again.states.faces, config.states.faces);
  const Config uniform = config_from_yaml(with_states("{lb: [0], ub: [1], eta: [0.1]}"));
  EXPECT_EQ(to_yaml(uniform).find("faces:"), std::string::npos);
  EXPECT_NE(config_hash(uniform), config_hash(config));
}

// ------------------------------------------------------------------------------------------
// Policy files

class RectilinearFile : public ::testing::Test {
 protected:
  void SetUp() override { directory_ = test_support::fresh_test_directory("amytiss_rectilinear_"); }
  void TearDown() override { std::filesystem::remove_all(directory_); }
  std::string path(const std::string& name) const { return (directory_ / name).string(); }
  std::filesystem::path directory_;
};

void remove_faces(const std::string& file) {
  detail::Hdf5Handle handle(H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  ASSERT_TRUE(handle.valid());
  ASSERT_GE(H5Ldelete(handle.get(), "/states/faces", H5P_DEFAULT), 0);
}

TEST_F(RectilinearFile, FacesRoundTripAndLookUpTheirCells) {
  const Config config = config_from_yaml(YAML::Load(std::string(kFaced1dSystem)));
  SynthesisOptions options;
  options.compute.device = DeviceKind::Auto;
  const Policy policy = synthesize(Abstraction::from_config(config), options, nullptr);
  write_policy_file(path("faces.h5"), policy, config);
  const LoadedPolicy loaded = read_policy_file_for(path("faces.h5"), config);
  ASSERT_FALSE(loaded.policy.states.uniform(0));
  EXPECT_EQ(loaded.policy.states.faces(0), policy.states.faces(0));
  EXPECT_EQ(loaded.policy.states.coordinate(0, 3), policy.states.coordinate(0, 3));
  EXPECT_EQ(loaded.policy.values, policy.values);
  EXPECT_EQ(loaded.policy.upper_values, policy.upper_values);
  // A state in the cell [0.05, 0.1] (index 8) gets that cell's value.
  const double state[] = {0.07};
  double input = 0, probability = -1;
  ASSERT_EQ(loaded.policy.lookup(state, 1, 0, &input, &probability), LookupStatus::Ok);
  EXPECT_EQ(probability, policy.value(0, 8));
  // Without its faces a grid given by them cannot be read: refused, not guessed.
  remove_faces(path("faces.h5"));
  EXPECT_NE(test_support::refusal([&] { read_policy_file(path("faces.h5")); }).find("faces"), std::string::npos);
}

TEST_F(RectilinearFile, FileWithoutFacesStillReads) {
  const Config config = config_from_yaml(with_states("{lb: [-1], ub: [1], eta: [0.1]}"));
  const Policy policy = synthesize(Abstraction::from_config(config), {}, nullptr);
  write_policy_file(path("old.h5"), policy, config);
  remove_faces(path("old.h5"));
  const LoadedPolicy loaded = read_policy_file_for(path("old.h5"), config);
  EXPECT_TRUE(loaded.policy.states.uniform(0));
  EXPECT_EQ(loaded.policy.values, policy.values);
  EXPECT_EQ(loaded.policy.states.faces(0), policy.states.faces(0));
}

}  // namespace
}  // namespace amytiss

// The command-line tool amytiss_synth, run as a process on the tiny configurations of test/data:
// its output lines, exit codes, the file it writes, and that Python's h5py opens that file.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/format.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/policy_file.hpp"
#include "cli_support.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;
using test_support::CliTest;
using test_support::CommandResult;
using test_support::kSynth;
using test_support::quote;
using test_support::kTinyConfig;

const std::string kSourceDir = AMYTISS_SOURCE_DIR;
const std::string kBadEtaConfig = kSourceDir + "/test/data/cli_bad_eta.yaml";
// cli_tiny.yaml: 9 x 9 states, 3 x 3 inputs, horizon 4.
constexpr std::size_t kTinyStates = 81, kTinyInputs = 9;
// Two runs of the same engine on the same problem agree exactly.
constexpr double kSameEngineTolerance = 0.0;

ComputeOverrides system_override() {
  ComputeOverrides overrides;
  overrides.guarantee = "system";
  return overrides;
}

TEST_F(CliTest, HelpListsEveryOption) {
  const CommandResult result = synth("--help");
  EXPECT_EQ(0, result.exit_code) << result.err;
  for (const char* option : {"--config", "--device", "--transitions", "--platform", "--output",
                             "--profile", "--compare-reference", "--list-devices", "--quiet", "--export",
                             "--export-max-transitions", "--guarantee", "--at"})
    EXPECT_CONTAINS(result.out, option);
}

TEST_F(CliTest, SynthesizesTheTinyProblemAndPrintsEachPart) {
  const CommandResult result =
      synth("--config " + quote(kTinyConfig) + " --device reference --output tiny.h5");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_EQ("", result.err);
  EXPECT_CONTAINS(result.out, "grid: states 81 (9 x 9), inputs 9 (3 x 3), disturbances 1");
  EXPECT_CONTAINS(result.out, "state-input pairs: 729");
  EXPECT_CONTAINS(result.out, "estimated memory: policy arrays");
  EXPECT_CONTAINS(result.out, "stored transitions");
  for (int step = 1; step <= 4; ++step)
    EXPECT_CONTAINS(result.out, "step " + std::to_string(step) + "/4");
  EXPECT_CONTAINS(result.out, "on reference");
  EXPECT_CONTAINS(result.out, "config + abstraction");
  EXPECT_CONTAINS(result.out, "synthesis (4 steps)");
  EXPECT_CONTAINS(result.out, "file write");
  EXPECT_CONTAINS(result.out, "V_0 over");
  EXPECT_CONTAINS(result.out, "wrote tiny.h5");

  const LoadedPolicy loaded = read_policy_file_for(path("tiny.h5"), load_config_file(kTinyConfig));
  EXPECT_EQ(kTinyStates, loaded.policy.states.size());
  EXPECT_EQ(kTinyInputs, loaded.policy.inputs.size());
  EXPECT_EQ(4u, loaded.policy.horizon);
  EXPECT_EQ("reference", loaded.policy.computed_by);
}

// --dry-run prints the plan of any engine: here auto's choice of the serial engine and why.
TEST_F(CliTest, DryRunPrintsThePlanWithTheReasonsAndWritesNothing) {
  const CommandResult result = synth("--config " + quote(kTinyConfig) + " --device auto --dry-run --output plan.h5");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.out, "plan: engine: reference (serial, double precision)");
  EXPECT_CONTAINS(result.out, "plan: device auto: the serial reference engine (planned work ");
  EXPECT_FALSE(fs::exists(path("plan.h5")));
}

TEST_F(CliTest, QuietOmitsTheProgressLines) {
  const CommandResult result =
      synth("--config " + quote(kTinyConfig) + " --device reference --quiet");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_EQ(std::string::npos, result.out.find("step 1/4")) << result.out;
  EXPECT_CONTAINS(result.out, "V_0 over");
}

TEST_F(CliTest, DefaultOutputIsTheConfigurationNameInTheCurrentDirectory) {
  const CommandResult result =
      synth("--config " + quote(kTinyConfig) + " --device reference --quiet");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_TRUE(fs::exists(path("cli_tiny.h5")));
}

TEST_F(CliTest, ProfilePrintsThePhaseTable) {
  const CommandResult result =
      synth("--config " + quote(kTinyConfig) + " --device reference --quiet --profile");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.out, "profile (reference)");
  EXPECT_CONTAINS(result.out, "GMAC/s");
  EXPECT_CONTAINS(result.out, "step 0");
  EXPECT_CONTAINS(result.out, "host peak (VmHWM)");
}

// On an OpenCL device the profile measures the memory and cache bandwidths and prints the
// roofline of the steps and of each stage.
TEST_F(CliTest, ProfileOnADevicePrintsTheMeasuredBandwidthsAndTheRoofline) {
  const CommandResult result = synth("--config " + quote(kTinyConfig) + " --device cpu --quiet --profile");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.out, "GB/s measured: copy of ");
  EXPECT_CONTAINS(result.out, "cache bandwidth ");
  const std::size_t roofline = result.out.find("roofline (peak ");
  ASSERT_NE(std::string::npos, roofline) << result.out;
  for (const std::string row : {"time steps (4) ", "stage 0 (x'0, all steps) "}) {
    const std::size_t at = result.out.find(row, roofline);
    ASSERT_NE(std::string::npos, at) << row << "\n" << result.out;
    const std::string line = result.out.substr(at, result.out.find('\n', at) - at);
    EXPECT_TRUE(line.find(" memory ") != std::string::npos || line.find(" cache ") != std::string::npos ||
                line.find(" compute ") != std::string::npos)
        << line;
  }
}

TEST_F(CliTest, CompareReferencePrintsSpeedUpAndDifference) {
  const CommandResult result = synth("--config " + quote(kTinyConfig) +
                                     " --device reference --quiet --compare-reference");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.out, "speed-up");
  const std::string marker = "max |dV_0| (engine - reference): ";
  const std::size_t at = result.out.find(marker);
  ASSERT_NE(std::string::npos, at) << result.out;
  EXPECT_LE(std::stod(result.out.substr(at + marker.size())), kSameEngineTolerance);
}

// The paper's a-priori error beside the abstraction's values: 4.7e+02 on the tiny problem (T 4,
// H 1.08, L(A) 77, delta 1.41): vacuous.
TEST_F(CliTest, PrintsThePapersAprioriError) {
  const CommandResult result = synth("--config " + quote(kTinyConfig) + " --device reference --quiet");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_CONTAINS(result.out, "a-priori error of the abstraction (paper's bound): 4.7e+02, vacuous: T 4 x H ");
}

// An unbounded specification's policy has upper bounds: --compare-reference reports the largest
// difference of each bound (the same engine twice: none).
TEST_F(CliTest, CompareReferenceComparesBothBoundsOfAnUnboundedPolicy) {
  std::ifstream tiny(kTinyConfig);
  std::stringstream text;
  text << tiny.rdbuf();
  std::string yaml = text.str();
  const std::string horizon = "horizon: 4";
  ASSERT_NE(yaml.find(horizon), std::string::npos);
  yaml.replace(yaml.find(horizon), horizon.size(), "horizon: infinite");
  std::ofstream(path("tiny_unbounded.yaml")) << yaml;
  const CommandResult result =
      synth("--config " + quote(path("tiny_unbounded.yaml")) + " --device reference --quiet --compare-reference");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.out, "paper's bound): inf, vacuous");
  for (const std::string marker :
       {"max |d lower V_0| (engine - reference): ", "max |d upper V_0| (engine - reference): "}) {
    const std::size_t at = result.out.find(marker);
    ASSERT_NE(std::string::npos, at) << result.out;
    EXPECT_LE(std::stod(result.out.substr(at + marker.size())), kSameEngineTolerance) << marker;
  }
}

// guarantee: system prints both bounds, their gap and, with --compare-reference, how far each bound
// is from the reference engine's (the joint interval MDP); its memory estimate holds no stored
// transitions.
TEST_F(CliTest, SystemGuaranteePrintsBothBoundsAndComparesThem) {
  std::ifstream tiny(kTinyConfig);
  std::stringstream text;
  text << tiny.rdbuf() << "guarantee: system\n";
  std::ofstream(path("tiny_system.yaml")) << text.str();
  const CommandResult result = synth("--config " + quote(path("tiny_system.yaml")) +
                                     " --device reference --quiet --compare-reference --output system.h5");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  const LoadedPolicy loaded = read_policy_file_for(path("system.h5"), load_config_file(path("tiny_system.yaml")));
  ASSERT_EQ(loaded.policy.guarantee, Guarantee::System) << "the engine computed no continuous-system bounds";
  for (const char* line :
       {"continuous-system bounds over", "lower (V_0, this policy) min", "upper (any controller)   min",
        "gap (upper - lower)      min", "a-priori error of the abstraction (paper's bound): ",
        "max |d lower V_0| (engine - reference): ", "max |d upper V_0| (engine - reference): ",
        "(lower and upper bounds), bounds engine ", "in all, no stored transitions"})
    EXPECT_CONTAINS(result.out, line);
  EXPECT_EQ(result.out.find("bytes per triple"), std::string::npos) << "the bounds store no transitions";
}

// The number after `label` in the output, or NaN.
double number_after(const std::string& out, const std::string& label) {
  const std::size_t at = out.find(label);
  return at == std::string::npos ? std::nan("") : std::stod(out.substr(at + label.size()));
}

// --at prints the values of the state's cell as the written policy holds them, and its input.
TEST_F(CliTest, AtPrintsTheValuesOfTheStatesCell) {
  constexpr double kPrintedRounding = 5e-7;  // six decimals
  const std::vector<double> state = {-2.2, 1.1};
  CommandResult result = synth("--config " + quote(kTinyConfig) + " --quiet --output tiny.h5 --at -2.2,1.1");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  LoadedPolicy loaded = read_policy_file_for(path("tiny.h5"), load_config_file(kTinyConfig));
  std::vector<double> input(2);
  double lower = 0.0, upper = 0.0;
  ASSERT_EQ(loaded.policy.lookup(state.data(), state.size(), 0, input.data(), &lower, &upper), LookupStatus::Ok);
  EXPECT_NEAR(number_after(result.out, "at [-2.2, 1.1]: V_0 "), lower, kPrintedRounding) << result.out;
  EXPECT_CONTAINS(result.out, "input [" + format_number(input[0]) + ", " + format_number(input[1]) + "]");

  // --guarantee system: the certified lower bound and the upper bound of the same cell.
  result = synth("--config " + quote(kTinyConfig) + " --quiet --guarantee system --output system.h5 --at -2.2,1.1");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  loaded = read_policy_file_for(path("system.h5"), load_config_file(kTinyConfig, system_override()));
  ASSERT_EQ(loaded.policy.guarantee, Guarantee::System);
  ASSERT_EQ(loaded.policy.lookup(state.data(), state.size(), 0, input.data(), &lower, &upper), LookupStatus::Ok);
  ASSERT_LT(lower, upper) << "a cell whose bounds differ shows that each is read from its own array";
  EXPECT_NEAR(number_after(result.out, "at [-2.2, 1.1]: certified lower bound "), lower, kPrintedRounding);
  EXPECT_NEAR(number_after(result.out, "(this policy), upper bound "), upper, kPrintedRounding) << result.out;
}

// A state of the wrong length or outside the grid, or an unknown guarantee, is refused before
// anything is computed (exit status 2, no file).
TEST_F(CliTest, BadStatesAndGuaranteesExitTwoBeforeComputing) {
  const std::string base = "--config " + quote(kTinyConfig) + " --quiet --output refused.h5 ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--at 1", "--at: got 1 values, expected 2, one per state dimension (x0 to x1)"},
      {"--at 1,x", "--at: got '1,x', expected the state's values separated by commas"},
      {"--at 9,0", "--at: the state [9, 0] lies outside the grid"},
      {"--guarantee certified", "--guarantee: got 'certified', expected one of"}};
  for (const auto& [arguments, message] : cases) {
    const CommandResult result = synth(base + arguments);
    EXPECT_EQ(2, result.exit_code) << arguments;
    EXPECT_CONTAINS(result.err, message);
    EXPECT_FALSE(fs::exists(path("refused.h5"))) << arguments;
  }
}

TEST_F(CliTest, BadConfigurationExitsTwoNamingTheKey) {
  const CommandResult result = synth("--config " + quote(kBadEtaConfig));
  EXPECT_EQ(2, result.exit_code) << result.out << result.err;
  EXPECT_EQ(0u, result.err.rfind("error: ", 0)) << result.err;
  EXPECT_CONTAINS(result.err, "states.eta");
  EXPECT_FALSE(fs::exists(path("cli_bad_eta.h5")));
}

TEST_F(CliTest, MissingConfigurationFileExitsTwo) {
  const CommandResult result = synth("--config " + quote(path("absent.yaml")));
  EXPECT_EQ(2, result.exit_code);
  EXPECT_CONTAINS(result.err, "error: ");
  EXPECT_CONTAINS(result.err, "absent.yaml");
}

// A device request the machine cannot honour is refused with exit status 1, naming the devices.
TEST_F(CliTest, AnAbsentDeviceKindExitsOneNamingTheDevices) {
  const CommandResult devices = synth("--list-devices");
  if (devices.out.find("(GPU") != std::string::npos) GTEST_SKIP() << "a GPU is present";
  const CommandResult result = synth("--config " + quote(kTinyConfig) + " --device gpu --quiet");
  EXPECT_EQ(1, result.exit_code);
  EXPECT_CONTAINS(result.err, "compute.device: got gpu, but no OpenCL gpu device");
  EXPECT_CONTAINS(result.err, "devices present");
}

TEST_F(CliTest, BadOptionsExitTwo) {
  CommandResult result = synth("--config " + quote(kTinyConfig) + " --device tpu");
  EXPECT_EQ(2, result.exit_code);
  EXPECT_CONTAINS(result.err, "error: --device: got 'tpu'");
  result = synth("--frobnicate");
  EXPECT_EQ(2, result.exit_code);
  EXPECT_CONTAINS(result.err, "unknown option '--frobnicate'");
  result = synth("--device reference");
  EXPECT_EQ(2, result.exit_code);
  EXPECT_CONTAINS(result.err, "--config FILE is required");
}

TEST_F(CliTest, ExportWritesTheModelOrRefusesItAboveTheLimit) {
  CommandResult result = synth("--config " + quote(kTinyConfig) + " --export prism model");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  // 73 free cells x 9 inputs, 8 fixed cells and the sink with one choice each.
  EXPECT_CONTAINS(result.out, "exported prism: 82 states, 666 choices");
  for (const char* file : {"model/model.tra", "model/model.sta", "model/model.lab", "model/README.md"})
    EXPECT_TRUE(fs::exists(path(file))) << file;
  EXPECT_FALSE(fs::exists(path("cli_tiny.h5"))) << "an export does not synthesize";
  result = synth("--config " + quote(kTinyConfig) + " --export drn drn");
  ASSERT_EQ(0, result.exit_code) << result.err;
  EXPECT_TRUE(fs::exists(path("drn/model.drn")));
  result = synth("--config " + quote(kTinyConfig) + " --export drn small --export-max-transitions 100");
  EXPECT_EQ(2, result.exit_code);
  EXPECT_CONTAINS(result.err, "more than the limit 100");
  EXPECT_FALSE(fs::exists(path("small")));
  result = synth("--config " + quote(kTinyConfig) + " --export json out");
  EXPECT_EQ(2, result.exit_code);
  EXPECT_CONTAINS(result.err, "--export: got 'json', expected prism or drn");
  result = synth("--config " + quote(kTinyConfig) + " --export prism out --export-max-transitions lots");
  EXPECT_EQ(2, result.exit_code);
  EXPECT_CONTAINS(result.err, "--export-max-transitions: got 'lots'");
  // The export is the centre-point abstraction: not what guarantee: system's bounds are about.
  result = synth("--config " + quote(kTinyConfig) + " --guarantee system --export drn system");
  EXPECT_EQ(2, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.err, "guarantee: got system");
  EXPECT_FALSE(fs::exists(path("system")));
}

TEST_F(CliTest, UnwritableOutputExitsOne) {
  const CommandResult result = synth("--config " + quote(kTinyConfig) +
                                     " --device reference --quiet --output " +
                                     quote(path("no/such/directory/p.h5")));
  EXPECT_EQ(1, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.err, "error: cannot write policy file");
}

TEST_F(CliTest, ListDevicesExitsZero) {
  const CommandResult result = synth("--list-devices");
  EXPECT_EQ(0, result.exit_code) << result.err;
  EXPECT_FALSE(result.out.empty());
}

TEST_F(CliTest, PythonH5pyOpensTheFileWithTheDocumentedLayout) {
  ASSERT_EQ(0, synth("--config " + quote(kTinyConfig) + " --device reference --quiet "
                     "--output tiny.h5").exit_code);
  const CommandResult result = run_in_directory(
      "/usr/bin/python3 " + quote(kSourceDir + "/scripts/inspect_policy.py") + " tiny.h5");
  ASSERT_EQ(0, result.exit_code) << result.out << result.err;
  EXPECT_CONTAINS(result.out, "attribute format = amytiss-policy");
  EXPECT_CONTAINS(result.out, "attribute format_version = 2");
  EXPECT_CONTAINS(result.out, "attribute engine_version = 1");
  EXPECT_CONTAINS(result.out, "attribute run_id = ");
  EXPECT_CONTAINS(result.out, "attribute content_digest = ");
  EXPECT_CONTAINS(result.out,
                  "attribute config_hash = " + config_hash(load_config_file(kTinyConfig)));
  EXPECT_CONTAINS(result.out, "attribute horizon = 4");
  EXPECT_CONTAINS(result.out, "attribute spec = reach_avoid");
  EXPECT_CONTAINS(result.out, "dataset /config string ()");
  // Every array carries HDF5's Fletcher-32 checksum, which h5py verifies too; the large ones are
  // compressed, and 9 inputs take uint8 indices.
  EXPECT_CONTAINS(result.out, "dataset /values float64 (5, 9, 9) shuffle gzip(1) fletcher32");
  EXPECT_CONTAINS(result.out, "dataset /input_index uint8 (4, 9, 9) shuffle gzip(1) fletcher32");
  EXPECT_CONTAINS(result.out, "dataset /input_values float64 (9, 2) fletcher32");
  EXPECT_CONTAINS(result.out, "dataset /roles uint8 (9, 9) shuffle gzip(1) fletcher32");
  for (const char* grid : {"states", "inputs"}) {
    EXPECT_CONTAINS(result.out, std::string("dataset /") + grid + "/lb float64 (2,)");
    EXPECT_CONTAINS(result.out, std::string("dataset /") + grid + "/eta float64 (2,)");
    EXPECT_CONTAINS(result.out, std::string("dataset /") + grid + "/counts uint64 (2,)");
  }
  EXPECT_CONTAINS(result.out, "config first line: ");
}

}  // namespace
}  // namespace amytiss

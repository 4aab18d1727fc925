#pragma once
// amytiss_synth's command line: its options, their parsing and the usage text.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace amytiss::cli {

/// The usage text of --help.
extern const char* const kUsage;

// Bad command-line input; reported like a configuration error (exit status 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The seed of --simulate when --seed is not given.
constexpr std::uint64_t kDefaultSimulationSeed = 1;

struct Options {
  std::string config_path;
  std::string device;       // empty: the configuration's
  std::string transitions;  // empty: the configuration's
  std::string sweep;        // empty: the configuration's
  std::string bounds_method;  // empty: the configuration's
  std::string platform;
  std::string devices;      // empty: the configuration's
  std::string guarantee;    // empty: the configuration's
  std::vector<double> at;   // a state whose values to print after the synthesis; empty: none
  double refine_gap = 0;    // --refine: refine at --at's state until this gap; 0: the configuration's refine
  std::size_t simulate = 0;   // episodes of the closed loop from --at's cell; 0: none
  std::uint64_t seed = kDefaultSimulationSeed;  // of --simulate
  bool seed_given = false;
  std::string output;
  std::string export_format;  // empty: no export
  std::string export_directory;
  std::size_t export_max_transitions = 10000000;
  bool dry_run = false;
  bool profile = false;
  bool compare_reference = false;
  bool list_devices = false;
  bool quiet = false;
  bool help = false;
};

/// The options of argv; UsageError for an unknown option, a missing value, a missing --config, or
/// --simulate without --at, with a count of 0 or above kMaxSimulatedEpisodes (closed_loop.hpp).
Options parse_options(int argc, char** argv);

}  // namespace amytiss::cli

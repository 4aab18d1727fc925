#include "options.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <utility>
#include <vector>

#include "amytiss/closed_loop.hpp"

namespace amytiss::cli {

const char* const kUsage =
    "usage: amytiss_synth --config FILE [options]\n"
    "\n"
    "Synthesizes a controller (policy) for the configuration's specification and writes it as\n"
    "an HDF5 policy file (docs/policy_file.md).\n"
    "\n"
    "options:\n"
    "  --config FILE                      YAML configuration (docs/configuration.md)\n"
    "  --device auto|cpu|gpu|reference    overrides compute.device\n"
    "  --transitions auto|stored|on_the_fly  overrides compute.transitions\n"
    "  --sweep auto|dense|factored        overrides compute.sweep (docs/engine.md)\n"
    "  --bounds-method auto|whole_tables|elimination|rows|joint\n"
    "                                     overrides compute.bounds_method (guarantee: system; docs/engine.md)\n"
    "  --platform NAME|INDEX              OpenCL platform/device: 0-based index or name substring\n"
    "  --devices all|LIST                 overrides compute.devices: several devices, comma-separated\n"
    "                                     (gpu:0,gpu:1; cpu:0/1 splits the CPU device; docs/scale_out.md)\n"
    "  --guarantee abstraction|system     overrides guarantee (system: bounds for the continuous system)\n"
    "  --at X0,X1,...                     print the policy's values at this state (step 0) and its input\n"
    "  --refine GAP                       with --at: refine the grid until upper - lower <= GAP at that\n"
    "                                     state (refine: {at: [--at], gap: GAP}, guarantee: system;\n"
    "                                     docs/refinement.md); replaces the configuration's refine\n"
    "  --simulate N                       with --at: N episodes of the continuous closed loop from uniform\n"
    "                                     points of that state's cell; prints the success rate beside the values\n"
    "  --seed S                           seed of --simulate (default 1; the same seed, the same rate)\n"
    "  --dry-run                          print the plan (engine, devices, sweep, work split), compute nothing\n"
    "  --output FILE                      policy file to write (default: <name>.h5 here)\n"
    "  --profile                          per-phase timing, rates and memory table\n"
    "  --compare-reference                also run the serial reference engine and compare V_0\n"
    "  --export prism|drn DIR             write the finite abstraction (PRISM explicit files or Storm\n"
    "                                     DRN, with a README) into DIR and exit (docs/export.md)\n"
    "  --export-max-transitions N         refuse to export more transitions (default 10000000)\n"
    "  --list-devices                     list the OpenCL devices and exit\n"
    "  --quiet                            no progress lines\n"
    "  --help                             this text\n"
    "\n"
    "Under mpirun (a build with MPI) the ranks split the synthesis; rank 0 prints and writes the file.\n"
    "\n"
    "exit status: 0 success, 2 bad input (configuration or options), 1 other failures\n";


namespace {

// "0.25,0.5,1.47" -> {0.25, 0.5, 1.47}; UsageError for an item that is not a finite number.
std::vector<double> parse_state(const std::string& text) {
  std::vector<double> state;
  // getline drops an empty last item: "1,1," would pass as "1,1".
  if (!text.empty() && text.back() == ',')
    throw UsageError("--at: got '" + text + "', expected the state's values separated by commas, without a comma "
                     "at the end (example: --at 0.25,0.5,1.47)");
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(value))
      throw UsageError("--at: got '" + text + "', expected the state's values separated by commas (example: --at "
                       "0.25,0.5,1.47)");
    state.push_back(value);
  }
  if (state.empty()) throw UsageError("--at: got no values, expected the state's values (example: --at 0.25,0.5,1.47)");
  return state;
}

// A whole number in [minimum, maximum] for `option`; UsageError naming the option, the text and
// `example` otherwise.
std::uint64_t parse_count(const std::string& option, const std::string& text, std::uint64_t minimum,
                          std::uint64_t maximum, const std::string& example) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
  const bool whole = !text.empty() && std::isdigit(static_cast<unsigned char>(text[0])) && *end == '\0' && errno == 0;
  if (!whole || value < minimum || value > maximum)
    throw UsageError(option + ": got '" + text + "', expected a whole number from " + std::to_string(minimum) +
                     " to " + std::to_string(maximum) + " (example: " + option + " " + example + ")");
  return value;
}

// --refine's gap: a number in (0, 1).
double parse_gap(const std::string& text) {
  char* end = nullptr;
  const double gap = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(gap > 0 && gap < 1))
    throw UsageError("--refine: got '" + text + "', expected a gap in (0, 1) (example: --at -8,-8 --refine 0.05)");
  return gap;
}

// --simulate runs from --at's cell after a synthesis; --seed only seeds it.
void check_simulation(const Options& options) {
  if (options.simulate && options.at.empty())
    throw UsageError("--simulate: got " + std::to_string(options.simulate) +
                     " episodes without --at, expected the state whose cell the episodes start from (example: "
                     "--at -8,-8 --simulate 1000)");
  if (options.simulate && options.dry_run)
    throw UsageError("--simulate: got it with --dry-run, expected a synthesis to simulate: a dry run computes no "
                     "policy (example: --at -8,-8 --simulate 1000)");
  if (options.refine_gap > 0 && options.at.empty())
    throw UsageError("--refine: got it without --at, expected the state whose gap decides (example: --at -8,-8 "
                     "--refine 0.05)");
  if (options.seed_given && !options.simulate)
    throw UsageError("--seed: got " + std::to_string(options.seed) +
                     " without --simulate, expected it with the episodes it seeds (example: --at -8,-8 --simulate "
                     "1000 --seed 7)");
}

// An export writes the abstraction and exits: the options of a synthesis would be ignored.
void check_export_alone(const Options& options) {
  if (options.export_format.empty()) return;
  const std::pair<bool, const char*> synthesis_options[] = {{options.dry_run, "--dry-run"},
                                                            {!options.at.empty(), "--at"},
                                                            {options.simulate > 0, "--simulate"},
                                                            {options.refine_gap > 0, "--refine"},
                                                            {!options.output.empty(), "--output"},
                                                            {options.profile, "--profile"},
                                                            {options.compare_reference, "--compare-reference"}};
  for (const auto& [given, name] : synthesis_options)
    if (given)
      throw UsageError(std::string("--export: got it with ") + name +
                       ", expected --export without the options of a synthesis (--dry-run, --at, --simulate, "
                       "--output, --profile, --compare-reference): an export writes the abstraction and computes no "
                       "policy (example: --config c.yaml --export prism out/)");
}

}  // namespace

Options parse_options(int argc, char** argv) {
  Options options;
  const std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError(arg + " needs a value (see --help)");
      return args[++i];
    };
    if (arg == "--config") options.config_path = value();
    else if (arg == "--device") options.device = value();
    else if (arg == "--transitions") options.transitions = value();
    else if (arg == "--sweep") options.sweep = value();
    else if (arg == "--bounds-method") options.bounds_method = value();
    else if (arg == "--platform") options.platform = value();
    else if (arg == "--devices") options.devices = value();
    else if (arg == "--guarantee") options.guarantee = value();
    else if (arg == "--at") options.at = parse_state(value());
    else if (arg == "--refine") options.refine_gap = parse_gap(value());
    else if (arg == "--simulate")
      options.simulate = parse_count("--simulate", value(), 1, kMaxSimulatedEpisodes, "1000");
    else if (arg == "--seed") {
      options.seed = parse_count("--seed", value(), 0, UINT64_MAX, "7");
      options.seed_given = true;
    } else if (arg == "--dry-run") options.dry_run = true;
    else if (arg == "--output" || arg == "-o") options.output = value();
    else if (arg == "--export") {
      options.export_format = value();
      options.export_directory = value();
      if (options.export_format != "prism" && options.export_format != "drn")
        throw UsageError("--export: got '" + options.export_format + "', expected prism or drn (example: --export "
                         "prism out/)");
    } else if (arg == "--export-max-transitions") {
      const std::string text = value();
      char* end = nullptr;
      const unsigned long long limit = std::strtoull(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || text[0] == '-')
        throw UsageError("--export-max-transitions: got '" + text + "', expected a whole number (example: 50000000)");
      options.export_max_transitions = std::size_t(limit);
    }
    else if (arg == "--profile") options.profile = true;
    else if (arg == "--compare-reference") options.compare_reference = true;
    else if (arg == "--list-devices") options.list_devices = true;
    else if (arg == "--quiet" || arg == "-q") options.quiet = true;
    else if (arg == "--help" || arg == "-h") options.help = true;
    else throw UsageError("unknown option '" + arg + "' (see --help)");
  }
  check_export_alone(options);
  check_simulation(options);
  if (!options.help && !options.list_devices && options.config_path.empty())
    throw UsageError("--config FILE is required (example: --config config/robot_safety.yaml)");
  return options;
}

}  // namespace amytiss::cli

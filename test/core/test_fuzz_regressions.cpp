// Replays the fuzzer's seed corpus (test/fuzz/corpus) and every kept crash input
// (test/fuzz/regressions) through the same function the libFuzzer target runs (scripts/fuzz):
// each must be refused or accepted, never crash or throw anything but the core's errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../fuzz/fuzz_one_input.hpp"

namespace amytiss {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> files_in(const std::string& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(std::string(AMYTISS_SOURCE_DIR) + "/test/fuzz/" + folder))
    if (entry.is_regular_file()) files.push_back(entry.path());
  return files;
}

void replay(const std::vector<fs::path>& files) {
  for (const auto& file : files) {
    std::ifstream stream(file, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
    SCOPED_TRACE(file.filename().string());
    EXPECT_NO_THROW(fuzz_one_input(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
  }
}

TEST(FuzzRegressions, SeedCorpus) {
  const auto files = files_in("corpus");
  EXPECT_GE(files.size(), 20u);
  replay(files);
}

TEST(FuzzRegressions, KeptCrashers) {
  const auto files = files_in("regressions");
  EXPECT_GE(files.size(), 4u);
  replay(files);
}

}  // namespace
}  // namespace amytiss

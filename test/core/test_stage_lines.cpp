// The lines of the variable elimination's stages (bounds/product/stage_lines.hpp): counted line by line, the
// cursor meets every line once, and with the free digits' combinations every output entry once;
// found from a line's first input entry, it names the same line; the combinations' order counts
// inputs and disturbances slowest.
#include <gtest/gtest.h>

#include <algorithm>

#include "bounds/product/elimination.hpp"
#include "bounds/product/stage_lines.hpp"
#include "test_support.hpp"

namespace amytiss::detail {
namespace {

using namespace amytiss::test_support;

// Three coordinates that read two or three components each, one of them an input and one a
// disturbance, on grids of different sizes.
const char* kSparse3d =
    "name: sparse_3d\n"
    "states: {lb: [-1, -1, -1], ub: [1, 1, 1], eta: [0.25, 0.5, 0.4]}\n"
    "inputs: {lb: [-0.2], ub: [0.2], eta: [0.2]}\n"
    "disturbances: {lb: [-0.05], ub: [0.05], eta: [0.1]}\n"
    "dynamics: [\"0.9*x0 + 0.05*x2 + u0\", \"0.9*x1 + 0.1*x0 + w0\", \"0.8*x2 + 0.1*x1 + u0\"]\n"
    "noise: {type: additive, distribution: normal, covariance: [0.02, 0.03, 0.05]}\n"
    "spec: {type: safety, horizon: 2}\nguarantee: system\n";

// Each output digit's value in an output offset (digits major to minor, as stage.output).
std::vector<std::size_t> digits_of(const FactoredStage& stage, std::size_t offset) {
  std::vector<std::size_t> digits(stage.output.size());
  for (std::size_t j = stage.output.size(); j-- > 0;) {
    digits[j] = offset % stage.output[j].radix;
    offset /= stage.output[j].radix;
  }
  return digits;
}

class StageLines : public ::testing::Test {
 protected:
  const Abstraction a = from_yaml(kSparse3d);
  std::string reason;
  const std::optional<FactoredPlan> plan = RobustFactoredSweep::plan(a, &reason);
};

TEST_F(StageLines, TheCursorMeetsEveryLineAndEveryOutputEntryOnce) {
  ASSERT_TRUE(plan) << reason;
  for (const FactoredStage& stage : plan->stages) {
    const StageWalk walk = StageWalk::of(stage, plan->variables);
    std::size_t lines = 1;
    for (const StageWalk::Carried& digit : walk.carried) lines *= digit.radix;
    ASSERT_EQ(lines * walk.free_offsets.size(), stage.output_size);
    std::vector<int> written(stage.output_size, 0);
    LineCursor cursor(walk.carried), found(walk.carried);
    cursor.seek(0);
    for (std::size_t line = 0; line < lines; ++line, cursor.next()) {
      found.seek_input(cursor.input);
      ASSERT_EQ(found.output, cursor.output) << "stage of dimension " << stage.dimension << " line " << line;
      ASSERT_EQ(found.tuple, cursor.tuple) << "stage of dimension " << stage.dimension << " line " << line;
      ASSERT_EQ(found.digits, cursor.digits) << "stage of dimension " << stage.dimension << " line " << line;
      LineCursor sought(walk.carried);
      sought.seek(line);
      ASSERT_EQ(sought.input, cursor.input);
      for (std::size_t offset : walk.free_offsets) ++written[cursor.output + offset];
    }
    EXPECT_TRUE(std::all_of(written.begin(), written.end(), [](int count) { return count == 1; }))
        << "stage of dimension " << stage.dimension;
  }
}

TEST_F(StageLines, CombinationsCountInputsAndDisturbancesSlowest) {
  ASSERT_TRUE(plan) << reason;
  bool met_a_free_input = false;
  for (const FactoredStage& stage : plan->stages) {
    const StageWalk walk = StageWalk::of(stage, plan->variables);
    std::vector<std::uint32_t> sorted = walk.free_order;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i) << "a permutation";
    // Along the order, the input and disturbance digits never fall back: they change only where
    // every other free digit has run through its values.
    std::vector<std::size_t> last;
    for (std::uint32_t combination : walk.free_order) {
      const std::vector<std::size_t> digits = digits_of(stage, walk.free_offsets[combination]);
      std::vector<std::size_t> jump_digits;
      for (std::size_t j = 0; j < stage.output.size(); ++j) {
        const TensorDigit& digit = stage.output[j];
        const bool jumps = !digit.post && plan->variables[digit.id].space != FactorVariable::Space::State;
        if (jumps && !stage.input_stride[j]) {
          jump_digits.push_back(digits[j]);
          met_a_free_input = met_a_free_input || digit.radix > 1;
        }
      }
      ASSERT_TRUE(last.empty() || last <= jump_digits) << "stage of dimension " << stage.dimension;
      last = jump_digits;
    }
  }
  EXPECT_TRUE(met_a_free_input) << "a stage with an input or disturbance among its free digits";
}

}  // namespace
}  // namespace amytiss::detail

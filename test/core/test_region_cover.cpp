// Whether a cell lies inside a union of boxes (model/box_cover.hpp), as the continuous-system
// bounds' cell roles ask it: the same answers as a straightforward exact recursion on random small
// unions, and unions of many boxes in 30 dimensions decided in a fraction of a second.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "bounds/cell_roles.hpp"
#include "model/box_cover.hpp"
#include "test_support.hpp"

namespace amytiss {
namespace {

using namespace test_support;
using detail::Bound;
using detail::box_covered;

constexpr std::uint64_t kSeed = 20261203;
constexpr double kSlack = 1e-9;
// Face perturbations well inside the slack: both methods read them as on the face.
constexpr double kPerturbation = 2.5e-10;
// A union of 14 boxes in 30 dimensions is decided within this (the old recursion: many seconds).
constexpr double kFastSeconds = 0.5;

bool overlaps(const std::vector<double>& lo, const std::vector<double>& hi, const Box& box,
              const std::vector<double>& slack) {
  for (std::size_t d = 0; d < lo.size(); ++d)
    if (hi[d] <= box.lb[d] + slack[d] || lo[d] >= box.ub[d] - slack[d]) return false;
  return true;
}

// The recursion the cell roles used before: the first box that overlaps covers the middle, the
// slabs sticking out of it must lie in the union of the later boxes. Exact, exponential in boxes.
bool reference_covered(std::vector<double> lo, std::vector<double> hi, const std::vector<Box>& boxes,
                       std::size_t first, const std::vector<double>& slack) {
  std::size_t i = first;
  while (i < boxes.size() && !overlaps(lo, hi, boxes[i], slack)) ++i;
  if (i == boxes.size()) return false;
  const Box& box = boxes[i];
  for (std::size_t d = 0; d < lo.size(); ++d) {
    if (lo[d] < box.lb[d] - slack[d]) {
      std::vector<double> slab_hi = hi;
      slab_hi[d] = box.lb[d];
      if (!reference_covered(lo, slab_hi, boxes, i + 1, slack)) return false;
      lo[d] = box.lb[d];
    }
    if (hi[d] > box.ub[d] + slack[d]) {
      std::vector<double> slab_lo = lo;
      slab_lo[d] = box.ub[d];
      if (!reference_covered(slab_lo, hi, boxes, i + 1, slack)) return false;
      hi[d] = box.ub[d];
    }
  }
  return true;
}

TEST(RegionCover, AgreesWithTheExactRecursionOnRandomSmallUnions) {
  std::mt19937_64 random(kSeed);
  auto pick = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random); };
  auto jitter = [&] { return std::uniform_real_distribution<double>(-kPerturbation, kPerturbation)(random); };
  std::size_t inside = 0, trials = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const std::size_t dims = std::size_t(pick(1, 4)), boxes_count = std::size_t(pick(1, 6));
    // The cell [0, 2]^dims; faces on the half-integers -1 .. 3, some moved within the slack.
    std::vector<double> lo(dims, 0.0), hi(dims, 2.0), slack(dims, kSlack);
    std::vector<Box> boxes;
    for (std::size_t b = 0; b < boxes_count; ++b) {
      Box box;
      for (std::size_t d = 0; d < dims; ++d) {
        const int a = pick(-2, 5), c = pick(-2, 5);
        box.lb.push_back(0.5 * std::min(a, c) + (trial % 2 ? jitter() : 0.0));
        box.ub.push_back(0.5 * std::max(a, c) + 0.5 + (trial % 2 ? jitter() : 0.0));
      }
      boxes.push_back(box);
    }
    const std::optional<bool> covered = box_covered(lo, hi, boxes, slack);
    ASSERT_TRUE(covered.has_value());
    ASSERT_EQ(*covered, reference_covered(lo, hi, boxes, 0, slack)) << "trial " << trial;
    inside += *covered;
    ++trials;
  }
  // Both answers occur often enough for the agreement to mean something.
  EXPECT_GT(inside, trials / 20);
  EXPECT_LT(inside, trials - trials / 20);
}

// One cell [0, 1]^30: `partial` boxes that each leave out a layer [0, a) (a in [0.05, 0.3]) of 15
// of the 30 dimensions (a random choice, fixed seed), then two boxes that cover the cell together, split at
// x0 = 0.5; `gap`: the second leaves out x1 < 0.05 as well, so that the points with x0 above 0.5
// and every other coordinate below 0.05 are in no box. The recursion above branches at every
// partial box.
std::vector<Box> layered_union(std::size_t dims, std::size_t partial, bool gap) {
  std::mt19937_64 random(kSeed);
  std::vector<std::size_t> order(dims);
  for (std::size_t d = 0; d < dims; ++d) order[d] = d;
  std::vector<Box> boxes;
  for (std::size_t b = 0; b < partial; ++b) {
    Box box{std::vector<double>(dims, -1.0), std::vector<double>(dims, 2.0)};
    std::shuffle(order.begin(), order.end(), random);
    for (std::size_t i = 0; i < dims / 2; ++i)
      box.lb[order[i]] = std::uniform_real_distribution<double>(0.05, 0.3)(random);
    boxes.push_back(box);
  }
  Box low{std::vector<double>(dims, -1.0), std::vector<double>(dims, 2.0)}, high = low;
  low.ub[0] = 0.5;
  high.lb[0] = 0.5;
  if (gap) high.lb[1] = 0.05;
  boxes.push_back(low);
  boxes.push_back(high);
  return boxes;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(RegionCover, ThirtyDimensionalUnionsOfFourteenBoxesAreDecidedQuickly) {
  constexpr std::size_t kDims = 30, kPartial = 12;
  const Grid cell(grid_spec(std::vector<double>(kDims, 0.5), std::vector<double>(kDims, 0.5),
                            std::vector<double>(kDims, 1.0)));
  auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(detail::robust_cell_roles(cell, reach_avoid_spec(1, Region(layered_union(kDims, kPartial, false))),
                                      Bound::Lower)[0],
            CellRole::FixedOne);
  EXPECT_LT(seconds_since(start), kFastSeconds);
  start = std::chrono::steady_clock::now();
  EXPECT_EQ(detail::robust_cell_roles(cell, reach_avoid_spec(1, Region(layered_union(kDims, kPartial, true))),
                                      Bound::Lower)[0],
            CellRole::Free);
  EXPECT_LT(seconds_since(start), kFastSeconds);
  // Safety: the lower bound keeps the cell exactly when it lies inside `safe`.
  start = std::chrono::steady_clock::now();
  EXPECT_EQ(detail::robust_cell_roles(cell, safety_spec(1, Region(layered_union(kDims, kPartial, false))),
                                      Bound::Lower)[0],
            CellRole::Free);
  EXPECT_EQ(detail::robust_cell_roles(cell, safety_spec(1, Region(layered_union(kDims, kPartial, true))),
                                      Bound::Lower)[0],
            CellRole::FixedZero);
  EXPECT_LT(seconds_since(start), kFastSeconds);
}

TEST(RegionCover, SmallThirtyDimensionalUnionsAgreeWithTheExactRecursion) {
  constexpr std::size_t kDims = 30;
  const std::vector<double> lo(kDims, 0.0), hi(kDims, 1.0), slack(kDims, kSlack);
  for (std::size_t partial = 1; partial <= 3; ++partial)
    for (bool gap : {false, true}) {
      const std::vector<Box> boxes = layered_union(kDims, partial, gap);
      EXPECT_EQ(box_covered(lo, hi, boxes, slack), std::optional<bool>(reference_covered(lo, hi, boxes, 0, slack)))
          << partial << " partial boxes, gap " << gap;
    }
}

}  // namespace
}  // namespace amytiss

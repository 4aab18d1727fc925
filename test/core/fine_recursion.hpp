#pragma once
// The continuous values of the 1-d test system x' = 0.9 x + u + N(0, kFineSigma^2) (reach_avoid
// with one target and one avoid box), by a recursion on cells kFineCellsPerCell times finer than
// the policy's, aligned with its cells and the sets: the truth that continuous-system bounds on
// 1-d grids (with faces, refined) must enclose.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"

namespace amytiss::test_support {

// The fine recursion's error against the continuous value: midpoint values on cells
// kFineCellsPerCell times finer than the coarse grid with exact Gaussian masses and the value's
// jumps on fine faces is second order, ~ h^2/24 |V''| per step (h ~ 4e-3, |V''| ~ 1/sigma^2 ~ 70).
constexpr double kFineGridError = 2e-4;
constexpr int kFineCellsPerCell = 60;
constexpr double kFineSigma = 0.12;  // the system's noise: covariance 0.0144

// V_0 of x' = 0.9 x + u + N(0, kFineSigma^2) at the midpoints of `faces` (the fine cells): 1 in the
// target, 0 in the avoid set and beyond the faces; `input(k, x)` the input index played, or every
// input's best when it returns -1.
inline std::vector<double> fine_values(const Abstraction& a, const std::vector<double>& faces,
                                const std::function<long(unsigned, double)>& input) {
  const std::size_t n = faces.size() - 1;
  const Box& target = a.config.spec.target->boxes[0];
  const Box& avoid = a.config.spec.avoid->boxes[0];
  std::vector<double> mid(n), value(n);
  std::vector<int> place(n);  // 1 target, -1 avoid, 0 undecided
  for (std::size_t i = 0; i < n; ++i) {
    mid[i] = 0.5 * (faces[i] + faces[i + 1]);
    place[i] = (mid[i] >= avoid.lb[0] && mid[i] <= avoid.ub[0]) ? -1 : (mid[i] >= target.lb[0] && mid[i] <= target.ub[0]);
    value[i] = place[i] == 1;
  }
  std::vector<double> tail(faces.size());
  for (unsigned k = a.horizon; k-- > 0;) {
    std::vector<double> next = value;
    for (std::size_t i = 0; i < n; ++i) {
      if (place[i] != 0) continue;
      const long played = input(k, mid[i]);
      double best = 0;
      for (std::size_t u = 0; u < a.inputs.size(); ++u) {
        if (played >= 0 && std::size_t(played) != u) continue;
        const double mean = 0.9 * mid[i] + a.inputs.point(u)[0];
        for (std::size_t j = 0; j < faces.size(); ++j) tail[j] = 0.5 * std::erfc((faces[j] - mean) / (kFineSigma * std::sqrt(2.0)));
        double expected = 0;
        for (std::size_t j = 0; j < n; ++j) expected += (tail[j] - tail[j + 1]) * value[j];
        best = std::max(best, expected);
      }
      next[i] = best;
    }
    value = next;
  }
  return value;
}

/// The fine faces: every cell of the policy's grid cut in kFineCellsPerCell, and the sets' bounds.
inline std::vector<double> fine_faces(const Abstraction& a) {
  const Grid& grid = a.states;
  std::vector<double> faces;
  for (std::size_t c = 0; c < grid.count(0); ++c)
    for (int j = 0; j < kFineCellsPerCell; ++j)
      faces.push_back(grid.face(0, std::int64_t(c)) + grid.width(0, c) * j / kFineCellsPerCell);
  faces.push_back(grid.covered_high(0));
  for (const Box& box : {a.config.spec.target->boxes[0], a.config.spec.avoid->boxes[0]})
    for (double v : {box.lb[0], box.ub[0]})
      if (v > faces.front() && v < faces.back()) faces.push_back(v);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

/// Expects, at every fine cell, the policy's lower bound at most the served controller's fine
/// value and the best input's fine value at most the upper bound (both within kFineGridError).
/// Returns the smallest served fine value less the lower bound over the free cells (1 when none).
inline double expect_encloses_fine_values(const Abstraction& a, const Policy& policy) {
  const Grid& grid = a.states;
  const std::vector<double> faces = fine_faces(a);
  auto cell = [&](double x) { return *grid.cell_of(&x); };
  const std::vector<double> served =
      fine_values(a, faces, [&](unsigned k, double x) { return long(policy.input(k, cell(x))); });
  const std::vector<double> best = fine_values(a, faces, [](unsigned, double) { return -1L; });
  double closest = 1;
  for (std::size_t i = 0; i + 1 < faces.size(); ++i) {
    const double x = 0.5 * (faces[i] + faces[i + 1]);
    const std::size_t c = cell(x);
    EXPECT_LE(policy.value(0, c), served[i] + kFineGridError) << "x " << x;
    EXPECT_LE(best[i], policy.upper_value(0, c) + kFineGridError) << "x " << x;
    if (a.roles[c] == CellRole::Free) closest = std::min(closest, served[i] - policy.value(0, c));
  }
  return closest;
}

}  // namespace amytiss::test_support

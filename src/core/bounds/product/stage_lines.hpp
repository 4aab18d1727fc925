#pragma once
// The lines of one stage of the variable elimination (bounds/product/elimination.hpp) and their
// searches: which output entries read which line of the stage's input, in which order the lines
// are met, and, per worker, the threshold searches of one line.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "factored/factored_plan.hpp"
#include "bounds/omax/robust_expectation.hpp"
#include "bounds/omax/threshold_expectation.hpp"

namespace amytiss::detail {

/// A stage's output digits split by what they do: those the input has name the line an entry reads
/// (carried); the others enumerate the tuples applied to that line (row-major, as the output).
struct StageWalk {
  struct Carried {
    std::size_t radix, input_stride, output_stride, tuple_stride;
    bool jumps;  // an input or disturbance
  };
  /// The lines' odometer, fastest first: by increasing input stride, inputs and disturbances last.
  std::vector<Carried> carried;
  /// Per combination of the other digits: its output offset and its tuple offset.
  std::vector<std::size_t> free_offsets, free_tuples;
  /// The combinations in an order where neighbours differ in a state or post cell where they can:
  /// inputs and disturbances count slowest.
  std::vector<std::uint32_t> free_order;
  /// When no line digit picks the window (every line applies the same windows), one search per
  /// distinct window: the first combination that has it, and each combination's search. Empty: one
  /// search per combination.
  std::vector<std::size_t> searched;
  std::vector<std::uint32_t> search_of;

  static StageWalk of(const FactoredStage& stage, const std::vector<FactorVariable>& variables);
  /// The carried digits alone (what `of` puts in `carried`), without the combinations.
  static std::vector<Carried> carried_of(const FactoredStage& stage, const std::vector<FactorVariable>& variables);
  /// Fills searched and search_of where the windows do not depend on the line; window_of[tuple]:
  /// the window of each tuple, `windows` of them.
  void share_searches(const std::vector<std::uint32_t>& window_of, std::size_t windows);
  /// Searches per line: one per distinct window that the line's tuples read.
  std::size_t searches_per_line() const { return search_of.empty() ? free_tuples.size() : searched.size(); }
};

/// The carried digits of a stage's lines, counted up line by line: consecutive lines are
/// consecutive values of the carried digits, fastest first (no division per line).
struct LineCursor {
  explicit LineCursor(const std::vector<StageWalk::Carried>& carried) : carried(carried), digits(carried.size()) {}
  /// To line `line`, by division.
  void seek(std::size_t line);
  /// To the line whose first entry is at `input` (an offset with the contracted digit 0), by division.
  void seek_input(std::size_t input);
  /// To the next line.
  void next();
  const std::vector<StageWalk::Carried>& carried;
  std::vector<std::size_t> digits;
  std::size_t input = 0, output = 0, tuple = 0;  // the line's first entry, results and tuples
};

/// One worker's searches of a stage's lines: the caller writes a line's keys (value for the lower
/// bound, -value for the upper), search() finds the bound of each window its tuples read. Each
/// search starts where the search of the window in the same place ended on the line searched
/// before: neighbouring lines hold close values, and their i-th windows are one tuple or
/// neighbouring ones, so the threshold sits at the same cell or next to it.
class LineSearcher {
 public:
  /// `sorted`: sort each line and search it in one batch (ThresholdSearches), or search it
  /// unsorted (threshold_scan()).
  LineSearcher(const StageWalk& walk, const PackedWindows& windows, const std::vector<std::uint32_t>& window_of,
               std::size_t length, Bound bound, bool sorted, VectorUnit unit);
  double* keys() { return line_.keys(); }
  /// Searches the line in keys() whose tuples start at `tuple_base`; `after_neighbour`: the line
  /// searched before is a neighbour (its ends are good starts; false: every search starts afresh).
  void search(std::size_t tuple_base, bool after_neighbour);
  /// The bound of the line's i-th combination of free digits (StageWalk::free_offsets).
  double bound(std::size_t i) const { return bounds_[shared_ ? walk_.search_of[i] : i]; }

 private:
  const StageWalk& walk_;
  const PackedWindows& windows_;
  const std::vector<std::uint32_t>& window_of_;
  Bound bound_;
  bool sorted_, shared_;
  VectorUnit unit_;
  std::size_t searches_;
  SortedLine line_;
  std::vector<std::uint32_t> ends_;  // where each search ended (a position)
  std::vector<const PackedWindow*> line_windows_;
  std::size_t windows_tuple_base_ = ~std::size_t(0);  // whose windows line_windows_ holds
  std::vector<double> bounds_;
  ThresholdSearches batch_;
};

}  // namespace amytiss::detail

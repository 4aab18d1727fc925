#include "bounds/mean_box.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace amytiss::detail {
namespace {

// The power of two at most 2^-40 of `width`, and the multiples of it just outside x. Floor and
// ceiling of a quotient by a power of two are exact; a value of magnitude 2^52 quanta or more is
// a multiple of the quantum already.
double binary_quantum(double width) { return std::ldexp(1.0, std::ilogb(width) - 40); }
double floor_to(double x, double quantum) {
  return std::abs(x) < std::ldexp(quantum, 52) ? std::floor(x / quantum) * quantum : x;
}
double ceil_to(double x, double quantum) {
  return std::abs(x) < std::ldexp(quantum, 52) ? std::ceil(x / quantum) * quantum : x;
}

}  // namespace

IntervalBox disturbance_cell(const Grid& disturbances, std::size_t disturbance) {
  IntervalBox cell;
  if (disturbances.dims() == 0) return cell;
  std::vector<std::size_t> multi(disturbances.dims());
  disturbances.multi_index(disturbance, multi.data());
  for (std::size_t j = 0; j < multi.size(); ++j) {
    const auto k = static_cast<std::int64_t>(multi[j]);
    // One point along the dimension: that value alone, as the abstraction's disturbance.
    cell.push_back(disturbances.count(j) == 1 ? Interval::point(disturbances.coordinate(j, 0))
                                              : Interval(disturbances.face(j, k), disturbances.face(j, k + 1)));
  }
  return cell;
}

MeanBox enclosure_mean_box(const ImageEnclosure& enclosure, const Grid& states, const Grid& inputs,
                           const Grid& disturbances) {
  // Rounded outward to a binary grid far finer than the cell (eta() is a faced dimension's
  // smallest width): boxes equal in exact arithmetic (a
  // linear map on the grid gives many cells one mean) are then equal bit for bit, and share one
  // entry of bounds and one search per line of the variable elimination.
  std::vector<double> quanta;
  for (double width : states.eta()) quanta.push_back(binary_quantum(width));
  return [&enclosure, &states, &inputs, &disturbances, quanta](std::size_t cell, std::size_t input,
                                                               std::size_t disturbance, double* lo, double* hi,
                                                               double* expansion) {
    const std::vector<double> centre = states.point(cell);
    std::vector<std::size_t> multi(centre.size());
    if (!states.all_uniform()) states.multi_index(cell, multi.data());
    IntervalBox box;
    for (std::size_t j = 0; j < centre.size(); ++j)
      box.push_back(states.uniform(j) ? Interval(centre[j] - 0.5 * states.eta()[j], centre[j] + 0.5 * states.eta()[j])
                                      : Interval(states.face(j, std::int64_t(multi[j])),
                                                 states.face(j, std::int64_t(multi[j]) + 1)));
    const std::vector<double> u = inputs.dims() ? inputs.point(input) : std::vector<double>{};
    const ImageBox image = enclosure.enclose_over(box, u, disturbance_cell(disturbances, disturbance));
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < image.box.size(); ++i) {
      const bool known = image.defined && !image.box[i].is_empty();
      lo[i] = known ? floor_to(image.box[i].lo, quanta[i]) : -kInfinity;
      hi[i] = known ? ceil_to(image.box[i].hi, quanta[i]) : kInfinity;
      expansion[i] = image.expansion[i];
    }
  };
}

}  // namespace amytiss::detail

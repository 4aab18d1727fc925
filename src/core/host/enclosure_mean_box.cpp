#include "host/enclosure_mean_box.hpp"

#include <limits>
#include <vector>

namespace amytiss::detail {

MeanBox enclosure_mean_box(const ImageEnclosure& enclosure, const Grid& states, const Grid& inputs,
                           const Grid& disturbances) {
  return [&enclosure, &states, &inputs, &disturbances](std::size_t cell, std::size_t input, std::size_t disturbance,
                                                       double* lo, double* hi) {
    const std::vector<double> centre = states.point(cell);
    IntervalBox box;
    for (std::size_t j = 0; j < centre.size(); ++j)
      box.push_back(Interval(centre[j] - 0.5 * states.eta()[j], centre[j] + 0.5 * states.eta()[j]));
    const std::vector<double> u = inputs.dims() ? inputs.point(input) : std::vector<double>{};
    const std::vector<double> w = disturbances.dims() ? disturbances.point(disturbance) : std::vector<double>{};
    const ImageBox image = enclosure.enclose(box, u, w);
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < image.box.size(); ++i) {
      lo[i] = image.defined && !image.box[i].is_empty() ? image.box[i].lo : -kInfinity;
      hi[i] = image.defined && !image.box[i].is_empty() ? image.box[i].hi : kInfinity;
    }
  };
}

}  // namespace amytiss::detail

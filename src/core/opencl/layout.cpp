#include "opencl/layout.hpp"

#include <algorithm>
#include <cstdint>


namespace amytiss {
namespace detail {

Layout::Layout(const Abstraction& a) {
  const std::size_t dims = a.states.dims();
  half.resize(dims);
  width.resize(dims);
  mass_offset.resize(dims);
  padded_count.resize(dims);
  padded_stride.resize(dims);
  whole.resize(dims);
  for (std::size_t i = 0; i < dims; ++i) {
    const long long count = static_cast<long long>(a.states.count(i));
    whole[i] = a.noise->whole_grid_dims()[i] ? 1 : 0;
    // A whole-grid window is the dimension itself: no padding, n cells from index 0 (padding
    // by n - 1 on each side would make the value array (3n - 2)^d: 2^28 cells for StocHy 14-d).
    width[i] = static_cast<long long>(dense_window_width(a, i));
    half[i] = whole[i] ? 0 : (width[i] - 1) / 2;
    mass_offset[i] = mass_record;
    mass_record += width[i];
    padded_count[i] = count + 2 * half[i];
  }
  for (std::size_t i = dims; i-- > 0;) {
    padded_stride[i] = static_cast<long long>(padded_size);
    padded_size *= static_cast<std::size_t>(padded_count[i]);
  }
}

std::size_t Layout::padded_offset(const Grid& states, std::size_t flat) const {
  std::size_t offset = 0;
  for (std::size_t i = states.dims(); i-- > 0;) {
    const std::size_t k = flat % states.count(i);
    flat /= states.count(i);
    offset += (k + static_cast<std::size_t>(half[i])) * static_cast<std::size_t>(padded_stride[i]);
  }
  return offset;
}

std::size_t Layout::record_bytes() const {
  return sizeof(std::uint32_t) + sizeof(float) * static_cast<std::size_t>(mass_record);
}

}  // namespace detail

}  // namespace amytiss

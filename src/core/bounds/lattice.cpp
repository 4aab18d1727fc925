#include "bounds/lattice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace amytiss::detail {
namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

bool noise_free(const NoiseModel& noise, std::size_t dim) { return noise.base_scale()[dim] == 0.0; }

std::int64_t lattice_target(const Grid& states, std::size_t dim, double m_lo, double m_hi) {
  return states.nearest(dim, m_lo + 0.5 * (m_hi - m_lo));
}

double lattice_loss(const Grid& states, std::size_t dim, double m_lo, double m_hi, double expansion) {
  if (!std::isfinite(m_lo) || !std::isfinite(m_hi)) return kInfinity;
  const auto count = static_cast<std::int64_t>(states.count(dim));
  const std::int64_t target = lattice_target(states, dim, m_lo, m_hi);
  // Off the grid the target is the half-line beyond the grid's face.
  const double a = target <= -1 ? -kInfinity : target >= count ? states.face(dim, count) : states.face(dim, target);
  const double b = target <= -1 ? states.face(dim, 0) : target >= count ? kInfinity : states.face(dim, target + 1);
  // Rounded up: the loss must not be understated. a - m_lo and m_hi - b are each one rounding.
  const double overhang = round_up(std::max(a - m_lo, m_hi - b));
  const double shrink = expansion >= 1.0 ? 0.0 : round_up(round_up(1.0 - expansion) * 0.5 * states.eta()[dim]);
  return round_up(overhang + shrink);
}

bool lattice_row(const Grid& states, std::size_t dim, double m_lo, double m_hi, double expansion) {
  return lattice_loss(states, dim, m_lo, m_hi, expansion) <= kLatticeSlack * states.eta()[dim];
}

DimensionBounds lattice_bounds(const Grid& states, std::size_t dim, double m_lo, double m_hi) {
  const auto count = static_cast<std::int64_t>(states.count(dim));
  const std::int64_t target = lattice_target(states, dim, m_lo, m_hi);
  DimensionBounds out;
  if (target < 0 || target >= count) {
    out.first = 0;
    out.last = -1;
    out.leave = {1.0, 1.0};
    return out;
  }
  out.first = out.last = target;
  out.cells = {MassInterval{1.0, 1.0}};
  return out;
}

}  // namespace amytiss::detail

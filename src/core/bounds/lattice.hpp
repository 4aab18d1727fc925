#pragma once
// Noise-free dimensions that move on the cells' lattice (docs/semantics.md, "Noise-free
// dimensions on the lattice"): a dimension with no noise whose map sends every cell (of every row
// of the interval MDP) into one cell, up to a slack far below the cell's width, gets the point
// mass [1, 1] on that cell instead of the spread over the cells its closed, outward-rounded mean
// box touches.
//
// Margins: a state coordinate v in cell [a, b] lies min(v - a, b - v) inside it (state units).
// For a mean box [m_lo, m_hi] that holds f_i over the closed source cell, f_i moving by at least
// `expansion` times any move of x_i (the least |df_i/dx_i| over the cell, 0 when unknown), and a
// target [a_t, b_t], a source coordinate with margin r maps to margin at least r - lattice_loss()
// in the target. A dimension whose every row loses at most kLatticeSlack * eta keeps, over n steps,
// every state that starts more than n * kLatticeSlack * eta (plus the lookup's rounding) inside its
// cell strictly inside the cells the rows name.
#include <cstddef>
#include <cstdint>

#include "amytiss/grid.hpp"
#include "amytiss/noise.hpp"
#include "bounds/mass_bounds.hpp"

namespace amytiss::detail {

/// The largest margin loss per step of a lattice dimension, relative to the cell's width.
constexpr double kLatticeSlack = 0x1p-36;

/// Whether dimension `dim` has no noise: a scale of 0 at every state (a variance of 0; the laws
/// scaled by 1, exponential, beta and custom, always have noise).
bool noise_free(const NoiseModel& noise, std::size_t dim);
/// The cell a lattice row sends dimension `dim` to: the nearest grid index of the mean box's
/// middle (may lie off the grid: below 0 or at least the count, the row then leaves the grid).
std::int64_t lattice_target(const Grid& states, std::size_t dim, double m_lo, double m_hi);
/// The margin loss of one row along `dim` (state units), for lattice_target()'s cell (off the grid:
/// the half-line beyond the grid's face): max(a_t - m_lo, m_hi - b_t) + max(0, 1 - expansion) * eta/2.
/// Infinite for a mean box that is not finite.
double lattice_loss(const Grid& states, std::size_t dim, double m_lo, double m_hi, double expansion);
/// Whether that loss is within kLatticeSlack * eta.
bool lattice_row(const Grid& states, std::size_t dim, double m_lo, double m_hi, double expansion);
/// The bounds of a row of a lattice dimension: a window of lattice_target()'s cell alone with
/// [1, 1] (every other cell 0), nothing cut or leaving; off the grid: no cells and leave [1, 1].
DimensionBounds lattice_bounds(const Grid& states, std::size_t dim, double m_lo, double m_hi);

}  // namespace amytiss::detail

#pragma once
// Generation of the OpenCL C program the engine builds for a problem: a prelude that defines the
// problem as compile-time constants (the contract is listed at the top of kernels/engine.cl), the
// separable contraction with the window widths as literal trip counts, the system's
// amytiss_dynamics(), then a kernel file. Other kernel families reuse the prelude, the
// contraction and the dynamics with their own kernel file.
#include <cstddef>
#include <string>

#include "amytiss/abstraction.hpp"
#include "opencl/layout.hpp"

namespace amytiss::detail {

/// The generated prelude: extensions, #defines (dimensions, sizes, MASS_RECORD, noise flags,
/// ON_THE_FLY, GROUP_SIZE, the cell-role codes ROLE_FREE / ROLE_FIXED_ZERO / ROLE_FIXED_ONE) and
/// the __constant arrays of the grids and the layout.
std::string opencl_prelude(const Abstraction& abstraction, const Layout& layout, bool on_the_fly,
                           std::size_t group_size);

/// double <name>(__global const double* v, <mass_space> const float* m): the separable contraction
/// of a window's values v with a record's masses m, unrolled for this layout.
std::string contraction_source(const Layout& layout, const std::string& name, const std::string& mass_space);

/// The whole program of the synthesis kernels: prelude + contract_global / contract_private +
/// dynamics + kernels/engine.cl.
std::string opencl_program_source(const Abstraction& abstraction, bool on_the_fly, std::size_t group_size);

}  // namespace amytiss::detail

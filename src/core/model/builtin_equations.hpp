#pragma once
// The built-in models' vector fields (model/models/*.h) once more as expressions of the grammar,
// for what the C functions cannot do: interval enclosures (model/enclosure.cpp). Same formulas,
// same constants, same order of operations; test_enclosure.cpp checks them against the C
// functions at random points.
#include <string>
#include <vector>

namespace amytiss {

/// dx_i/dt of built-in `model` (a name of builtin_models()) as expression texts over x0.., u0..
/// (no constants to substitute). Throws std::logic_error for another name.
std::vector<std::string> builtin_rate_equations(const std::string& model);

}  // namespace amytiss

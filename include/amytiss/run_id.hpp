#pragma once
// The id that names one synthesis run (Policy::run_id, the policy file's run_id).
#include <string>

namespace amytiss {

/// A fresh random run id (16 lowercase hex digits) from std::random_device.
std::string new_run_id();

}  // namespace amytiss

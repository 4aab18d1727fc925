#pragma once
// Versions that decide whether a stored policy may be reused.

namespace amytiss {

/// Version of the computed results: bump it with any change to the abstraction, the noise
/// masses or the engines that can change a value or a chosen input. A policy file records the
/// version that computed it; read_policy_file_for() refuses another one, so the synthesizer and
/// the command-line tool recompute instead of reusing a result an older engine made.
constexpr unsigned kEngineVersion = 1;

}  // namespace amytiss

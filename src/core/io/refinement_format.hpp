#pragma once
// The /refinement group of a policy file (docs/policy_file.md): the rounds of `refine`, present
// only in files of a refined synthesis.
#include "amytiss/policy.hpp"
#include "io/hdf5_reader.hpp"
#include "io/hdf5_writer.hpp"

namespace amytiss::detail {

/// Writes /refinement/{states, seconds, gap, at, lower, upper, served_round, stop} when
/// `refinement.rounds` is not empty; nothing otherwise.
void write_refinement(const Hdf5Writer& writer, const Refinement& refinement);
/// Reads /refinement where the file has it (else an empty Refinement); refuses lengths that
/// disagree, a served round beyond the rounds and gaps outside [0, 1].
/// `state_dims`: the policy's state dimensions (the columns of /refinement/at).
Refinement read_refinement(const Hdf5Reader& reader, std::size_t state_dims);
/// Every number and text of `refinement` as 64-bit words, in a fixed order, for the content digest.
std::vector<std::uint64_t> refinement_words(const Refinement& refinement);

}  // namespace amytiss::detail

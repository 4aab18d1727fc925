#include "io/refinement_format.hpp"

#include <cstring>

namespace amytiss::detail {
namespace {

// Row r of lower and upper: the bounds at each `at` state in round r.
std::vector<double> bounds_matrix(const Refinement& refinement, bool upper) {
  std::vector<double> out;
  for (const RefinementRound& round : refinement.rounds)
    out.insert(out.end(), (upper ? round.upper : round.lower).begin(), (upper ? round.upper : round.lower).end());
  return out;
}

std::uint64_t bits(double value) {
  std::uint64_t word = 0;
  std::memcpy(&word, &value, sizeof word);
  return word;
}

}  // namespace

void write_refinement(const Hdf5Writer& writer, const Refinement& refinement) {
  if (refinement.rounds.empty()) return;
  const hsize_t rounds = refinement.rounds.size();
  const hsize_t at = refinement.at.size();
  std::vector<std::uint64_t> states;
  std::vector<double> seconds, gap;
  for (const RefinementRound& round : refinement.rounds) {
    states.push_back(round.states);
    seconds.push_back(round.seconds);
    gap.push_back(round.gap);
  }
  writer.group("/refinement");
  writer.dataset("/refinement/states", {rounds}, H5T_STD_U64LE, H5T_NATIVE_UINT64, states.data());
  writer.dataset("/refinement/seconds", {rounds}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, seconds.data());
  writer.dataset("/refinement/gap", {rounds}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, gap.data());
  if (at > 0) {
    std::vector<double> points;
    for (const auto& point : refinement.at) points.insert(points.end(), point.begin(), point.end());
    writer.dataset("/refinement/at", {at, hsize_t(refinement.at.front().size())}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                   points.data());
    const std::vector<double> lower = bounds_matrix(refinement, false), upper = bounds_matrix(refinement, true);
    writer.dataset("/refinement/lower", {rounds, at}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, lower.data());
    writer.dataset("/refinement/upper", {rounds, at}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, upper.data());
  }
  const std::uint64_t served = refinement.served_round;
  writer.dataset("/refinement/served_round", {1}, H5T_STD_U64LE, H5T_NATIVE_UINT64, &served);
  writer.string_dataset("/refinement/stop", refinement.stop);
}

Refinement read_refinement(const Hdf5Reader& reader, std::size_t state_dims) {
  Refinement refinement;
  if (!reader.has_object("/refinement")) return refinement;
  const auto states = reader.vector_dataset<std::uint64_t>("/refinement/states", H5T_INTEGER, H5T_NATIVE_UINT64);
  const auto seconds = reader.vector_dataset<double>("/refinement/seconds", H5T_FLOAT, H5T_NATIVE_DOUBLE);
  const auto gap = reader.vector_dataset<double>("/refinement/gap", H5T_FLOAT, H5T_NATIVE_DOUBLE);
  const std::size_t rounds = states.size();
  if (rounds == 0 || seconds.size() != rounds || gap.size() != rounds)
    reader.fail("'/refinement' has states, seconds and gap of lengths " + std::to_string(rounds) + ", " +
                std::to_string(seconds.size()) + ", " + std::to_string(gap.size()) + ", expected one equal length >= 1");
  std::vector<double> lower, upper;
  std::size_t at = 0;
  if (reader.has_object("/refinement/at")) {
    const std::vector<hsize_t> shape = reader.dataset_shape("/refinement/at");
    if (shape.size() != 2 || shape[0] == 0 || shape[1] != state_dims)
      reader.fail("'/refinement/at' must have shape (states, " + std::to_string(state_dims) + ")");
    at = std::size_t(shape[0]);
    const auto points = reader.numeric_dataset<double>("/refinement/at", H5T_FLOAT, H5T_NATIVE_DOUBLE, shape);
    for (std::size_t i = 0; i < at; ++i)
      refinement.at.emplace_back(points.begin() + std::ptrdiff_t(i * state_dims),
                                 points.begin() + std::ptrdiff_t((i + 1) * state_dims));
    lower = reader.numeric_dataset<double>("/refinement/lower", H5T_FLOAT, H5T_NATIVE_DOUBLE,
                                           {hsize_t(rounds), hsize_t(at)});
    upper = reader.numeric_dataset<double>("/refinement/upper", H5T_FLOAT, H5T_NATIVE_DOUBLE,
                                           {hsize_t(rounds), hsize_t(at)});
  }
  for (std::size_t r = 0; r < rounds; ++r) {
    if (!(gap[r] >= 0 && gap[r] <= 1)) reader.fail("'/refinement/gap' element " + std::to_string(r) + " is not in [0, 1]");
    RefinementRound round{states[r], seconds[r], gap[r], {}, {}};
    round.lower.assign(lower.begin() + std::ptrdiff_t(r * at), lower.begin() + std::ptrdiff_t((r + 1) * at));
    round.upper.assign(upper.begin() + std::ptrdiff_t(r * at), upper.begin() + std::ptrdiff_t((r + 1) * at));
    refinement.rounds.push_back(std::move(round));
  }
  refinement.served_round = reader.numeric_dataset<std::uint64_t>("/refinement/served_round", H5T_INTEGER,
                                                                  H5T_NATIVE_UINT64, {1})[0];
  if (refinement.served_round >= rounds)
    reader.fail("'/refinement/served_round' is " + std::to_string(refinement.served_round) + ", expected below the " +
                std::to_string(rounds) + " rounds");
  refinement.stop = reader.string_dataset("/refinement/stop");
  return refinement;
}

std::vector<std::uint64_t> refinement_words(const Refinement& refinement) {
  std::vector<std::uint64_t> words{refinement.at.size(), refinement.rounds.size(), refinement.served_round};
  for (const auto& point : refinement.at)
    for (double value : point) words.push_back(bits(value));
  for (const RefinementRound& round : refinement.rounds) {
    words.insert(words.end(), {round.states, bits(round.seconds), bits(round.gap), round.lower.size()});
    for (std::size_t i = 0; i < round.lower.size(); ++i) words.insert(words.end(), {bits(round.lower[i]), bits(round.upper[i])});
  }
  for (char c : refinement.stop) words.push_back(std::uint64_t(static_cast<unsigned char>(c)));
  return words;
}

}  // namespace amytiss::detail

#pragma once
// Checks of what validation or the caller already guarantees: a failure is a bug in this library,
// not a user error, and throws std::logic_error(context + what). A file names its context once,
//   constexpr detail::Require require{"MassBounds: "};
// and states each invariant with what it expects:
//   require(dim < noise.dims(), "dimension out of range");
#include <string_view>

namespace amytiss::detail {

class Require {
 public:
  constexpr explicit Require(const char* context) : context_(context) {}

  void operator()(bool invariant, std::string_view what) const {
    if (!invariant) fail(what);
  }

  /// Throws std::logic_error(context + what).
  [[noreturn]] void fail(std::string_view what) const;

 private:
  const char* context_;
};

}  // namespace amytiss::detail

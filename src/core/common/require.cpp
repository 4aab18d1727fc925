#include "common/require.hpp"

#include <stdexcept>
#include <string>

namespace amytiss::detail {

void Require::fail(std::string_view what) const {
  std::string message(context_);
  message.append(what);
  throw std::logic_error(message);
}

}  // namespace amytiss::detail

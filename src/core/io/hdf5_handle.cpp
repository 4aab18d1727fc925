#include "io/hdf5_handle.hpp"

namespace amytiss::detail {

SilenceHdf5Errors::SilenceHdf5Errors() {
  H5Eget_auto2(H5E_DEFAULT, &previous_function_, &previous_data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

SilenceHdf5Errors::~SilenceHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, previous_function_, previous_data_); }

namespace {

herr_t take_first_description(unsigned, const H5E_error2_t* entry, void* reason) {
  auto* text = static_cast<std::string*>(reason);
  if (text->empty() && entry->desc) *text = entry->desc;
  return 0;
}

}  // namespace

std::string hdf5_error_reason() {
  std::string reason;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, take_first_description, &reason);
  return reason;
}

}  // namespace amytiss::detail

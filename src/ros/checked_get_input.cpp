#include "checked_get_input.hpp"

#include <cstring>

#include <boost/make_shared.hpp>
#include <ros/service_callback_helper.h>

namespace amytiss_ros {

namespace {

// GetInput's request on the wire: uint32 state length, the float64 values, uint32 time_step.
constexpr std::size_t kLengthBytes = 4;
constexpr std::size_t kValueBytes = 8;
constexpr std::size_t kStepBytes = 4;

using GetInputSpec = ros::ServiceSpec<amytiss::GetInput::Request, amytiss::GetInput::Response>;

class CheckedGetInputHelper : public ros::ServiceCallbackHelper {
 public:
  explicit CheckedGetInputHelper(const GetInputCallback& callback) : decoding_(callback) {}

  bool call(ros::ServiceCallbackHelperCallParams& params) override {
    const ros::SerializedMessage& request = params.request;
    const std::size_t size = request.num_bytes - std::size_t(request.message_start - request.buf.get());
    const std::string refusal = oversized_get_input_reason(request.message_start, size);
    if (refusal.empty()) return decoding_.call(params);
    // Answered like any malformed request, so the caller reads why.
    amytiss::GetInput::Response response;
    response.success = false;
    response.message = refusal;
    params.response = ros::serialization::serializeServiceResponse(true, response);
    return true;
  }

 private:
  ros::ServiceCallbackHelperT<GetInputSpec> decoding_;
};

}  // namespace

std::string oversized_get_input_reason(const std::uint8_t* request, std::size_t size) {
  if (size < kLengthBytes + kStepBytes)
    return "request of " + std::to_string(size) + " bytes refused: a GetInput request has at least " +
           std::to_string(kLengthBytes + kStepBytes) + " (state length and time_step)";
  std::uint32_t claimed = 0;
  std::memcpy(&claimed, request, kLengthBytes);  // ROS serialization is little-endian, as is this host
  const std::uint64_t needed = kLengthBytes + std::uint64_t(claimed) * kValueBytes + kStepBytes;
  if (needed <= size) return "";
  return "request of " + std::to_string(size) + " bytes refused before decoding: its state claims " +
         std::to_string(claimed) + " values, which need " + std::to_string(needed) + " bytes";
}

ros::AdvertiseServiceOptions checked_get_input_options(const std::string& service, const GetInputCallback& callback) {
  ros::AdvertiseServiceOptions options;
  options.init<amytiss::GetInput>(service, callback);
  options.helper = boost::make_shared<CheckedGetInputHelper>(callback);
  return options;
}

}  // namespace amytiss_ros

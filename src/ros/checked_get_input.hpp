#pragma once
// The GetInput service with requests checked before roscpp decodes them. roscpp resizes a
// float64[] to the length a request claims before it checks that the bytes are there, so a
// 16-byte request claiming 2^29 values would make the server allocate 4 GiB. Here a request whose
// claimed state length does not fit in the bytes received is answered (success false, a message
// saying so) without being decoded; every other request goes to the callback as usual.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include <amytiss/GetInput.h>
#include <ros/advertise_service_options.h>

namespace amytiss_ros {

/// "" when a serialized GetInput request (`size` bytes from `request`, after the 4-byte TCPROS
/// frame length) holds every state value its length field claims; otherwise a sentence saying
/// what it claims and how many bytes came.
std::string oversized_get_input_reason(const std::uint8_t* request, std::size_t size);

using GetInputCallback = std::function<bool(amytiss::GetInput::Request&, amytiss::GetInput::Response&)>;

/// Options for NodeHandle::advertiseService: `service` (relative to the handle) of type
/// amytiss/GetInput whose requests are checked with oversized_get_input_reason() first.
ros::AdvertiseServiceOptions checked_get_input_options(const std::string& service, const GetInputCallback& callback);

}  // namespace amytiss_ros

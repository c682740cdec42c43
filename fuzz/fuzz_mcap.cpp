// libFuzzer target: the MCAP reader and the message decoders must reject any input with
// scanmatch::Error, never crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/bag/bag.hpp"
#include "scanmatch/io/bag/ros_messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto bag = scanmatch::open_bag_bytes(
        std::string("\x89MCAP0\r\n", 8) + std::string(reinterpret_cast<const char*>(data), size),
        "fuzz");
    scanmatch::BagMessage m;
    while (bag->next(m)) {
      try {
        if (scanmatch::ros_message_type(m.type) == scanmatch::RosMessageType::kLaserScan)
          scanmatch::decode_laser_scan(m, "fuzz");
        else
          scanmatch::decode_cloud_message(m, "fuzz");
      } catch (const scanmatch::Error&) {
      }
    }
  } catch (const scanmatch::Error&) {
  }
  return 0;
}

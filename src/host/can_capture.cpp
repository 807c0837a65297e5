#include "host/can_capture.h"

#include <cerrno>
#include <cstring>

namespace motwin::host {
namespace {

void put_u32_le(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}

}  // namespace

Result<std::unique_ptr<CanCapture>> CanCapture::open(const std::string& path) {
  const bool pcap = path.size() >= 5 && path.compare(path.size() - 5, 5, ".pcap") == 0;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return Error{"cannot create " + path + ": " + std::strerror(errno)};
  if (pcap) {
    uint8_t header[24] = {};
    put_u32_le(header, 0xA1B2C3D4);  // microsecond timestamps, little-endian file
    header[4] = 2;                   // version 2.4
    header[6] = 4;
    put_u32_le(header + 16, 65535);  // snaplen
    put_u32_le(header + 20, 227);    // LINKTYPE_CAN_SOCKETCAN
    if (std::fwrite(header, 1, sizeof(header), file) != sizeof(header) || std::fflush(file) != 0) {
      Error error{"cannot write " + path + ": " + std::strerror(errno)};
      std::fclose(file);
      return error;
    }
  }
  return std::unique_ptr<CanCapture>(new CanCapture(file, pcap ? Format::kPcap : Format::kCandump));
}

CanCapture::~CanCapture() { std::fclose(file_); }

void CanCapture::on_frame(const can::CanFrame& frame, uint64_t timestamp_us) {
  ++frames_;
  const uint8_t dlc = frame.dlc > 8 ? 8 : frame.dlc;
  if (format_ == Format::kPcap) {
    uint8_t record[16 + 16] = {};
    put_u32_le(record, static_cast<uint32_t>(timestamp_us / 1'000'000u));
    put_u32_le(record + 4, static_cast<uint32_t>(timestamp_us % 1'000'000u));
    put_u32_le(record + 8, 16);
    put_u32_le(record + 12, 16);
    // struct can_frame with the identifier in network byte order (LINKTYPE_CAN_SOCKETCAN).
    uint32_t id = frame.id & (frame.extended ? can::kMaxExtendedId : can::kMaxStandardId);
    if (frame.extended) id |= 0x8000'0000u;
    if (frame.rtr) id |= 0x4000'0000u;
    uint8_t* can_frame = record + 16;
    for (int i = 0; i < 4; ++i) can_frame[i] = static_cast<uint8_t>(id >> (24 - 8 * i));
    can_frame[4] = dlc;
    if (!frame.rtr) std::memcpy(can_frame + 8, frame.data, dlc);
    std::fwrite(record, 1, sizeof(record), file_);
  } else {
    const std::string line = format_candump_line(frame, timestamp_us);
    std::fputs(line.c_str(), file_);
    std::fputc('\n', file_);
  }
  std::fflush(file_);
}

std::string format_candump_line(const can::CanFrame& frame, uint64_t timestamp_us, const std::string& channel) {
  char head[64];
  std::snprintf(head, sizeof(head), frame.extended ? "(%llu.%06llu) %s %08X#" : "(%llu.%06llu) %s %03X#",
                static_cast<unsigned long long>(timestamp_us / 1'000'000u),
                static_cast<unsigned long long>(timestamp_us % 1'000'000u), channel.c_str(),
                static_cast<unsigned>(frame.id));
  std::string line = head;
  if (frame.rtr) {
    line += 'R';
  } else {
    const uint8_t dlc = frame.dlc > can::kMaxDataLength ? can::kMaxDataLength : frame.dlc;
    for (uint8_t i = 0; i < dlc; ++i) {
      char byte[3];
      std::snprintf(byte, sizeof(byte), "%02X", frame.data[i]);
      line += byte;
    }
  }
  return line;
}

}  // namespace motwin::host

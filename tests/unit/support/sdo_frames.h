// Raw CAN frames for SDO tests and benchmarks without GoogleTest: a CAN controller that records
// what the firmware transmits, a frame builder, a dictionary with one long value that is
// read in parts (the streaming path of the SDO server), and a block-upload client loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "board/can_controller.h"
#include "core/canopen/object_dictionary.h"
#include "core/canopen/sdo_server.h"
#include "types/can_frame.h"

namespace motwin::testing {

class RecordingCanController final : public board::CanController {
 public:
  std::vector<can::CanFrame> frames;
  bool transmit(const can::CanFrame& frame) override {
    frames.push_back(frame);
    return true;
  }
  std::vector<can::CanFrame> take() {
    std::vector<can::CanFrame> out;
    out.swap(frames);
    return out;
  }
};

inline can::CanFrame frame_of(uint32_t id, std::initializer_list<uint8_t> bytes) {
  can::CanFrame frame;
  frame.id = id;
  for (uint8_t b : bytes) frame.data[frame.dlc++] = b;
  return frame;
}

// Byte i of the long value: not periodic in the window or segment size, so that a byte taken
// from the wrong offset shows.
inline uint8_t domain_byte(size_t i) { return static_cast<uint8_t>((i * 131u) ^ (i >> 7) ^ (i >> 13)); }

// 2100: a read-only value (a long string, as a DOMAIN would be) of `domain_size` bytes (domain_byte), served in parts; read_part
// fails with `fail_code` from `fail_from` on. 2101: as 2100, but the dictionary does not
// stream it (the default read_part).
class StreamingDictionary final : public canopen::ObjectDictionary {
 public:
  size_t domain_size = 100'000;
  size_t fail_from = SIZE_MAX;
  canopen::SdoAbort fail_code = canopen::SdoAbort::kHardware;
  size_t part_reads = 0;
  size_t largest_part = 0;

  canopen::SdoAbort find(uint16_t index, uint8_t sub, canopen::ObjectRef& out) const override {
    if (index != 0x2100 && index != 0x2101) return canopen::SdoAbort::kNoObject;
    if (sub != 0) return canopen::SdoAbort::kNoSubIndex;
    out = canopen::ObjectRef{&kDomain, 0, index, 0};
    return canopen::SdoAbort::kNone;
  }
  size_t size(const canopen::ObjectRef&) override { return domain_size; }
  canopen::SdoAbort read(const canopen::ObjectRef&, uint8_t* out, size_t capacity, size_t& length) override {
    if (domain_size > capacity) return canopen::SdoAbort::kOutOfMemory;
    for (size_t i = 0; i < domain_size; ++i) out[i] = domain_byte(i);
    length = domain_size;
    return canopen::SdoAbort::kNone;
  }
  canopen::SdoAbort write(const canopen::ObjectRef&, const uint8_t*, size_t) override {
    return canopen::SdoAbort::kReadOnly;
  }
  canopen::SdoAbort read_part(const canopen::ObjectRef& ref, size_t offset, uint8_t* out, size_t capacity,
                              size_t& length) override {
    if (ref.index != 0x2100) return ObjectDictionary::read_part(ref, offset, out, capacity, length);
    if (offset + capacity > fail_from) return fail_code;
    ++part_reads;
    length = offset >= domain_size ? 0 : (domain_size - offset < capacity ? domain_size - offset : capacity);
    if (length > largest_part) largest_part = length;
    for (size_t i = 0; i < length; ++i) out[i] = domain_byte(offset + i);
    return canopen::SdoAbort::kNone;
  }

 private:
  static constexpr canopen::EntryInfo kDomain{0x2100, 0, canopen::ObjectCode::kVar, "Domain", "Domain",
                                              canopen::DataType::kVisibleString, canopen::Access::kRo, false, 0, 0, 0,
                                              false, 0, canopen::StorageGroup::kNone, nullptr};
};

inline uint32_t abort_code_of(const can::CanFrame& frame) {
  return frame.data[4] | frame.data[5] << 8 | frame.data[6] << 16 | uint32_t{frame.data[7]} << 24;
}

// What a block upload delivered.
struct BlockUploadResult {
  std::vector<uint8_t> data;
  uint32_t abort_code = 0;       // the server's abort, 0 if none
  uint16_t server_crc = 0;       // from the end frame
  size_t announced_size = 0;
  size_t frames_from_server = 0;
};

// A CiA-301 block upload client on `server` (node 1): initiate with CRC and `block_size`, start,
// acknowledge every sub-block (all segments, or only `acknowledge_limit` of them when it is
// lower, so that the rest is sent again), end. Frames go straight to the server, no bus.
inline BlockUploadResult block_upload(canopen::SdoServer& server, RecordingCanController& can, uint16_t index,
                                      uint8_t block_size, uint8_t acknowledge_limit = 127) {
  BlockUploadResult result;
  // Each request's answer lands in `answer` (can.frames, reused: no allocation per sub-block).
  const std::vector<can::CanFrame>& answer = can.frames;
  auto exchange = [&](std::initializer_list<uint8_t> bytes) {
    can.frames.clear();
    server.on_request(frame_of(0x601, bytes));
    server.process(0);
    result.frames_from_server += answer.size();
  };
  exchange({0xA4, static_cast<uint8_t>(index), static_cast<uint8_t>(index >> 8), 0, block_size, 0, 0, 0});
  if (answer.size() != 1 || answer[0].data[0] == 0x80) {
    if (!answer.empty()) result.abort_code = abort_code_of(answer[0]);
    return result;
  }
  result.announced_size =
      answer[0].data[4] | answer[0].data[5] << 8 | answer[0].data[6] << 16 | size_t{answer[0].data[7]} << 24;
  result.data.reserve(result.announced_size);
  exchange({0xA3, 0, 0, 0, 0, 0, 0, 0});
  for (;;) {
    if (answer.empty()) return result;
    if (answer[0].data[0] == 0x80) {
      result.abort_code = abort_code_of(answer[0]);
      return result;
    }
    if (answer.size() == 1 && (answer[0].data[0] & 0xE3) == 0xC1) {  // end: n unused bytes, CRC
      const size_t unused = (answer[0].data[0] >> 2) & 0x07;
      result.data.resize(result.data.size() - unused);
      result.server_crc = static_cast<uint16_t>(answer[0].data[1] | answer[0].data[2] << 8);
      exchange({0xA1, 0, 0, 0, 0, 0, 0, 0});
      return result;
    }
    const uint8_t keep = static_cast<uint8_t>(answer.size() < acknowledge_limit ? answer.size() : acknowledge_limit);
    for (uint8_t i = 0; i < keep; ++i) result.data.insert(result.data.end(), answer[i].data + 1, answer[i].data + 8);
    exchange({0xA2, keep, block_size, 0, 0, 0, 0, 0});
  }
}

}  // namespace motwin::testing

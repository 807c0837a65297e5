// A TMCM-3216 on a RAM NVM with a CAN controller that records what it transmits, and a small
// SDO client that speaks raw CiA-301 frames to it: what the CANopen core tests drive.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "board/can_controller.h"
#include "sdo_frames.h"
#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm3216/tmcm3216.h"
#include "types/can_frame.h"

namespace motwin::testing {


inline uint32_t le32(const can::CanFrame& frame, size_t offset) {
  return static_cast<uint32_t>(frame.data[offset]) | static_cast<uint32_t>(frame.data[offset + 1]) << 8 |
         static_cast<uint32_t>(frame.data[offset + 2]) << 16 | static_cast<uint32_t>(frame.data[offset + 3]) << 24;
}

using Tmcm3216 = modules::tmcm3216::Tmcm3216;
using Tmcm3216Nvm = board::RamNonVolatileMemory<Tmcm3216::kNvmSize>;

// What an SDO exchange returned: the response, or the abort code (0 when not aborted).
struct SdoResult {
  can::CanFrame response;
  uint32_t abort = 0;
  uint32_t value = 0;         // expedited upload
  std::string bytes;          // segmented upload
};

// A small SDO and NMT client in raw CiA-301 frames over a rig's `device` (a pointer to the module)
// and `can` (the RecordingCanController it transmits on); `other` collects what was not the SDO
// response (heartbeats, EMCYs, PDOs).
template <class Rig>
struct CanopenClient {
  std::vector<can::CanFrame> other;

  uint8_t node() { return self().device->node_id(); }

  // Delivers a frame and runs one process call (no time passes); what the device sent.
  std::vector<can::CanFrame> send(const can::CanFrame& frame) {
    self().can.take();
    EXPECT_TRUE(self().device->receive(frame));
    self().device->process(0);
    return self().can.take();
  }

  // One SDO request; expects exactly one response on 0x580 + node (other frames go to `other`).
  can::CanFrame sdo(std::initializer_list<uint8_t> bytes) {
    std::vector<can::CanFrame> responses;
    for (const can::CanFrame& f : self().send(frame_of(0x600u + self().node(), bytes))) {
      if (f.id == 0x580u + self().node()) {
        responses.push_back(f);
      } else {
        other.push_back(f);
      }
    }
    EXPECT_EQ(responses.size(), 1u) << "SDO request got " << responses.size() << " responses";
    if (responses.empty()) return can::CanFrame{};
    EXPECT_EQ(responses[0].dlc, 8);
    return responses[0];
  }

  static uint32_t abort_of(const can::CanFrame& response) { return response.data[0] == 0x80 ? le32(response, 4) : 0; }

  SdoResult upload(uint16_t index, uint8_t sub) {
    SdoResult result;
    result.response = sdo({0x40, static_cast<uint8_t>(index), static_cast<uint8_t>(index >> 8), sub, 0, 0, 0, 0});
    result.abort = abort_of(result.response);
    if (result.abort != 0) return result;
    const uint8_t header = result.response.data[0];
    if ((header & 0xE2) == 0x42) {  // expedited
      result.value = le32(result.response, 4);
      const size_t n = (header & 0x01) ? 4 - ((header >> 2) & 0x03) : 4;
      for (size_t i = 0; i < n; ++i) result.bytes.push_back(static_cast<char>(result.response.data[4 + i]));
      return result;
    }
    EXPECT_EQ(header, 0x41) << "initiate upload response";
    const uint32_t size = le32(result.response, 4);
    uint8_t toggle = 0;
    for (int guard = 0; guard < 64; ++guard) {
      const can::CanFrame segment = sdo({static_cast<uint8_t>(0x60 | toggle), 0, 0, 0, 0, 0, 0, 0});
      result.abort = abort_of(segment);
      if (result.abort != 0) return result;
      EXPECT_EQ(segment.data[0] & 0x10, toggle);
      const size_t n = 7 - ((segment.data[0] >> 1) & 0x07);
      for (size_t i = 0; i < n; ++i) result.bytes.push_back(static_cast<char>(segment.data[1 + i]));
      if (segment.data[0] & 0x01) break;
      toggle ^= 0x10;
    }
    EXPECT_EQ(result.bytes.size(), size);
    return result;
  }

  // Expedited download of `size` bytes (1..4) with the size indicated.
  uint32_t download(uint16_t index, uint8_t sub, uint32_t value, uint8_t size = 4) {
    const uint8_t header = static_cast<uint8_t>(0x23 | ((4 - size) << 2));
    const can::CanFrame response =
        sdo({header, static_cast<uint8_t>(index), static_cast<uint8_t>(index >> 8), sub, static_cast<uint8_t>(value),
             static_cast<uint8_t>(value >> 8), static_cast<uint8_t>(value >> 16), static_cast<uint8_t>(value >> 24)});
    const uint32_t abort = abort_of(response);
    if (abort == 0) {
      EXPECT_EQ(response.data[0], 0x60);
      EXPECT_EQ(response.data[1], static_cast<uint8_t>(index));
      EXPECT_EQ(response.data[2], static_cast<uint8_t>(index >> 8));
      EXPECT_EQ(response.data[3], sub);
    }
    return abort;
  }

  uint32_t read_u32(uint16_t index, uint8_t sub) {
    const SdoResult r = upload(index, sub);
    EXPECT_EQ(r.abort, 0u) << std::hex << index << " sub " << int(sub);
    return r.value;
  }

  void nmt(uint8_t command, uint8_t target) { self().send(frame_of(0x000, {command, target})); }

 private:
  Rig& self() { return static_cast<Rig&>(*this); }
};

struct Tmcm3216Rig : CanopenClient<Tmcm3216Rig> {
  std::unique_ptr<Tmcm3216Nvm> nvm = std::make_unique<Tmcm3216Nvm>();
  RecordingCanController can;
  std::unique_ptr<Tmcm3216> device;

  explicit Tmcm3216Rig(modules::tmcm3216::Tmcm3216Config config = {}, bool format = true) {
    if (format) Tmcm3216::format_factory_image(nvm->mutable_data(), nvm->size());
    device = std::make_unique<Tmcm3216>(*nvm, can, config);
    device->power_up();
  }

  // Power cycle with the same NVM.
  void power_cycle(modules::tmcm3216::Tmcm3216Config config = {}) {
    device = std::make_unique<Tmcm3216>(*nvm, can, config);
    device->power_up();
  }

};

}  // namespace motwin::testing

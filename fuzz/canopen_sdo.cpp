// The TMCM-3216's CANopen stack fed frame sequences: SDO requests (expedited, segmented, block,
// garbage) to its server, NMT commands, and frames on any other identifier (SYNC, PDOs, LSS,
// heartbeats), with time passing in between (SDO timeouts, heartbeat production).
//
// Invariants:
// - every frame on 0x580 + node ID is a valid SDO response: 8 bytes, a server command specifier
//   with its reserved bits clear, an abort code from CiA-301's table, and an initiate response
//   naming the index and sub-index of the request it answers;
// - at most one SDO response per request (or per timeout), none while the node is stopped;
// - every writable numeric object of the dictionary, for every axis, holds a value inside its
//   row's range.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "canopen_checks.h"

namespace {

using namespace motwin;
using fuzz::check_dictionary_ranges;
using fuzz::check_sdo_response;
using fuzz::trace;

// A request a client could plausibly send: mostly well-formed command specifiers on real
// objects, sometimes anything.
can::CanFrame next_sdo_request(FuzzedDataProvider& in, fuzz::Tmcm3216& device) {
  can::CanFrame frame;
  frame.id = canopen::kSdoRequestCobIdBase + device.node_id();
  frame.dlc = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegralInRange<uint8_t>(0, 8) : 8;
  for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
  if (in.ConsumeBool()) {
    const auto rows = device.dictionary().rows();
    const auto& info = rows[in.ConsumeIntegralInRange<size_t>(0, rows.size() - 1)].info;
    const uint16_t index = static_cast<uint16_t>(info.index + in.ConsumeIntegralInRange<int>(0, 2) * info.axis_stride);
    frame.data[1] = static_cast<uint8_t>(index);
    frame.data[2] = static_cast<uint8_t>(index >> 8);
    frame.data[3] = info.sub;
  }
  return frame;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = std::make_unique<fuzz::Tmcm3216Rig>();
  fuzz::Tmcm3216& device = *rig->device;
  rig->can.frames.clear();
  bool block_upload = false;

  for (int step = 0; step < 200 && in.remaining_bytes() > 0; ++step) {
    can::CanFrame frame;
    bool is_sdo_request = false;
    uint32_t elapsed_us = 0;
    switch (in.ConsumeIntegralInRange<int>(0, 9)) {
      case 0: {  // NMT
        frame.id = 0;
        frame.dlc = 2;
        const uint8_t commands[] = {0x01, 0x02, 0x80, 0x81, 0x82};
        frame.data[0] = in.ConsumeBool() ? commands[in.ConsumeIntegralInRange<int>(0, 4)] : in.ConsumeIntegral<uint8_t>();
        frame.data[1] = in.ConsumeBool() ? 0 : device.node_id();
        break;
      }
      case 1: {  // any identifier: SYNC, PDOs, LSS, heartbeats, other nodes
        frame.id = in.ConsumeIntegralInRange<uint32_t>(0, 0x7FF);
        frame.rtr = in.ConsumeIntegralInRange<int>(0, 7) == 0;
        frame.dlc = in.ConsumeIntegralInRange<uint8_t>(0, 8);
        for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
        break;
      }
      case 2:  // time passes
        elapsed_us = in.ConsumeIntegralInRange<uint32_t>(0, 2'000'000);
        break;
      default:
        frame = next_sdo_request(in, device);
        is_sdo_request = true;
        break;
    }
    const uint8_t node_before = device.node_id();
    const bool stopped_before = device.nmt_state() == canopen::NmtState::kStopped;
    const bool time_only = elapsed_us != 0 || (frame.id == 0 && frame.dlc == 0);
    if (!time_only) {
      trace("->", frame);
      device.receive(frame);
    }
    device.process(time_only ? elapsed_us : 0);

    // A request other than a block upload one ends a block upload.
    const uint8_t ccs = frame.data[0] >> 5;
    if (is_sdo_request && ccs != 5) block_upload = false;
    size_t responses = 0;
    for (const can::CanFrame& out : rig->can.frames) {
      trace("  <-", out);
      if (out.id != canopen::kSdoResponseCobIdBase + node_before || out.extended) continue;
      ++responses;
      check_sdo_response(out, is_sdo_request && frame.dlc == 8 ? &frame : nullptr, block_upload);
      if (out.data[0] == 0x80) block_upload = false;
      if (is_sdo_request && ccs == 5 && (out.data[0] >> 5) == 6) block_upload = true;
    }
    FUZZ_CHECK(responses <= 1 || block_upload, "%zu SDO responses to one request", responses);
    if (stopped_before && device.nmt_state() == canopen::NmtState::kStopped) {
      FUZZ_CHECK(responses == 0, "an SDO response while the node is stopped");
    }
    rig->can.frames.clear();
    if (step % 8 == 7) check_dictionary_ranges(device);
  }
  check_dictionary_ranges(device);
  return 0;
}

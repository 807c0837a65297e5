// The TMCM-3216's CANopen stack fed frame sequences: SDO requests (expedited, segmented, block,
// garbage) to its server, NMT commands, and frames on any other identifier (SYNC, PDOs, LSS,
// heartbeats), with time passing in between (SDO timeouts, heartbeat production).
//
// Invariants:
// - every frame on 0x580 + node ID is the response the SDO client expects in the transfer state
//   it sees (fuzz::SdoClientView, canopen_checks.h): how many (one per request, none to a client
//   abort or within a sub-block, a sub-block of segments, none while stopped), command
//   specifiers and reserved bits, index echoes, toggle bits, sizes and c bits, block sequence
//   numbers and sizes, the block CRCs, abort codes from CiA-301's table and the ones it asks for
//   (toggle, sequence, block size, CRC, timeout), the timeout itself;
// - an expedited download acknowledged without abort reads back as written; an aborted one
//   changes nothing;
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
using fuzz::trace;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = fuzz::fresh_rig<fuzz::Tmcm3216Rig>();
  fuzz::Tmcm3216& device = *rig->device;
  rig->can.frames.clear();
  fuzz::SdoClientView client(device);

  for (int step = 0; step < 200 && in.remaining_bytes() > 0; ++step) {
    can::CanFrame frame;
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
        frame = fuzz::raw_sdo_request(in, device, 3);
        break;
    }
    const bool time_only = elapsed_us != 0 || (frame.id == 0 && frame.dlc == 0);
    client.before(time_only ? nullptr : &frame, elapsed_us);
    if (!time_only) {
      trace("->", frame);
      device.receive(frame);
    }
    device.process(time_only ? elapsed_us : 0);
    for (const can::CanFrame& out : rig->can.frames) trace("  <-", out);
    client.after(rig->can.frames);
    rig->can.frames.clear();
    if (step % 8 == 7) check_dictionary_ranges(device);
  }
  check_dictionary_ranges(device);
  return 0;
}

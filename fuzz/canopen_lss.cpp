// The LSS slave of the TMCM-3216 (src/core/canopen/lss_slave.*, CiA-305): master frames on
// 0x7E5 (switch state, selective switch on its real identity or not, configure node ID and bit
// timing, store, inquire, fastscan) with NMT resets in between.
//
// Invariants:
// - answers go out only on 0x7E4, 8 bytes, with a slave command specifier (44, 11, 13, 17,
//   4F, 5A..5E); a master frame of another length is never answered; at most one answer each;
// - the answer to 11 (configure node ID) is error 0 exactly for IDs 1..127 and 255;
// - 5E answers the active node ID; the active node ID is always 1..127 or 255;
// - the object dictionary stays in range.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <memory>

#include "canopen_checks.h"
#include "core/canopen/lss_slave.h"

namespace {

using namespace motwin;

constexpr uint8_t kCommands[] = {0x04, 0x40, 0x41, 0x42, 0x43, 0x11, 0x13, 0x15, 0x17,
                                 0x5A, 0x5B, 0x5C, 0x5D, 0x5E, 0x51};

bool is_slave_answer(uint8_t cs) {
  return cs == 0x44 || cs == 0x11 || cs == 0x13 || cs == 0x17 || cs == 0x4F || (cs >= 0x5A && cs <= 0x5E);
}

uint32_t identity(fuzz::Tmcm3216& device, uint8_t sub) {
  canopen::ObjectRef ref;
  if (!fuzz::ObjectLookup::of(device).find(0x1018, sub, ref)) return 0;
  uint8_t bytes[8] = {};
  fuzz::read_numeric(device, ref, bytes);
  return fuzz::le32(bytes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  auto rig = fuzz::fresh_rig<fuzz::Tmcm3216Rig>();
  fuzz::Tmcm3216& device = *rig->device;
  rig->can.frames.clear();
  for (int step = 0; step < 200 && in.remaining_bytes() > 0; ++step) {
    can::CanFrame frame;
    frame.id = canopen::kLssMasterCobId;
    frame.dlc = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegralInRange<uint8_t>(0, 8) : 8;
    for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
    const int kind = in.ConsumeIntegralInRange<int>(0, 9);
    if (kind == 0) {  // NMT reset node / communication: pending settings apply
      frame.id = 0;
      frame.dlc = 2;
      frame.data[0] = in.ConsumeBool() ? 0x81 : 0x82;
      frame.data[1] = 0;
    } else if (kind == 1) {  // time (bit timing activation delays)
      device.process(in.ConsumeIntegralInRange<uint32_t>(0, 100'000));
      rig->can.frames.clear();
      continue;
    } else if (kind <= 7) {
      frame.data[0] = kCommands[in.ConsumeIntegralInRange<size_t>(0, sizeof(kCommands) - 1)];
      if (frame.data[0] >= 0x40 && frame.data[0] <= 0x43 && in.ConsumeBool()) {
        const uint32_t part = identity(device, static_cast<uint8_t>(frame.data[0] - 0x40 + 1));
        for (int i = 0; i < 4; ++i) frame.data[1 + i] = static_cast<uint8_t>(part >> (8 * i));
      }
      if (frame.data[0] == 0x04) frame.data[1] = in.ConsumeBool() ? 1 : 0;
      if (frame.data[0] == 0x11 && in.ConsumeBool()) frame.data[1] = in.ConsumeIntegralInRange<uint8_t>(0, 130);
    }
    fuzz::trace("->", frame);
    device.receive(frame);
    device.process(0);

    size_t answers = 0;
    for (const can::CanFrame& out : rig->can.frames) {
      fuzz::trace("  <-", out);
      if (out.id != canopen::kLssSlaveCobId) continue;
      ++answers;
      FUZZ_CHECK(frame.id == canopen::kLssMasterCobId && frame.dlc == 8, "an LSS answer to a frame of %u bytes on %x",
                 frame.dlc, frame.id);
      FUZZ_CHECK(out.dlc == 8 && !out.rtr && !out.extended, "LSS answer with %u bytes", out.dlc);
      FUZZ_CHECK(is_slave_answer(out.data[0]), "LSS answer specifier %02x", out.data[0]);
      if (out.data[0] == 0x11) {
        const uint8_t requested = frame.data[1];
        const bool valid = (requested >= 1 && requested <= 127) || requested == 255;
        FUZZ_CHECK(frame.data[0] == 0x11 && (out.data[1] == 0) == valid, "configure node ID %u answered error %u",
                   requested, out.data[1]);
      }
      if (out.data[0] == 0x5E) {
        FUZZ_CHECK(out.data[1] == device.node_id(), "inquire node ID answered %u, active %u", out.data[1],
                   device.node_id());
      }
    }
    FUZZ_CHECK(answers <= 1, "%zu LSS answers to one frame", answers);
    const uint8_t node = device.node_id();
    FUZZ_CHECK((node >= 1 && node <= 127) || node == 255, "active node ID %u", node);
    rig->can.frames.clear();
  }
  fuzz::check_dictionary_ranges(device);
  return 0;
}

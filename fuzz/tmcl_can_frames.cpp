// TMCL over CAN (src/core/tmcl/can_link.*) on a TMCM-1636: frames with any identifier (mostly
// the module's receive ID, GP 71), any length, remote or data, with control ticks in between.
//
// Invariants:
// - remote frames and frames on other identifiers are not addressed and get no reply;
// - an addressed data frame gets exactly one reply on the module's send ID (GP 70, as it is
//   after the command), except command 137 with 1234; a frame of fewer than 7 bytes is answered
//   with status 2 and executes nothing; the reply is 7 or 8 bytes and carries a TMCL status;
// - frames that were never addressed leave every parameter as on a fresh module;
// - writable parameters stay inside their rows' ranges.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <memory>

#include "core/tmcl/can_link.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motwin;
  FuzzedDataProvider in(data, size);
  auto rig = std::make_unique<fuzz::Tmcm1636Rig>();
  tmcl::CanSettings settings;
  if (!tmcl::read_can_settings(rig->module, settings)) return 0;
  size_t executed = 0;
  for (int step = 0; step < 200 && in.remaining_bytes() > 0; ++step) {
    if (in.ConsumeIntegralInRange<int>(0, 9) == 0) {
      for (int t = in.ConsumeIntegralInRange<int>(1, 200); t > 0; --t) rig->module.tick();
      continue;
    }
    tmcl::read_can_settings(rig->module, settings);
    can::CanFrame frame;
    frame.id = in.ConsumeIntegralInRange<int>(0, 3) != 0 ? settings.receive_id
                                                           : in.ConsumeIntegralInRange<uint32_t>(0, 0x7FF);
    frame.rtr = in.ConsumeIntegralInRange<int>(0, 15) == 0;
    frame.dlc = in.ConsumeIntegralInRange<int>(0, 3) != 0 ? 7 + in.ConsumeIntegralInRange<uint8_t>(0, 1)
                                                           : in.ConsumeIntegralInRange<uint8_t>(0, 8);
    for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
    if (in.ConsumeBool()) frame.data[0] = static_cast<uint8_t>(in.ConsumeIntegralInRange<int>(0, 15));  // real commands

    const tmcl::CanResponse response = tmcl::serve_can_frame(rig->engine, frame, 0);
    const bool ours = !frame.rtr && !frame.extended && frame.id == settings.receive_id;
    FUZZ_CHECK(response.addressed == ours, "frame on %x (receive ID %x, rtr %d): addressed %d", frame.id,
               settings.receive_id, frame.rtr, response.addressed);
    if (!ours) {
      FUZZ_CHECK(!response.has_reply, "a frame not addressed to the module was answered");
      continue;
    }
    if (frame.dlc >= 7) ++executed;
    tmcl::CanSettings after;
    tmcl::read_can_settings(rig->module, after);
    const int32_t value = static_cast<int32_t>(static_cast<uint32_t>(frame.data[3]) << 24 |
                                               static_cast<uint32_t>(frame.data[4]) << 16 |
                                               static_cast<uint32_t>(frame.data[5]) << 8 | frame.data[6]);
    if (!response.has_reply) {
      FUZZ_CHECK(frame.dlc >= 7 && frame.data[0] == 137 && value == 1234, "command %u (%u bytes) got no reply",
                 frame.data[0], frame.dlc);
      continue;
    }
    const can::CanFrame& reply = response.reply;
    FUZZ_CHECK(reply.id == after.send_id && !reply.rtr, "reply on %x, send ID %x", reply.id, after.send_id);
    FUZZ_CHECK(reply.dlc == 7 || reply.dlc == 8, "reply of %u bytes", reply.dlc);
    if (frame.dlc >= 7 && frame.data[0] == 136 && frame.data[1] == 0) continue;  // version string
    const uint8_t status = reply.data[1];
    FUZZ_CHECK(status == 100 || status == 101 || status == 128 || (status >= 1 && status <= 6),
               "reply status %u to command %u", status, frame.data[0]);
    if (frame.dlc < 7) FUZZ_CHECK(status == 2, "a %u-byte request answered with status %u", frame.dlc, status);
    if (response.reset_after_send) rig->engine.complete_reset();
    fuzz::check_parameter_ranges(rig->module, "after a CAN frame");
  }
  if (executed == 0) {
    auto fresh = std::make_unique<fuzz::Tmcm1636Rig>();
    FUZZ_CHECK(fuzz::probe_parameters(rig->module) == fuzz::probe_parameters(fresh->module) ||
                   rig->module.tick_count() != 0,
               "frames that executed nothing changed a parameter");
  }
  return 0;
}

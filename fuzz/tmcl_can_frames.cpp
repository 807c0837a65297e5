// TMCL over CAN (src/core/tmcl/can_link.*) on a TMCM-1636: frames with any identifier (mostly
// the module's receive ID, GP 71), standard or extended, any length, remote or data, with control
// ticks in between.
//
// Invariants (docs/canopen.md, "TMCL over CAN"):
// - remote frames and frames on other identifiers are not addressed and get no reply;
// - a data frame on the receive ID, standard or extended, gets exactly one reply on the module's
//   send ID (GP 70, as it is after the command) in the request's ID format, except command 137
//   with 1234; the reply carries the receive ID's low byte (as it is after the command) and a
//   TMCL status, and is as long as the request (7, or 8 for 8 bytes), except the version string
//   (136 type 0: 8 bytes, the version characters); it echoes the command (134: the command read
//   from the program);
// - a frame of fewer than 7 bytes executes nothing and is answered in 7 bytes with status 2, its
//   command byte (0 when empty) and value 0;
// - frames that executed nothing leave every parameter and the EEPROM image as on a fresh module
//   given the same control ticks;
// - writable parameters stay inside their rows' ranges.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

#include "core/tmcl/can_link.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motwin;
  FuzzedDataProvider in(data, size);
  auto rig = fuzz::fresh_rig<fuzz::Tmcm1636Rig>();
  tmcl::CanSettings settings;
  if (!tmcl::read_can_settings(rig->module, settings)) return 0;
  size_t executed = 0;
  uint64_t ticks = 0;
  for (int step = 0; step < 200 && in.remaining_bytes() > 0; ++step) {
    if (in.ConsumeIntegralInRange<int>(0, 9) == 0) {
      for (int t = in.ConsumeIntegralInRange<int>(1, 200); t > 0; --t, ++ticks) rig->module.tick();
      continue;
    }
    tmcl::read_can_settings(rig->module, settings);
    can::CanFrame frame;
    frame.id = in.ConsumeIntegralInRange<int>(0, 3) != 0 ? settings.receive_id
                                                           : in.ConsumeIntegralInRange<uint32_t>(0, 0x7FF);
    frame.extended = in.ConsumeIntegralInRange<int>(0, 3) == 0;
    if (frame.extended && in.ConsumeIntegralInRange<int>(0, 3) == 0) {
      frame.id = in.ConsumeIntegralInRange<uint32_t>(0, can::kMaxExtendedId);
    }
    frame.rtr = in.ConsumeIntegralInRange<int>(0, 15) == 0;
    frame.dlc = in.ConsumeIntegralInRange<int>(0, 3) != 0 ? 7 + in.ConsumeIntegralInRange<uint8_t>(0, 1)
                                                           : in.ConsumeIntegralInRange<uint8_t>(0, 8);
    for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
    if (in.ConsumeBool()) frame.data[0] = static_cast<uint8_t>(in.ConsumeIntegralInRange<int>(0, 15));  // real commands

    const tmcl::CanResponse response = tmcl::serve_can_frame(rig->engine, frame, 0);
    const bool ours = !frame.rtr && frame.id == settings.receive_id;
    FUZZ_CHECK(response.addressed == ours, "frame on %x (receive ID %x, rtr %d, extended %d): addressed %d", frame.id,
               settings.receive_id, frame.rtr, frame.extended, response.addressed);
    if (!ours) {
      FUZZ_CHECK(!response.has_reply, "a frame not addressed to the module was answered");
      continue;
    }
    const bool request = frame.dlc >= tmcl::kCanRequestLength;
    if (request) ++executed;
    tmcl::CanSettings after;
    tmcl::read_can_settings(rig->module, after);
    const uint8_t command = frame.dlc > 0 ? frame.data[0] : 0;
    const int32_t value = static_cast<int32_t>(static_cast<uint32_t>(frame.data[3]) << 24 |
                                               static_cast<uint32_t>(frame.data[4]) << 16 |
                                               static_cast<uint32_t>(frame.data[5]) << 8 | frame.data[6]);
    if (!response.has_reply) {
      FUZZ_CHECK(request && command == 137 && value == 1234, "command %u (%u bytes) got no reply", command, frame.dlc);
      continue;
    }
    const can::CanFrame& reply = response.reply;
    FUZZ_CHECK(reply.id == after.send_id && !reply.rtr && reply.extended == frame.extended,
               "reply on %x (extended %d), send ID %x, request extended %d", reply.id, reply.extended, after.send_id,
               frame.extended);
    if (request && command == 136 && frame.data[1] == 0) {
      FUZZ_CHECK(reply.dlc == 8 && std::memcmp(reply.data, fuzz::Tmcm1636::kIdentity.version_string, 8) == 0,
                 "version string reply of %u bytes", reply.dlc);
      continue;
    }
    FUZZ_CHECK(reply.dlc == (frame.dlc >= tmcl::kCanLongRequestLength ? 8 : 7), "reply of %u bytes to %u bytes",
               reply.dlc, frame.dlc);
    FUZZ_CHECK(reply.data[0] == (after.receive_id & 0xFF), "reply names receive ID %u, GP 71 is %u", reply.data[0],
               after.receive_id);
    const uint8_t status = reply.data[1];
    FUZZ_CHECK(tmcl::is_status_code(status),
               "reply status %u to command %u", status, command);
    if (command != 134) FUZZ_CHECK(reply.data[2] == command, "reply echoes command %u, request %u", reply.data[2], command);
    if (!request) {
      FUZZ_CHECK(status == 2 && reply.dlc == 7 && reply.data[3] == 0 && reply.data[4] == 0 && reply.data[5] == 0 &&
                     reply.data[6] == 0,
                 "a %u-byte request answered with status %u", frame.dlc, status);
    }
    if (response.reset_after_send) rig->engine.complete_reset();
    fuzz::check_parameter_ranges(rig->module, "after a CAN frame");
  }
  if (executed == 0) {
    const auto fresh = fuzz::fresh_rig<fuzz::Tmcm1636Rig, 1>();
    for (uint64_t t = 0; t < ticks; ++t) fresh->module.tick();
    FUZZ_CHECK(fuzz::probe_parameters(rig->module) == fuzz::probe_parameters(fresh->module),
               "frames that executed nothing changed a parameter");
    FUZZ_CHECK(std::memcmp(rig->nvm.data(), fresh->nvm.data(), rig->nvm.size()) == 0,
               "frames that executed nothing changed the EEPROM image");
  }
  return 0;
}

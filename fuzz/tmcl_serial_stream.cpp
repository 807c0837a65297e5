// TMCL 9-byte frames as a byte stream from a serial line or a TCP connection: framing with
// resynchronisation by pause, address filter, checksum, dispatch and reply encoding.
//
// Input: byte 0 sets where pauses longer than the resync gap fall (before every n-th byte, 0:
// never); the rest is the stream. Invariants:
// - frames are cut exactly where an independent model of the framing rules cuts them;
// - a frame for another address gets no reply; a frame with a bad checksum gets exactly the
//   status-1 reply; any other frame gets exactly one 9-byte reply with a valid checksum, the
//   echoed command and the module's (possibly just changed) addresses, except command 137
//   with 1234 (no reply) and command 136 type 0 (the version string);
// - a stream in which no frame was executed (garbage: wrong addresses, bad checksums, partial
//   frames) leaves every parameter readable as on a fresh module.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

#include "core/tmcl/serial_link.h"
#include "fuzz_support.h"

namespace {

using namespace motwin;

constexpr uint64_t kByteTimeUs = 87;  // one byte at 115200 bit/s
constexpr uint64_t kPauseUs = tmcl::SerialFrameDecoder::kDefaultResyncGapUs + 1000;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const unsigned pause_every = data[0];
  data += 1;
  size -= 1;

  auto rig = fuzz::fresh_rig<fuzz::Tmcm1636Rig>();
  tmcl::SerialFrameDecoder decoder;
  uint64_t now_us = 1000;
  size_t model_fill = 0;
  size_t executed = 0;

  for (size_t i = 0; i < size; ++i) {
    const bool pause = pause_every != 0 && i % pause_every == 0;
    now_us += pause ? kPauseUs : kByteTimeUs;
    if (pause) model_fill = 0;
    ++model_fill;
    const bool complete = decoder.push(data[i], now_us);
    FUZZ_CHECK(complete == (model_fill == tmcl::kFrameLength), "byte %zu: decoder %s a frame, model has %zu bytes", i,
               complete ? "completed" : "did not complete", model_fill);
    if (!complete) continue;
    model_fill = 0;

    const tmcl::Frame frame = decoder.frame();
    FUZZ_CHECK(std::memcmp(frame.data(), data + i + 1 - tmcl::kFrameLength, tmcl::kFrameLength) == 0,
               "frame ending at byte %zu is not the last 9 bytes of the stream", i);
    const tmcl::SerialSettings before = rig->module.serial_settings();
    const tmcl::SerialResponse response = tmcl::serve_serial_frame(rig->engine, frame, 0);
    if (frame[0] != before.module_address) {
      FUZZ_CHECK(response.length == 0, "frame for address %u (module is %u) was answered", frame[0],
                 before.module_address);
      continue;
    }
    if (tmcl::checksum(frame.data(), 8) != frame[8]) {
      const tmcl::Frame expected =
          tmcl::encode_reply(before.host_address, before.module_address, tmcl::Reply{1, 0, 0});
      FUZZ_CHECK(response.length == 9 && response.bytes == expected, "bad checksum not answered with status 1");
      continue;
    }
    ++executed;
    const tmcl::Instruction instruction = tmcl::decode_instruction(frame);
    const tmcl::SerialSettings after = rig->module.serial_settings();
    if (instruction.command == 137 && response.length == 0) {
      FUZZ_CHECK(instruction.value == 1234, "command 137 with value %d got no reply", instruction.value);
      continue;
    }
    FUZZ_CHECK(response.length == 9, "command %u got a reply of %u bytes", instruction.command, response.length);
    FUZZ_CHECK(response.bytes[0] == after.host_address, "reply to command %u: host address %u, expected %u",
               instruction.command, response.bytes[0], after.host_address);
    if (instruction.command == 136 && instruction.type == 0) {
      FUZZ_CHECK(std::memcmp(&response.bytes[1], fuzz::Tmcm1636::kIdentity.version_string, 8) == 0,
                 "version string reply");
      continue;
    }
    FUZZ_CHECK(response.bytes[1] == after.module_address, "reply to command %u: module address %u, expected %u",
               instruction.command, response.bytes[1], after.module_address);
    FUZZ_CHECK(tmcl::checksum(response.bytes.data(), 8) == response.bytes[8], "reply to command %u: checksum",
               instruction.command);
    const uint8_t status = response.bytes[2];
    FUZZ_CHECK(tmcl::is_status_code(status),
               "reply to command %u: status %u is no TMCL status", instruction.command, status);
    if (instruction.command != 134) {
      FUZZ_CHECK(response.bytes[3] == instruction.command, "reply echoes command %u instead of %u", response.bytes[3],
                 instruction.command);
    }
    if (response.reset_after_send) rig->engine.complete_reset();
  }

  if (executed == 0) {
    // Garbage only: read-only probes see a fresh module (probed once per process: a fresh rig is
    // the same every time).
    static const struct Fresh {
      std::vector<int32_t> parameters;
      fuzz::Tmcm1636Nvm nvm;
    }* const fresh = [] {
      const auto rig = std::make_unique<fuzz::Tmcm1636Rig>();
      auto* probe = new Fresh{fuzz::probe_parameters(rig->module), {}};
      std::memcpy(probe->nvm.mutable_data(), rig->nvm.data(), rig->nvm.size());
      return probe;
    }();
    FUZZ_CHECK(fuzz::probe_parameters(rig->module) == fresh->parameters,
               "a stream without one executed frame changed a parameter");
    FUZZ_CHECK(std::memcmp(rig->nvm.data(), fresh->nvm.data(), rig->nvm.size()) == 0,
               "a stream without one executed frame changed the EEPROM image");
  }
  fuzz::check_parameter_ranges(rig->module, "after the stream");
  return 0;
}

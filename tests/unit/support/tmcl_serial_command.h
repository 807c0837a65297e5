// One TMCL instruction to address 1 through an engine's serial link, its reply decoded: what the
// module rigs' command() helpers send. Without Google Test, so that the benchmarks drive the
// rigs too (tmcl_command.h adds the test helpers).
#pragma once

#include <cstdint>

#include "core/tmcl/engine.h"
#include "core/tmcl/instruction.h"
#include "core/tmcl/serial_link.h"

namespace motwin::testing {

inline tmcl::Reply serial_command(tmcl::TmclEngine& engine, uint8_t cmd, uint8_t type, uint8_t motor, int32_t value) {
  const auto response = tmcl::serve_serial_frame(engine, tmcl::encode_request(1, tmcl::Instruction{cmd, type, motor, value}), 0);
  const auto& b = response.bytes;
  const uint32_t v = (uint32_t{b[4]} << 24) | (uint32_t{b[5]} << 16) | (uint32_t{b[6]} << 8) | b[7];
  return tmcl::Reply{b[2], b[3], static_cast<int32_t>(v)};
}

}  // namespace motwin::testing

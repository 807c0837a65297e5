// One TMCL instruction to address 1 through an engine's serial link, its reply decoded: what the
// module rigs' command() helpers send.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>

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

// Downloads `program` from address 0 (commands 132, 133); every line must be taken (status 101).
// Rig: anything with command(cmd, type, motor, value) returning a tmcl::Reply.
template <class Rig>
void download_program(Rig& rig, std::initializer_list<tmcl::Instruction> program) {
  ASSERT_EQ(rig.command(tmcl::command::kEnterDownloadMode, 0, 0, 0).status, 100);
  for (const auto& in : program) ASSERT_EQ(rig.command(in.command, in.type, in.motor_bank, in.value).status, 101);
  ASSERT_EQ(rig.command(tmcl::command::kExitDownloadMode, 0, 0, 0).status, 100);
}

}  // namespace motwin::testing

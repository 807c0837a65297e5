// The TMCL helpers of the tests: serial_command() (tmcl_serial_command.h) and a program download.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>

#include "core/tmcl/instruction.h"
#include "tmcl_serial_command.h"

namespace motwin::testing {

// Downloads `program` from address 0 (commands 132, 133); every line must be taken (status 101).
// Rig: anything with command(cmd, type, motor, value) returning a tmcl::Reply.
template <class Rig>
void download_program(Rig& rig, std::initializer_list<tmcl::Instruction> program) {
  ASSERT_EQ(rig.command(tmcl::command::kEnterDownloadMode, 0, 0, 0).status, 100);
  for (const auto& in : program) ASSERT_EQ(rig.command(in.command, in.type, in.motor_bank, in.value).status, 101);
  ASSERT_EQ(rig.command(tmcl::command::kExitDownloadMode, 0, 0, 0).status, 100);
}

}  // namespace motwin::testing

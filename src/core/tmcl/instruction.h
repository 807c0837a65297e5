// One TMCL instruction: what a host sends (without address and checksum) and what program
// memory holds. The same struct runs from a host and from a stored program.
#pragma once

#include <cstdint>

namespace motwin::tmcl {

struct Instruction {
  uint8_t command = 0;
  uint8_t type = 0;
  uint8_t motor_bank = 0;
  int32_t value = 0;
};

// Where an instruction comes from. Direct-mode reads never touch the accumulator
// (TMCM-1636 manual 2.5.5); the interpreter loads it from CommandResult::value instead.
enum class Origin : uint8_t { kHost, kProgram };

// TMCL command numbers (TMCM-1636 manual table 4 and table 10; docs/tmcl-protocol.md "Code tables",
// "Control commands").
namespace command {
inline constexpr uint8_t kNop = 0;
inline constexpr uint8_t kRor = 1;
inline constexpr uint8_t kRol = 2;
inline constexpr uint8_t kMst = 3;
inline constexpr uint8_t kMvp = 4;
inline constexpr uint8_t kSap = 5;
inline constexpr uint8_t kGap = 6;
inline constexpr uint8_t kStap = 7;
inline constexpr uint8_t kRsap = 8;
inline constexpr uint8_t kSgp = 9;
inline constexpr uint8_t kGgp = 10;
inline constexpr uint8_t kStgp = 11;
inline constexpr uint8_t kRsgp = 12;
inline constexpr uint8_t kRfs = 13;
inline constexpr uint8_t kSio = 14;
inline constexpr uint8_t kGio = 15;
inline constexpr uint8_t kCalc = 19;
inline constexpr uint8_t kComp = 20;
inline constexpr uint8_t kJc = 21;
inline constexpr uint8_t kJa = 22;
inline constexpr uint8_t kCsub = 23;
inline constexpr uint8_t kRsub = 24;
inline constexpr uint8_t kEi = 25;
inline constexpr uint8_t kDi = 26;
inline constexpr uint8_t kWait = 27;
inline constexpr uint8_t kStop = 28;
inline constexpr uint8_t kSco = 30;
inline constexpr uint8_t kGco = 31;
inline constexpr uint8_t kCco = 32;
inline constexpr uint8_t kCalcx = 33;
inline constexpr uint8_t kAap = 34;
inline constexpr uint8_t kAgp = 35;
inline constexpr uint8_t kCle = 36;
inline constexpr uint8_t kVect = 37;
inline constexpr uint8_t kReti = 38;
inline constexpr uint8_t kAco = 39;
inline constexpr uint8_t kStopApplication = 128;
inline constexpr uint8_t kRunApplication = 129;
inline constexpr uint8_t kStepApplication = 130;
inline constexpr uint8_t kResetApplication = 131;
inline constexpr uint8_t kEnterDownloadMode = 132;
inline constexpr uint8_t kExitDownloadMode = 133;
inline constexpr uint8_t kReadProgramMemory = 134;
inline constexpr uint8_t kGetApplicationStatus = 135;
inline constexpr uint8_t kGetFirmwareVersion = 136;
inline constexpr uint8_t kRestoreFactoryDefaults = 137;
inline constexpr uint8_t kRequestPositionReachedEvent = 138;
inline constexpr uint8_t kEnterAsciiMode = 139;
inline constexpr uint8_t kRamDebug = 142;  // the datalogger (docs/datalogger.md)
inline constexpr uint8_t kGetInfo = 157;   // firmware facts by id (docs/datalogger.md "Command 157")
inline constexpr uint8_t kSoftwareReset = 255;
}  // namespace command

// MVP types.
namespace move_type {
inline constexpr uint8_t kAbsolute = 0;
inline constexpr uint8_t kRelative = 1;
inline constexpr uint8_t kCoordinate = 2;
}  // namespace move_type

// RFS types.
namespace rfs_type {
inline constexpr uint8_t kStart = 0;
inline constexpr uint8_t kStop = 1;
inline constexpr uint8_t kStatus = 2;  // value 0 when done, non-zero while running
}  // namespace rfs_type

// Value that commands 137 and 255 require (manual table 10).
inline constexpr int32_t kResetMagic = 1234;

}  // namespace motwin::tmcl

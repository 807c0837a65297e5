// TMCL reply status codes (TMCM-1636 manual table 3, docs/tmcl-protocol.md "Status codes").
#pragma once

#include <cstdint>

namespace motwin::tmcl {

enum class Status : uint8_t {
  kChecksumError = 1,
  kInvalidCommand = 2,
  kWrongType = 3,        // also: unknown parameter number, read-only parameter written
  kInvalidValue = 4,     // also: motor or bank number out of range
  kEepromLocked = 5,     // also: the EEPROM image could not be written
  kNotAvailable = 6,
  kMaxExceeded = 9,      // the datalogger's (command 142) "maximum exceeded" (docs/datalogger.md)
  kOk = 100,
  kStoredInProgram = 101,
  kPositionReachedEvent = 128,  // second, delayed reply of command 138
};

constexpr uint8_t to_byte(Status status) { return static_cast<uint8_t>(status); }

constexpr const char* status_name(uint8_t code) {
  switch (code) {
    case 1: return "wrong checksum";
    case 2: return "invalid command";
    case 3: return "wrong type";
    case 4: return "invalid value";
    case 5: return "configuration EEPROM locked";
    case 6: return "command not available";
    case 9: return "maximum exceeded";
    case 100: return "ok";
    case 101: return "command stored";
    case 128: return "position reached";
    default: return "unknown status";
  }
}

constexpr bool is_success(uint8_t code) { return code == 100 || code == 101 || code == 128; }

// A code of the enum above: what a reply may carry.
constexpr bool is_status_code(uint8_t code) { return is_success(code) || (code >= 1 && code <= 6) || code == 9; }

}  // namespace motwin::tmcl

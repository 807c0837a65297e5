// The TMCL registers shared by direct mode and stored programs: accumulator, X register,
// comparison result and error flags (docs/tmcl-protocol.md "Interpreter model"). Direct-mode CLE
// clears the same flags a program tests with JC.
#pragma once

#include <cstdint>

namespace motwin::tmcl {

// CLE / JC error flag bits.
enum ErrorFlag : uint8_t {
  kErrorTimeout = 1 << 0,        // ETO: a WAIT timed out
  kErrorExternalAlarm = 1 << 1,  // EAL
  kErrorDeviation = 1 << 2,      // EDV: encoder deviation
  kErrorPosition = 1 << 3,       // EPO
  kErrorShutdown = 1 << 4,       // ESD
};

// GP 128 values.
enum class ApplicationStatus : uint8_t { kStopped = 0, kRunning = 1, kStepping = 2, kReset = 3 };

struct TmclRuntime {
  int32_t accumulator = 0;
  int32_t x_register = 0;
  uint8_t error_flags = 0;
  // Operands of the last COMP (JC evaluates its condition on them).
  int32_t compare_accumulator = 0;
  int32_t compare_operand = 0;
  ApplicationStatus application_status = ApplicationStatus::kStopped;
  uint32_t program_counter = 0;
  bool download_mode = false;       // GP 129
  uint32_t download_address = 0;    // next address a downloaded instruction goes to
  uint8_t last_error = 0;           // status of the last failed command (TMCM-142 GP 131), 0: none

  // Command 131: registers, flags and program counter cleared (download state and last error kept).
  void clear_registers() {
    const bool download = download_mode;
    const uint32_t address = download_address;
    const uint8_t error = last_error;
    *this = TmclRuntime{};
    download_mode = download;
    download_address = address;
    last_error = error;
  }
};

}  // namespace motwin::tmcl

// Test hook MOTWIN_CRASH_AT_PERSIST_STEP=STEP[:N] (docs/host-runtime.md, "Crash-point hook"):
// the process SIGKILLs itself just before step STEP of the Nth EEPROM image write it starts
// (N from 1, default 1; every image write of every module counts, the factory image written at
// start-up included), with no cleanup, so the files are left exactly as a crash at that point
// leaves them. It makes the kill -9 tests deterministic
// (tests/integration/test_fault_crash_points.py); it is never set in normal use.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "host/eeprom_file.h"
#include "types/result.h"

namespace motwin::host {

inline constexpr char kCrashAtPersistStepVariable[] = "MOTWIN_CRASH_AT_PERSIST_STEP";

struct PersistCrashPoint {
  PersistStep step;
  uint64_t persist_number;  // 1: the first image write the process starts
};

// "open-temporary", "write-temporary", "sync-temporary", "rename", "sync-directory".
std::string_view persist_step_name(PersistStep step);

// "write-temporary", "rename:3" ...; anything else (an unknown step, N of 0, a sign, spaces, a
// number that does not fit) fails with a message saying what was expected.
Result<PersistCrashPoint> parse_persist_crash_point(std::string_view text);

// Reads the variable (once, at start-up): unset or empty installs nothing; a valid value makes
// the crash the process's persist observer (EepromFile::set_process_persist_observer). A bad
// value fails: a start-up error.
Result<void> install_persist_crash_hook_from_environment();

}  // namespace motwin::host

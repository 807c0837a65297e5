#include "core/tmcl/engine.h"

#include "core/tmcl/ascii_link.h"

namespace motwin::tmcl {
namespace {

CommandResult status_only(Status status, int32_t echo) { return CommandResult{status, echo, ReplyKind::kNormal, false}; }

CommandResult read_result(Status status, int32_t value, int32_t echo) {
  if (status != Status::kOk) return status_only(status, echo);
  return CommandResult{Status::kOk, value, ReplyKind::kNormal, true};
}

// CLE types (docs/tmcl-protocol.md "Code tables"): ALL 0, ETO 1, EAL 2, EDV 3, EPO 4, ESD 5.
constexpr uint8_t kCleMasks[] = {0xFF, kErrorTimeout, kErrorExternalAlarm, kErrorDeviation, kErrorPosition,
                                 kErrorShutdown};

// CALC/CALCX operations (docs/tmcl-protocol.md "Code tables"): ADD 0 .. LOAD 9, CALCX adds SWAP 10.
// Arithmetic wraps as 32-bit two's complement. Division or modulo by zero leaves the accumulator
// unchanged and answers status 4 (docs/decisions.md).
Status calculate(TmclRuntime& r, uint8_t operation, int32_t operand, bool with_x) {
  const auto a = static_cast<uint32_t>(r.accumulator);
  const auto b = static_cast<uint32_t>(operand);
  switch (operation) {
    case 0: r.accumulator = static_cast<int32_t>(a + b); return Status::kOk;
    case 1: r.accumulator = static_cast<int32_t>(a - b); return Status::kOk;
    case 2: r.accumulator = static_cast<int32_t>(a * b); return Status::kOk;
    case 3:
    case 4:
      if (operand == 0) return Status::kInvalidValue;
      if (r.accumulator == INT32_MIN && operand == -1) {  // the one overflowing quotient
        r.accumulator = operation == 3 ? INT32_MIN : 0;
      } else {
        r.accumulator = operation == 3 ? r.accumulator / operand : r.accumulator % operand;
      }
      return Status::kOk;
    case 5: r.accumulator = static_cast<int32_t>(a & b); return Status::kOk;
    case 6: r.accumulator = static_cast<int32_t>(a | b); return Status::kOk;
    case 7: r.accumulator = static_cast<int32_t>(a ^ b); return Status::kOk;
    case 8:
      if (with_x) {
        r.x_register = static_cast<int32_t>(~static_cast<uint32_t>(r.x_register));
      } else {
        r.accumulator = static_cast<int32_t>(~a);
      }
      return Status::kOk;
    case 9:
      if (with_x) {
        r.x_register = r.accumulator;
      } else {
        r.accumulator = operand;
      }
      return Status::kOk;
    case 10:
      if (!with_x) return Status::kWrongType;
      {
        const int32_t accumulator = r.accumulator;
        r.accumulator = r.x_register;
        r.x_register = accumulator;
      }
      return Status::kOk;
    default:
      return Status::kWrongType;
  }
}

// Bank 3 (interrupt configuration) belongs to the interpreter on every TMCL module.
constexpr uint8_t kInterruptBank = 3;

bool is_control_command(uint8_t command) {
  return (command >= command::kStopApplication && command <= command::kEnterAsciiMode) ||
         command == command::kSoftwareReset;
}

}  // namespace

void TmclEngine::power_up() {
  ++power_up_count_;
  events_ = {};
  device_.power_up();
  ProgramMemory* memory = device_.program_memory();
  if (memory != nullptr) memory->load();
  interpreter_.reset();
  device_.runtime().application_status = ApplicationStatus::kStopped;
  if (memory != nullptr && device_.autostart()) interpreter_.run(true, 0);
}

// Download mode (command 132): instructions from the host are stored, not executed, and
// answered with status 101 (docs/tmcl-protocol.md "Control commands").
CommandResult TmclEngine::store_downloaded(const Instruction& in) {
  TmclRuntime& runtime = device_.runtime();
  ProgramMemory* memory = device_.program_memory();
  if (memory == nullptr || !memory->stage(runtime.download_address, in)) return status_only(Status::kInvalidValue, in.value);
  ++runtime.download_address;
  return status_only(Status::kStoredInProgram, in.value);
}

// Commands 128..135 (manual table 10).
CommandResult TmclEngine::control_command(const Instruction& in) {
  TmclRuntime& runtime = device_.runtime();
  ProgramMemory* memory = device_.program_memory();
  if (memory == nullptr) return status_only(Status::kInvalidCommand, in.value);
  switch (in.command) {
    case command::kStopApplication:
      return status_only(interpreter_.stop(), in.value);
    case command::kRunApplication:
      if (in.type > 1) return status_only(Status::kWrongType, in.value);
      return status_only(interpreter_.run(in.type == 1, static_cast<uint32_t>(in.value)), in.value);
    case command::kStepApplication:
      return status_only(interpreter_.step(), in.value);
    case command::kResetApplication:
      interpreter_.reset();
      return status_only(Status::kOk, in.value);
    case command::kEnterDownloadMode:
      if (static_cast<uint32_t>(in.value) >= memory->capacity()) return status_only(Status::kInvalidValue, in.value);
      interpreter_.stop();
      runtime.download_mode = true;
      runtime.download_address = static_cast<uint32_t>(in.value);
      return status_only(Status::kOk, in.value);
    case command::kExitDownloadMode: {
      const bool was_downloading = runtime.download_mode;
      runtime.download_mode = false;
      if (was_downloading && !memory->commit()) return status_only(Status::kEepromLocked, in.value);
      return status_only(Status::kOk, in.value);
    }
    case command::kReadProgramMemory: {
      // Reply layout (docs/tmcl-programs.md): type 0 -> command byte = stored opcode, value =
      // stored value; type 1 -> command byte = stored opcode, value = type << 8 | motor.
      Instruction stored;
      if (in.type > 1) return status_only(Status::kWrongType, in.value);
      if (!memory->read(static_cast<uint32_t>(in.value), stored)) return status_only(Status::kInvalidValue, in.value);
      CommandResult result{Status::kOk, in.type == 0 ? stored.value : (stored.type << 8) | stored.motor_bank,
                           ReplyKind::kNormal, false};
      result.reply_command = stored.command;
      return result;
    }
    case command::kGetApplicationStatus: {
      const auto mode = static_cast<uint32_t>(runtime.application_status);
      const uint32_t wait = interpreter_.waiting() ? 1u : 0u;
      switch (in.type) {
        case 0: return CommandResult{Status::kOk, static_cast<int32_t>((mode << 24) | (wait << 16) | (runtime.download_address & 0xFFFF)), ReplyKind::kNormal, false};
        case 1: return CommandResult{Status::kOk, static_cast<int32_t>((mode << 24) | (wait << 16) | (runtime.program_counter & 0xFFFF)), ReplyKind::kNormal, false};
        case 2: return CommandResult{Status::kOk, runtime.accumulator, ReplyKind::kNormal, false};
        case 3: return CommandResult{Status::kOk, runtime.x_register, ReplyKind::kNormal, false};
        case 4: return CommandResult{Status::kOk, static_cast<int32_t>((static_cast<uint32_t>(interpreter_.stop_reason()) << 16) | (interpreter_.stop_address() & 0xFFFF)), ReplyKind::kNormal, false};
        default: return status_only(Status::kWrongType, in.value);
      }
    }
    default:
      return status_only(Status::kInvalidCommand, in.value);
  }
}

// The steps of one instruction: download mode stores it, the program-control commands and the
// interrupt bank are the engine's own, everything else goes to its command family.
// Every failed command, from a host or a program, leaves its status for GP 131 of the modules
// that list it (the TMCM-142). A wrong checksum never reaches the engine (the links answer it).
CommandResult TmclEngine::execute(const Instruction& in, Origin origin, ChannelId channel) {
  const CommandResult result = dispatch(in, origin, channel);
  if (!is_success(to_byte(result.status))) device_.runtime().last_error = to_byte(result.status);
  return result;
}

CommandResult TmclEngine::dispatch(const Instruction& in, Origin origin, ChannelId channel) {
  if (origin == Origin::kHost && device_.runtime().download_mode && !is_control_command(in.command)) {
    return store_downloaded(in);
  }
  if (in.command >= command::kStopApplication && in.command <= command::kGetApplicationStatus) {
    if (origin == Origin::kProgram) return status_only(Status::kInvalidCommand, in.value);
    return control_command(in);
  }
  if (is_interrupt_configuration(in)) return interrupt_configuration(in);
  switch (in.command) {
    case command::kRor:
    case command::kRol:
    case command::kMst:
    case command::kMvp:
      return motion_command(in);
    case command::kSap:
    case command::kGap:
    case command::kStap:
    case command::kRsap:
    case command::kAap:
      return axis_parameter_command(in);
    case command::kSgp:
    case command::kGgp:
    case command::kStgp:
    case command::kRsgp:
    case command::kAgp:
      return global_parameter_command(in);
    case command::kSio:
    case command::kGio:
    case command::kRfs:
    case command::kSco:
    case command::kAco:
    case command::kGco:
    case command::kCco:
      return device_command(in);
    case command::kNop:
    case command::kCalc:
    case command::kCalcx:
    case command::kComp:
    case command::kCle:
      return register_command(in);
    // Program flow makes no sense from a host (manual 2.5.3): "command not available".
    case command::kJc:
    case command::kJa:
    case command::kCsub:
    case command::kRsub:
    case command::kWait:
    case command::kStop:
      return status_only(Status::kNotAvailable, in.value);
    case command::kGetFirmwareVersion:
    case command::kRestoreFactoryDefaults:
    case command::kRequestPositionReachedEvent:
    case command::kEnterAsciiMode:
    case command::kSoftwareReset:
      return module_command(in, channel);
    case command::kRamDebug:
    case command::kGetInfo: {
      // Direct mode only: a stored program never gets here (the interpreter stops at any
      // command >= 128 with "invalid instruction").
      int32_t value = in.value;
      const Status status = in.command == command::kRamDebug ? device_.ram_debug(in.type, in.motor_bank, value)
                                                             : device_.get_info(in.type, in.motor_bank, value);
      return status_only(status, status == Status::kOk ? value : in.value);
    }
    default:
      return status_only(Status::kInvalidCommand, in.value);
  }
}

// Interrupt configuration: SGP/GGP/AGP on bank 3 belong to the interpreter.
bool TmclEngine::is_interrupt_configuration(const Instruction& in) {
  return in.motor_bank == kInterruptBank &&
         (in.command == command::kSgp || in.command == command::kGgp || in.command == command::kAgp);
}

CommandResult TmclEngine::interrupt_configuration(const Instruction& in) {
  if (in.command == command::kGgp) {
    int32_t value = 0;
    const Status status = interpreter_.get_interrupt_parameter(in.type, value);
    return read_result(status, value, in.value);
  }
  const int32_t value = in.command == command::kSgp ? in.value : device_.runtime().accumulator;
  return status_only(interpreter_.set_interrupt_parameter(in.type, value), in.value);
}

// ROR, ROL, MST, MVP on a motor of the module.
CommandResult TmclEngine::motion_command(const Instruction& in) {
  const int32_t echo = in.value;
  if (in.motor_bank >= device_.motor_count()) return status_only(Status::kInvalidValue, echo);
  switch (in.command) {
    case command::kRor:
      return status_only(device_.rotate(in.motor_bank, in.value), echo);
    case command::kRol:
      // ROL negates; -INT32_MIN does not fit and is out of every velocity range anyway.
      if (in.value == INT32_MIN) return status_only(Status::kInvalidValue, echo);
      return status_only(device_.rotate(in.motor_bank, -in.value), echo);
    case command::kMst:
      return status_only(device_.stop(in.motor_bank), echo);
    default:  // MVP
      return status_only(device_.move(in.motor_bank, in.type, in.value), echo);
  }
}

// SAP, GAP, STAP, RSAP, AAP on a motor of the module.
CommandResult TmclEngine::axis_parameter_command(const Instruction& in) {
  const int32_t echo = in.value;
  if (in.motor_bank >= device_.motor_count()) return status_only(Status::kInvalidValue, echo);
  switch (in.command) {
    case command::kSap:
      return status_only(device_.set_axis_parameter(in.type, in.motor_bank, in.value), echo);
    case command::kGap: {
      int32_t value = 0;
      const Status status = device_.get_axis_parameter(in.type, in.motor_bank, value);
      return read_result(status, value, echo);
    }
    case command::kStap:
      return status_only(device_.store_axis_parameter(in.type, in.motor_bank), echo);
    case command::kRsap:
      return status_only(device_.restore_axis_parameter(in.type, in.motor_bank), echo);
    default:  // AAP
      return status_only(device_.set_axis_parameter(in.type, in.motor_bank, device_.runtime().accumulator), echo);
  }
}

// SGP, GGP, STGP, RSGP, AGP: the bank is the device's to check.
CommandResult TmclEngine::global_parameter_command(const Instruction& in) {
  const int32_t echo = in.value;
  switch (in.command) {
    case command::kSgp:
      return status_only(device_.set_global_parameter(in.type, in.motor_bank, in.value), echo);
    case command::kGgp: {
      int32_t value = 0;
      const Status status = device_.get_global_parameter(in.type, in.motor_bank, value);
      return read_result(status, value, echo);
    }
    case command::kStgp:
      return status_only(device_.store_global_parameter(in.type, in.motor_bank), echo);
    case command::kRsgp:
      return status_only(device_.restore_global_parameter(in.type, in.motor_bank), echo);
    default:  // AGP
      return status_only(device_.set_global_parameter(in.type, in.motor_bank, device_.runtime().accumulator), echo);
  }
}

// SIO, GIO, RFS and the coordinates: the motor or bank byte is the device's to check, so that a
// module without RFS or coordinates answers status 2 whatever the operands (255 selects the
// coordinates' EEPROM copies).
CommandResult TmclEngine::device_command(const Instruction& in) {
  const int32_t echo = in.value;
  int32_t value = 0;
  switch (in.command) {
    case command::kSio:
      return status_only(device_.set_output(in.type, in.motor_bank, in.value), echo);
    case command::kGio: {
      const Status status = device_.get_input(in.type, in.motor_bank, value);
      return read_result(status, value, echo);
    }
    case command::kRfs: {
      const Status status = device_.reference_search(in.motor_bank, in.type, value);
      // STATUS is a read (a program loads the accumulator); START and STOP echo the operand.
      if (in.type == 2) return read_result(status, value, echo);
      return status_only(status, echo);
    }
    case command::kSco:
      return status_only(device_.set_coordinate(in.type, in.motor_bank, in.value), echo);
    case command::kAco:
      return status_only(device_.set_coordinate(in.type, in.motor_bank, device_.runtime().accumulator), echo);
    case command::kGco: {
      const Status status = device_.get_coordinate(in.type, in.motor_bank, value);
      return read_result(status, value, echo);
    }
    default:  // CCO
      return status_only(device_.capture_coordinate(in.type, in.motor_bank), echo);
  }
}

// NOP, CALC, CALCX, COMP, CLE: the registers shared with a running program.
CommandResult TmclEngine::register_command(const Instruction& in) {
  const int32_t echo = in.value;
  TmclRuntime& runtime = device_.runtime();
  switch (in.command) {
    case command::kCalc:
      return status_only(calculate(runtime, in.type, in.value, false), echo);
    case command::kCalcx:
      return status_only(calculate(runtime, in.type, runtime.x_register, true), echo);
    case command::kComp:
      runtime.compare_accumulator = runtime.accumulator;
      runtime.compare_operand = in.value;
      return status_only(Status::kOk, echo);
    case command::kCle:
      if (in.type >= sizeof(kCleMasks)) return status_only(Status::kWrongType, echo);
      runtime.error_flags &= static_cast<uint8_t>(~kCleMasks[in.type]);
      return status_only(Status::kOk, echo);
    default:  // NOP
      return status_only(Status::kOk, echo);
  }
}

// Commands 136, 137, 138, 139 and 255: firmware version, factory defaults, the position event,
// ASCII mode and reset.
CommandResult TmclEngine::module_command(const Instruction& in, ChannelId channel) {
  const int32_t echo = in.value;
  switch (in.command) {
    case command::kGetFirmwareVersion:
      if (in.type == 0) return CommandResult{Status::kOk, echo, ReplyKind::kVersionString, false};
      if (in.type == 1) return CommandResult{Status::kOk, device_.identity().binary_version(), ReplyKind::kNormal, false};
      return status_only(Status::kWrongType, echo);
    case command::kRestoreFactoryDefaults:
      // Manual table 10: value 1234, no reply. A wrong value is answered (status 4) so that a
      // host waiting for a reply is not left hanging (docs/decisions.md).
      if (in.value != kResetMagic) return status_only(Status::kInvalidValue, echo);
      device_.restore_factory_defaults();
      power_up();
      return CommandResult{Status::kOk, echo, ReplyKind::kNone, false};
    case command::kRequestPositionReachedEvent:
      return request_position_event(in, channel);
    case command::kEnterAsciiMode: {
      // Only on modules with the ASCII interface: their global table has GP 67 (ascii_link.h).
      int32_t configuration = 0;
      if (device_.get_global_parameter(ascii_config::kGlobalParameter, 0, configuration) != Status::kOk) {
        return status_only(Status::kInvalidCommand, echo);
      }
      return CommandResult{Status::kOk, echo, ReplyKind::kThenAsciiMode, false};
    }
    default:  // 255
      if (in.value != kResetMagic) return status_only(Status::kInvalidValue, echo);
      return CommandResult{Status::kOk, echo, ReplyKind::kThenReset, false};
  }
}

// Command 138: value = bit mask of motors (bit n = motor n). The normal reply goes out now;
// a second reply (status 128, command 138, value = mask) when all of them have reached their
// target position (docs/decisions.md).
CommandResult TmclEngine::request_position_event(const Instruction& in, ChannelId channel) {
  const uint32_t all_motors = (1u << device_.motor_count()) - 1u;
  const auto mask = static_cast<uint32_t>(in.value);
  if (mask == 0 || (mask & ~all_motors) != 0) return status_only(Status::kInvalidValue, in.value);
  for (auto& event : events_) {
    if (event.active && event.channel == channel && event.motor_mask == mask) return status_only(Status::kOk, in.value);
  }
  for (auto& event : events_) {
    if (!event.active) {
      event = PendingEvent{true, channel, mask};
      return status_only(Status::kOk, in.value);
    }
  }
  return status_only(Status::kInvalidValue, in.value);  // all slots taken
}

void TmclEngine::collect_events(ReplySink& sink) {
  for (auto& event : events_) {
    if (!event.active) continue;
    bool reached = true;
    for (uint8_t motor = 0; motor < device_.motor_count(); ++motor) {
      if ((event.motor_mask & (1u << motor)) != 0 && !device_.position_reached(motor)) reached = false;
    }
    if (!reached) continue;
    event.active = false;
    sink.deliver(event.channel, Reply{to_byte(Status::kPositionReachedEvent), command::kRequestPositionReachedEvent,
                                      static_cast<int32_t>(event.motor_mask)});
  }
}

void TmclEngine::forget_channel(ChannelId channel) {
  for (auto& event : events_) {
    if (event.channel == channel) event.active = false;
  }
}

void TmclEngine::complete_reset() { power_up(); }

size_t TmclEngine::pending_event_count() const {
  size_t n = 0;
  for (const auto& event : events_) n += event.active ? 1 : 0;
  return n;
}

}  // namespace motwin::tmcl

#include "core/tmcl/interpreter.h"

#include "core/tmcl/device.h"
#include "core/tmcl/engine.h"

namespace motwin::tmcl {
namespace {

// WAIT conditions.
constexpr uint8_t kWaitTicks = 0;
constexpr uint8_t kWaitPosition = 1;
constexpr uint8_t kWaitReferenceSwitch = 2;
constexpr uint8_t kWaitLimitSwitch = 3;
constexpr uint8_t kWaitReferenceSearch = 4;

// Bank 3 numbers of the timer periods.
constexpr uint8_t kTimerPeriodParameters = 3;

}  // namespace

const char* stop_reason_text(StopReason reason) {
  switch (reason) {
    case StopReason::kNone: return "not stopped";
    case StopReason::kStopInstruction: return "STOP instruction";
    case StopReason::kHostStop: return "stopped by the host";
    case StopReason::kJumpOutsideProgram: return "jump, call or return outside program memory";
    case StopReason::kEndOfMemory: return "ran past the end of program memory";
    case StopReason::kDamagedInstruction: return "damaged instruction record (checksum)";
    case StopReason::kInvalidInstruction: return "instruction that cannot run in a program";
  }
  return "unknown";
}

TmclInterpreter::TmclInterpreter(TmclEngine& engine)
    : engine_(engine), device_(engine.device()), runtime_(engine.device().runtime()) {}

Status TmclInterpreter::stop() {
  if (runtime_.application_status == ApplicationStatus::kRunning ||
      runtime_.application_status == ApplicationStatus::kStepping) {
    runtime_.application_status = ApplicationStatus::kStopped;
    stop_reason_ = StopReason::kHostStop;
    stop_address_ = runtime_.program_counter;
  }
  wait_.active = false;
  step_pending_ = false;
  return Status::kOk;
}

Status TmclInterpreter::run(bool from_address, uint32_t address) {
  ProgramMemory* memory = device_.program_memory();
  if (memory == nullptr) return Status::kNotAvailable;
  if (from_address) {
    if (address >= memory->capacity()) return Status::kInvalidValue;
    runtime_.program_counter = address;
    wait_.active = false;
  }
  runtime_.application_status = ApplicationStatus::kRunning;
  stop_reason_ = StopReason::kNone;
  step_pending_ = false;
  return Status::kOk;
}

Status TmclInterpreter::step() {
  if (device_.program_memory() == nullptr) return Status::kNotAvailable;
  runtime_.application_status = ApplicationStatus::kStepping;
  stop_reason_ = StopReason::kNone;
  step_pending_ = true;
  return Status::kOk;
}

// Command 131: program stopped, PC and stack at 0, registers and flags cleared.
void TmclInterpreter::reset() {
  runtime_.clear_registers();
  runtime_.application_status = ApplicationStatus::kReset;
  stack_size_ = 0;
  wait_ = WaitState{};
  step_pending_ = false;
  stop_reason_ = StopReason::kNone;
  in_interrupt_ = false;
  interrupts_enabled_ = false;
  levels_primed_ = false;
  enabled_.fill(false);
  pending_.fill(false);
}

void TmclInterpreter::halt(StopReason reason, uint32_t address) {
  runtime_.application_status = ApplicationStatus::kStopped;
  stop_reason_ = reason;
  stop_address_ = address;
  wait_.active = false;
  step_pending_ = false;
}

bool TmclInterpreter::jump(uint32_t address) {
  const ProgramMemory* memory = device_.program_memory();
  if (memory == nullptr || address >= memory->capacity()) {
    halt(StopReason::kJumpOutsideProgram, runtime_.program_counter - 1);  // the jumping instruction
    return false;
  }
  runtime_.program_counter = address;
  return true;
}

int32_t TmclInterpreter::operand_or_accumulator(int32_t value) const {
  return value == -1 ? runtime_.accumulator : value;
}

void TmclInterpreter::tick(uint64_t now_us) {
  const bool running = runtime_.application_status == ApplicationStatus::kRunning;
  if (running && interrupts_enabled_) sample_interrupt_sources(now_us);
  if (running && !in_interrupt_ && interrupts_enabled_ && enter_pending_interrupt()) return;
  if (wait_.active) {
    service_wait(now_us);
    return;
  }
  if (running || (runtime_.application_status == ApplicationStatus::kStepping && step_pending_)) {
    step_pending_ = false;
    execute_next(now_us);
  }
}

void TmclInterpreter::execute_next(uint64_t now_us) {
  ProgramMemory* memory = device_.program_memory();
  if (memory == nullptr) return;
  const uint32_t address = runtime_.program_counter;
  if (address >= memory->capacity()) {
    halt(StopReason::kEndOfMemory, address);
    return;
  }
  Instruction instruction;
  if (!memory->read(address, instruction)) {
    halt(StopReason::kDamagedInstruction, address);
    return;
  }
  runtime_.program_counter = address + 1;
  ++instructions_executed_;
  execute(instruction, now_us);
}

void TmclInterpreter::execute(const Instruction& in, uint64_t now_us) {
  const uint32_t address = runtime_.program_counter - 1;
  switch (in.command) {
    case command::kNop:
      return;
    case command::kJa:
      jump(static_cast<uint32_t>(in.value));
      return;
    case command::kJc:
      if (in.type > 12) {
        halt(StopReason::kInvalidInstruction, address);
      } else if (condition_holds(in.type)) {
        jump(static_cast<uint32_t>(in.value));
      }
      return;
    case command::kCsub:
      // Manual 2.6.19: a call beyond the stack depth is ignored.
      if (stack_size_ < kStackDepth) {
        const uint32_t return_address = runtime_.program_counter;
        if (jump(static_cast<uint32_t>(in.value))) stack_[stack_size_++] = return_address;
      }
      return;
    case command::kRsub:
      // Manual 2.6.20: ignored on an empty stack.
      if (stack_size_ > 0) jump(stack_[--stack_size_]);
      return;
    case command::kWait:
      begin_wait(in, now_us);
      return;
    case command::kStop:
      halt(StopReason::kStopInstruction, address);
      return;
    case command::kVect:
      if (in.type >= vector::kCount) {
        halt(StopReason::kInvalidInstruction, address);
        return;
      }
      {
        const ProgramMemory* memory = device_.program_memory();
        if (static_cast<uint32_t>(in.value) >= memory->capacity()) {
          halt(StopReason::kJumpOutsideProgram, address);
          return;
        }
      }
      vectors_[in.type] = static_cast<uint32_t>(in.value);
      vector_set_[in.type] = true;
      return;
    case command::kEi:
    case command::kDi: {
      const bool enable = in.command == command::kEi;
      if (enable) {
        // Periods and edges count from the moment of enabling, not from power-up.
        if (in.type == vector::kGlobal || in.type < timer_last_us_.size()) timer_last_us_.fill(now_us);
        levels_primed_ = false;
      }
      if (in.type == vector::kGlobal) {
        interrupts_enabled_ = enable;
      } else if (in.type < vector::kCount) {
        enabled_[in.type] = enable;
        if (!enable) pending_[in.type] = false;
      } else {
        halt(StopReason::kInvalidInstruction, address);
      }
      return;
    }
    case command::kReti:
      if (!in_interrupt_) return;  // RETI outside an interrupt routine: ignored
      runtime_.program_counter = saved_.program_counter;
      runtime_.accumulator = saved_.accumulator;
      runtime_.x_register = saved_.x_register;
      runtime_.compare_accumulator = saved_.compare_accumulator;
      runtime_.compare_operand = saved_.compare_operand;
      wait_ = saved_.wait;
      in_interrupt_ = false;
      return;
    default:
      break;
  }
  if (in.command >= command::kStopApplication) {  // control commands exist in direct mode only
    halt(StopReason::kInvalidInstruction, address);
    return;
  }
  const CommandResult result = engine_.execute(in, Origin::kProgram);
  if (result.status == Status::kInvalidCommand) {
    halt(StopReason::kInvalidInstruction, address);
    return;
  }
  // Other errors (a value out of range, say) are not fatal: the instruction has no effect,
  // as on the real module, and the program continues.
  if (result.loads_accumulator) runtime_.accumulator = result.value;
}

// JC conditions (docs/tmcl-protocol.md "Code tables"): ZE/NZ/EQ/NE/GT/GE/LT/LE on the last COMP,
// then the error flags. ZE and NZ test the difference of the COMP operands for zero, i.e. they
// equal EQ and NE.
bool TmclInterpreter::condition_holds(uint8_t condition) const {
  const int32_t a = runtime_.compare_accumulator;
  const int32_t b = runtime_.compare_operand;
  switch (condition) {
    case 0: case 2: return a == b;
    case 1: case 3: return a != b;
    case 4: return a > b;
    case 5: return a >= b;
    case 6: return a < b;
    case 7: return a <= b;
    case 8: return (runtime_.error_flags & kErrorTimeout) != 0;
    case 9: return (runtime_.error_flags & kErrorExternalAlarm) != 0;
    case 10: return (runtime_.error_flags & kErrorDeviation) != 0;
    case 11: return (runtime_.error_flags & kErrorPosition) != 0;
    case 12: return (runtime_.error_flags & kErrorShutdown) != 0;
    default: return false;
  }
}

void TmclInterpreter::begin_wait(const Instruction& in, uint64_t now_us) {
  if (in.type > kWaitReferenceSearch || (in.type != kWaitTicks && in.motor_bank >= device_.motor_count())) {
    halt(StopReason::kInvalidInstruction, runtime_.program_counter - 1);
    return;
  }
  int32_t ticks = operand_or_accumulator(in.value);
  if (ticks < 0) ticks = 0;  // manual 2.6.21: the accumulator must not be negative
  wait_ = WaitState{true, in.type, in.motor_bank, false, 0};
  if (in.type == kWaitTicks || ticks > 0) {
    wait_.has_deadline = true;
    wait_.deadline_us = now_us + static_cast<uint64_t>(ticks) * kTmclTickUs;
  }
  service_wait(now_us);
}

bool TmclInterpreter::wait_satisfied() const {
  switch (wait_.condition) {
    case kWaitPosition: return device_.position_reached(wait_.motor);
    case kWaitReferenceSwitch: return device_.home_switch_active(wait_.motor);
    case kWaitLimitSwitch:
      return device_.stop_switch_active(wait_.motor, true) || device_.stop_switch_active(wait_.motor, false);
    case kWaitReferenceSearch: return !device_.reference_search_running(wait_.motor);
    default: return false;
  }
}

void TmclInterpreter::service_wait(uint64_t now_us) {
  if (wait_.condition == kWaitTicks) {
    if (now_us >= wait_.deadline_us) wait_.active = false;
    return;
  }
  if (wait_satisfied()) {
    wait_.active = false;
  } else if (wait_.has_deadline && now_us >= wait_.deadline_us) {
    wait_.active = false;
    runtime_.error_flags |= kErrorTimeout;
  }
}

Status TmclInterpreter::set_interrupt_parameter(uint8_t number, int32_t value) {
  if (number < kTimerPeriodParameters) {
    if (value < 0) return Status::kInvalidValue;
    timer_period_ms_[number] = static_cast<uint32_t>(value);
    return Status::kOk;
  }
  if (!is_edge_trigger(number)) return Status::kWrongType;
  if (value < 0 || value > 3) return Status::kInvalidValue;
  edge_trigger_[number] = static_cast<uint8_t>(value);
  return Status::kOk;
}

Status TmclInterpreter::get_interrupt_parameter(uint8_t number, int32_t& value) const {
  if (number < kTimerPeriodParameters) {
    value = static_cast<int32_t>(timer_period_ms_[number]);
    return Status::kOk;
  }
  if (!is_edge_trigger(number)) return Status::kWrongType;
  value = edge_trigger_[number];
  return Status::kOk;
}

bool TmclInterpreter::is_edge_trigger(uint8_t number) const {
  const uint8_t motors = device_.motor_count() < vector::kMaxMotors ? device_.motor_count() : vector::kMaxMotors;
  if (number >= vector::kLeftStopSwitch0 && number <= vector::right_stop_switch(static_cast<uint8_t>(motors - 1))) {
    return true;
  }
  return number >= vector::kInput0 && number < vector::kInput0 + vector::kInputCount;
}

// Raises pending flags for timers that expired and edges that match their trigger.
void TmclInterpreter::sample_interrupt_sources(uint64_t now_us) {
  for (uint8_t timer = 0; timer < timer_period_ms_.size(); ++timer) {
    const uint64_t period_us = static_cast<uint64_t>(timer_period_ms_[timer]) * 1000u;
    if (period_us == 0) {
      timer_last_us_[timer] = now_us;
      continue;
    }
    if (now_us - timer_last_us_[timer] >= period_us) {
      timer_last_us_[timer] += period_us * ((now_us - timer_last_us_[timer]) / period_us);
      if (enabled_[timer]) pending_[timer] = true;
    }
  }
  const bool primed = levels_primed_;
  levels_primed_ = true;
  const auto edge = [&](uint8_t vector, bool level, uint8_t trigger) {
    const bool previous = primed ? last_level_[vector] : level;
    last_level_[vector] = level;
    const bool rising = level && !previous;
    const bool falling = !level && previous;
    if (((trigger & 1) != 0 && rising) || ((trigger & 2) != 0 && falling)) {
      if (enabled_[vector]) pending_[vector] = true;
    }
  };
  const uint8_t motors = device_.motor_count() < vector::kMaxMotors ? device_.motor_count() : vector::kMaxMotors;
  for (uint8_t m = 0; m < motors; ++m) {
    const uint8_t left = vector::left_stop_switch(m);
    const uint8_t right = vector::right_stop_switch(m);
    edge(vector::position_reached(m), device_.position_reached(m), 1);
    edge(left, device_.stop_switch_active(m, true), edge_trigger_[left]);
    edge(right, device_.stop_switch_active(m, false), edge_trigger_[right]);
  }
  for (uint8_t i = 0; i < vector::kInputCount; ++i) {
    const uint8_t v = static_cast<uint8_t>(vector::kInput0 + i);
    if (edge_trigger_[v] == 0) continue;
    int32_t level = 0;
    const uint8_t port = static_cast<uint8_t>(device_.first_interrupt_input_port() + i);
    if (device_.get_input(port, 0, level) != Status::kOk) continue;
    edge(v, level != 0, edge_trigger_[v]);
  }
}

// No nesting: one interrupt routine at a time, lowest vector number first. The interrupted
// context (PC, A, X, comparison, a WAIT in progress) comes back with RETI.
bool TmclInterpreter::enter_pending_interrupt() {
  for (uint8_t v = 0; v < vector::kCount; ++v) {
    if (!pending_[v] || !enabled_[v] || !vector_set_[v]) continue;
    pending_[v] = false;
    saved_ = SavedContext{runtime_.program_counter, runtime_.accumulator, runtime_.x_register,
                          runtime_.compare_accumulator, runtime_.compare_operand, wait_};
    wait_.active = false;
    in_interrupt_ = true;
    runtime_.program_counter = vectors_[v];
    return true;
  }
  return false;
}

}  // namespace motwin::tmcl

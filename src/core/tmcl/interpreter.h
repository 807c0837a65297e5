// The TMCL interpreter: runs the stored program one instruction per control tick, interleaved
// with host commands and the control loops (docs/tmcl-protocol.md "Interpreter model", TMCM-1636
// manual 2.6.15-2.6.26 and 6). Program flow (JA, JC, CSUB, RSUB, WAIT, STOP, VECT, EI, DI,
// RETI) is executed here; every other instruction goes through TmclEngine::execute with
// Origin::kProgram, and a read loads the accumulator.
#pragma once

#include <array>
#include <cstdint>

#include "core/tmcl/instruction.h"
#include "core/tmcl/program_memory.h"
#include "core/tmcl/runtime.h"
#include "core/tmcl/status.h"

namespace motwin::tmcl {

class TmclDevice;
class TmclEngine;

// Why a program stopped; readable with StopReasonText and command 135 type 4.
enum class StopReason : uint8_t {
  kNone = 0,
  kStopInstruction,     // STOP
  kHostStop,            // command 128 (131 clears the reason)
  kJumpOutsideProgram,  // JA/JC/CSUB/VECT target or RETI/RSUB return beyond program memory
  kEndOfMemory,         // the program counter ran past the last address
  kDamagedInstruction,  // a record whose checksum does not match
  kInvalidInstruction,  // a control command, unknown command or malformed flow command
};

const char* stop_reason_text(StopReason reason);

// Interrupt vectors (TMCL V4-generation numbering, docs/tmcl-programs.md). Per motor m of a
// module with several: position reached 3 + m, left stop switch 27 + 2m, right 28 + 2m (up to
// six motors, as Trinamic's multi-axis modules number them).
namespace vector {
inline constexpr uint8_t kTimer0 = 0;
inline constexpr uint8_t kTimer1 = 1;
inline constexpr uint8_t kTimer2 = 2;
inline constexpr uint8_t kPositionReached0 = 3;
inline constexpr uint8_t kLeftStopSwitch0 = 27;
inline constexpr uint8_t kRightStopSwitch0 = 28;
inline constexpr uint8_t kMaxMotors = 6;
constexpr uint8_t position_reached(uint8_t motor) { return static_cast<uint8_t>(kPositionReached0 + motor); }
constexpr uint8_t left_stop_switch(uint8_t motor) { return static_cast<uint8_t>(kLeftStopSwitch0 + 2 * motor); }
constexpr uint8_t right_stop_switch(uint8_t motor) { return static_cast<uint8_t>(kRightStopSwitch0 + 2 * motor); }
inline constexpr uint8_t kInput0 = 39;
inline constexpr uint8_t kInputCount = 8;
inline constexpr uint8_t kCount = kInput0 + kInputCount;
inline constexpr uint8_t kGlobal = 255;
}  // namespace vector

class TmclInterpreter {
 public:
  static constexpr uint8_t kStackDepth = 8;
  static constexpr uint32_t kTmclTickUs = 10000;  // WAIT counts 10 ms ticks

  explicit TmclInterpreter(TmclEngine& engine);

  // Control commands (table 10).
  Status stop();                                  // 128
  Status run(bool from_address, uint32_t address);  // 129
  Status step();                                  // 130
  void reset();                                   // 131 and power-up
  // One control tick at simulated time now_us: executes at most one instruction.
  void tick(uint64_t now_us);

  bool waiting() const { return wait_.active; }
  StopReason stop_reason() const { return stop_reason_; }
  uint32_t stop_address() const { return stop_address_; }
  uint64_t instructions_executed() const { return instructions_executed_; }

  // Bank 3: timer periods (ms) 0..2, edge triggers for the stop switches (27/28, + 2 per motor)
  // and inputs 39..46 (0 off, 1 rising, 2 falling, 3 both).
  Status set_interrupt_parameter(uint8_t number, int32_t value);
  Status get_interrupt_parameter(uint8_t number, int32_t& value) const;

 private:
  struct WaitState {
    bool active = false;
    uint8_t condition = 0;
    uint8_t motor = 0;
    bool has_deadline = false;
    uint64_t deadline_us = 0;
  };
  struct SavedContext {
    uint32_t program_counter = 0;
    int32_t accumulator = 0;
    int32_t x_register = 0;
    int32_t compare_accumulator = 0;
    int32_t compare_operand = 0;
    WaitState wait;
  };

  void execute_next(uint64_t now_us);
  void execute(const Instruction& instruction, uint64_t now_us);
  void halt(StopReason reason, uint32_t address);
  bool jump(uint32_t address);
  bool condition_holds(uint8_t condition) const;
  bool wait_satisfied() const;
  void begin_wait(const Instruction& instruction, uint64_t now_us);
  void service_wait(uint64_t now_us);
  void sample_interrupt_sources(uint64_t now_us);
  // A bank-3 number that sets an edge trigger: a stop switch of a motor the module has, an input.
  bool is_edge_trigger(uint8_t number) const;
  bool enter_pending_interrupt();
  int32_t operand_or_accumulator(int32_t value) const;

  TmclEngine& engine_;
  TmclDevice& device_;
  TmclRuntime& runtime_;

  std::array<uint32_t, kStackDepth> stack_{};
  uint8_t stack_size_ = 0;
  WaitState wait_;
  StopReason stop_reason_ = StopReason::kNone;
  uint32_t stop_address_ = 0;
  bool step_pending_ = false;
  uint64_t instructions_executed_ = 0;

  // Interrupts.
  std::array<uint32_t, vector::kCount> vectors_{};
  std::array<bool, vector::kCount> vector_set_{};
  std::array<bool, vector::kCount> enabled_{};
  std::array<bool, vector::kCount> pending_{};
  std::array<uint8_t, vector::kCount> edge_trigger_{};
  std::array<bool, vector::kCount> last_level_{};
  std::array<uint32_t, 3> timer_period_ms_{};
  std::array<uint64_t, 3> timer_last_us_{};
  bool interrupts_enabled_ = false;
  bool in_interrupt_ = false;
  bool levels_primed_ = false;
  SavedContext saved_;
};

}  // namespace motwin::tmcl

// The TMCL command dispatcher: one instruction in, one result out, the same for a host and
// for a stored program. Transport framing (serial, CAN, ASCII) lives in the *_link files.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/tmcl/device.h"
#include "core/tmcl/instruction.h"
#include "core/tmcl/interpreter.h"
#include "core/tmcl/status.h"

namespace motwin::tmcl {

// Identifies the host connection a request came from, so that delayed replies (command 138)
// reach the host that asked.
using ChannelId = uint16_t;

enum class ReplyKind : uint8_t {
  kNormal,
  kVersionString,   // command 136 type 0: host address + 8 ASCII characters
  kNone,            // command 137: no reply
  kThenReset,       // command 255: reply first, then power-up
  kThenAsciiMode,   // command 139: reply first (binary), then the link reads ASCII lines
};

struct CommandResult {
  Status status = Status::kOk;
  int32_t value = 0;          // reply value; for reads: the value read
  ReplyKind kind = ReplyKind::kNormal;
  bool loads_accumulator = false;  // a read: a program copies value into the accumulator
  int16_t reply_command = -1;      // >= 0: command byte of the reply (134); else the request's
};

// A reply as the link layers encode it.
struct Reply {
  uint8_t status;
  uint8_t command;
  int32_t value;
};

class ReplySink {
 public:
  virtual void deliver(ChannelId channel, const Reply& reply) = 0;

 protected:
  ~ReplySink() = default;
};

class TmclEngine {
 public:
  explicit TmclEngine(TmclDevice& device) : device_(device), interpreter_(*this) {}

  TmclDevice& device() { return device_; }
  TmclInterpreter& interpreter() { return interpreter_; }

  // Power-up of the firmware: the profile restores its parameters, the program memory is
  // loaded, and the stored program starts if autostart (GP 77) is on.
  void power_up();
  // One control tick at simulated time now_us: the stored program advances by at most one
  // instruction.
  void tick(uint64_t now_us) { interpreter_.tick(now_us); }

  // Runs one instruction. `channel` only matters for command 138.
  CommandResult execute(const Instruction& instruction, Origin origin, ChannelId channel = 0);

  // Delivers the delayed replies that have become due (command 138). Call after each tick batch.
  void collect_events(ReplySink& sink);

  // A host connection went away: its pending events are dropped.
  void forget_channel(ChannelId channel);

  // Command 255 after its reply has gone out (and the host runtime's power-up).
  void complete_reset();

  size_t pending_event_count() const;
  // Counts power-ups (start, 255, 137): links reset their mode (binary or ASCII, GP 67) on each.
  uint32_t power_up_count() const { return power_up_count_; }

 private:
  CommandResult dispatch(const Instruction& instruction, Origin origin, ChannelId channel);
  struct PendingEvent {
    bool active = false;
    ChannelId channel = 0;
    uint32_t motor_mask = 0;
  };
  static constexpr size_t kMaxPendingEvents = 16;

  // The steps of execute(), one per command family.
  CommandResult store_downloaded(const Instruction& in);
  CommandResult control_command(const Instruction& in);
  static bool is_interrupt_configuration(const Instruction& in);
  CommandResult interrupt_configuration(const Instruction& in);
  CommandResult motion_command(const Instruction& in);
  CommandResult axis_parameter_command(const Instruction& in);
  CommandResult global_parameter_command(const Instruction& in);
  CommandResult device_command(const Instruction& in);
  CommandResult register_command(const Instruction& in);
  CommandResult module_command(const Instruction& in, ChannelId channel);
  CommandResult request_position_event(const Instruction& in, ChannelId channel);

  TmclDevice& device_;
  std::array<PendingEvent, kMaxPendingEvents> events_{};
  uint32_t power_up_count_ = 0;
  TmclInterpreter interpreter_;
};

}  // namespace motwin::tmcl

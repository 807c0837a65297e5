// NMT slave with boot-up and the heartbeat producer (CiA-301 7.2.8.3, TMCM-3216 manual 2.2,
// object 1017), in the shape of CANopenNode's CO_NMT_Heartbeat: commands are queued by
// on_command() and acted on in process(), which is told how much time has passed.
//
// State machine:
//   kInitializing --boot()--> kPreOperational (boot-up message 0x700+node, data 00)
//   kPreOperational/kOperational/kStopped --start(01)--> kOperational
//                                         --stop(02)---> kStopped
//                                         --preop(80)--> kPreOperational
//   any --reset node(81) / reset communication(82)--> the device resets (process() returns
//          what to reset), then calls boot() again.
// A heartbeat (0x700+node, one byte: the state) goes out every 1017 ms when 1017 != 0, at once
// when the state changes, and the first one right after 1017 is written (as CANopenNode does).
#pragma once

#include <cstdint>

#include "board/can_controller.h"
#include "types/can_frame.h"

namespace motwin::canopen {

enum class NmtState : uint8_t {
  kInitializing = 0x00,
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
};

enum class NmtCommand : uint8_t {
  kStart = 0x01,
  kStop = 0x02,
  kEnterPreOperational = 0x80,
  kResetNode = 0x81,
  kResetCommunication = 0x82,
};

// What process() asks the device to do.
enum class NmtReset : uint8_t { kNone, kNode, kCommunication };

inline constexpr uint32_t kNmtCobId = 0x000;
inline constexpr uint32_t kHeartbeatCobIdBase = 0x700;

class NmtSlave {
 public:
  explicit NmtSlave(board::CanController& can) : can_(can) {}

  // Node ID (1..127) for the boot-up and heartbeat COB-ID and for addressed commands.
  void set_node_id(uint8_t node_id) { node_id_ = node_id; }
  uint8_t node_id() const { return node_id_; }

  // Back to kInitializing (power-up and both resets); pending commands are dropped.
  void initialize();
  // End of initialisation: boot-up message, kPreOperational.
  void boot();

  // An NMT command frame (COB-ID 0). Frames with DLC != 2 or for another node are ignored
  // (CANopenNode does the same); the command takes effect in the next process().
  void on_command(const can::CanFrame& frame);

  // Producer heartbeat time (1017) in ms; 0 switches the heartbeat off. The next heartbeat goes
  // out in the next process() call.
  void set_heartbeat_period_ms(uint16_t period_ms);
  uint16_t heartbeat_period_ms() const { return heartbeat_period_ms_; }

  // Acts on a pending command and sends the heartbeat when due. Returns a reset the device must
  // carry out (then call initialize() and boot()).
  NmtReset process(uint32_t elapsed_us);

  NmtState state() const { return state_; }
  // Directly, for the device's own use (error behaviour 1029 later).
  void enter(NmtState state);

 private:
  void send_state(uint8_t value);

  board::CanController& can_;
  uint8_t node_id_ = 1;
  NmtState state_ = NmtState::kInitializing;
  bool command_pending_ = false;
  uint8_t pending_command_ = 0;
  uint16_t heartbeat_period_ms_ = 0;
  uint64_t heartbeat_remaining_us_ = 0;
  bool heartbeat_now_ = false;
};

}  // namespace motwin::canopen

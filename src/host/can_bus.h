// The in-process virtual CAN bus: simulated nodes (virtual modules) and client endpoints
// (socketcand connections, later SLCAN and SocketCAN) attach to it, and every frame one of them
// sends reaches every other attached endpoint, never the sender itself (a CAN controller does not
// receive its own frames, and python-canopen's PDO logic is confused by echoes: docs/canopen.md
// "Reaching a virtual bus without kernel CAN"). Frames arrive in the order they were sent (no
// arbitration).
//
// Bus load: with a bit rate set, each frame occupies the bus for its exact bit count (stuff bits
// included, host/can_bit_timing.h) starting when the bus is free. Its timestamp is the simulated
// time its last bit leaves the bus, so back-to-back frames are spaced as on a real bus and an
// offered load above 100 % shows as a growing queueing delay (stats()). Delivery itself stays
// immediate in wall time: the stamps and the statistics carry the bus time (docs/canopen.md).
//
// Bit-rate mismatch: a node's CAN controller runs at its own bit rate (controller_bit_rate()).
// While that differs from the bus's, the node neither receives the bus's frames nor gets its own
// onto the bus (real hardware would see only error frames), and its error counters climb by the
// ISO 11898-1 fault-confinement steps until it is error-passive (receiving) or bus-off
// (transmitting); CanNodeBusStats counts this per node. Single-threaded, like the rest of the
// host runtime.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "types/can_frame.h"

namespace motwin::host {

class CanBusEndpoint {
 public:
  // A frame sent by another endpoint; `timestamp_us` is the bus clock when it was sent.
  virtual void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) = 0;
  // Bit/s the endpoint's CAN controller is set up for now; 0: it follows the bus (clients,
  // adapters, captures). Asked before every frame the endpoint sends or would receive, so a node
  // reports a rate that changed by a reset at once. Not const: a node may bring its view of its
  // own controller up to date here (TmclCanNode follows a power-up).
  virtual uint32_t controller_bit_rate() { return 0; }

 protected:
  ~CanBusEndpoint() = default;
};

struct CanBusStats {
  uint64_t frames = 0;
  uint64_t bits = 0;                  // stuff bits included
  uint64_t busy_ns = 0;               // time the bus carried bits
  uint64_t total_queue_delay_ns = 0;  // sum over frames of (start of transmission - send time)
  uint64_t max_queue_delay_ns = 0;
};

// Fault confinement of a node's controller (ISO 11898-1): error-active below 128 in both error
// counters, error-passive from 128, bus-off when the transmit error counter passes 255.
enum class CanErrorState : uint8_t { kErrorActive, kErrorPassive, kBusOff };

// One node as the bus sees it. The error counters are those of the node's controller; they start
// at 0 whenever the controller is set up again (its bit rate changes: a reset or power-up of the
// module). The frame counts add up over the whole run.
struct CanNodeBusStats {
  static constexpr uint16_t kWarningLimit = 96;    // the error LED's "warning limit" (manual 2.4.2)
  static constexpr uint16_t kPassiveLimit = 128;
  static constexpr uint16_t kBusOffLimit = 256;
  // Bus-off lasts 128 occurrences of 11 recessive bits at the node's rate, then the controller
  // is error-active again with both counters 0 (automatic recovery, as EMCY 8140 implies).
  static constexpr uint32_t kBusOffRecoveryBits = 128 * 11;

  uint32_t bit_rate = 0;         // the controller's rate (0: follows the bus)
  bool off_speed = false;        // bit_rate differs from the bus's
  uint64_t frames_missed = 0;    // bus frames the node could not receive (off speed or bus-off)
  uint64_t frames_not_sent = 0;  // frames of the node that never reached the bus
  uint16_t receive_errors = 0;   // REC: +1 per frame missed off speed (capped at kBusOffLimit - 1)
  uint16_t transmit_errors = 0;  // TEC: +8 per frame it tried to send off speed
  CanErrorState error_state = CanErrorState::kErrorActive;
  uint64_t bus_off_count = 0;     // times it went bus-off
  uint64_t bus_off_since_us = 0;  // bus clock when it last went bus-off
  bool warning() const { return receive_errors >= kWarningLimit || transmit_errors >= kWarningLimit; }
  bool any_trouble() const { return off_speed || frames_missed != 0 || frames_not_sent != 0 || bus_off_count != 0; }
};

std::string_view to_string(CanErrorState state);  // "error-active", "error-passive", "bus-off"
// " node NAME bitrate 500000 off-speed error-passive rec 128 tec 0 missed 12 not-sent 3 bus-off 0":
// the part of a `can-stats` line (motwin serve --can-stats) for one node.
std::string format_node_bus_stats(std::string_view name, const CanNodeBusStats& node);

class CanBus {
 public:
  using EndpointId = uint32_t;
  using Clock = std::function<uint64_t()>;

  // `clock` stamps each frame (the simulated time of the modules, in µs); none: 0.
  explicit CanBus(Clock clock = {}) : clock_(std::move(clock)) {}
  CanBus(const CanBus&) = delete;
  CanBus& operator=(const CanBus&) = delete;

  void set_clock(Clock clock) { clock_ = std::move(clock); }
  uint64_t now_us() const { return clock_ ? clock_() : 0; }

  // Never returns 0. An endpoint attached while a frame is being delivered sees the next one.
  EndpointId attach(CanBusEndpoint& endpoint);
  // Safe from inside on_frame (of any endpoint); the endpoint gets no further frame.
  void detach(EndpointId id);

  // Delivers `frame` to every endpoint but `from`. A frame sent from inside an on_frame callback
  // (a node answering an SDO request) is queued and delivered once the current one has reached
  // everybody, so every endpoint sees the frames in one order.
  void send(EndpointId from, const can::CanFrame& frame);

  size_t endpoint_count() const;
  uint64_t frame_count() const { return frame_count_; }

  // Bit/s of the bus; 0 (the default): frames take no time and are stamped with the send time,
  // and no node is ever off speed.
  void set_bit_rate(uint32_t bit_rate) { bit_rate_ = bit_rate; }
  uint32_t bit_rate() const { return bit_rate_; }
  const CanBusStats& stats() const { return stats_; }

  // false: the endpoint's controller is off speed or bus-off, so it neither receives nor sends.
  // An id that is not attached is on the bus (nothing stops it).
  bool takes_part(EndpointId id);
  // The node's view, brought up to date with its controller's bit rate now; nullptr when it is not
  // attached.
  const CanNodeBusStats* node_stats(EndpointId id);
  const CanNodeBusStats* node_stats(const CanBusEndpoint& endpoint);

 private:
  struct Entry {
    EndpointId id;
    CanBusEndpoint* endpoint;  // nullptr once detached
    CanNodeBusStats node;
  };
  struct Pending {
    EndpointId from;
    can::CanFrame frame;
    uint64_t timestamp_us;
  };

  Clock clock_;
  std::vector<Entry> entries_;
  std::deque<Pending> pending_;
  EndpointId next_id_ = 1;
  bool delivering_ = false;
  uint64_t frame_count_ = 0;
  uint32_t bit_rate_ = 0;
  uint64_t busy_until_ns_ = 0;
  CanBusStats stats_;

  // The timestamp of a frame sent now: when its transmission ends.
  uint64_t account(const can::CanFrame& frame);
  Entry* find(EndpointId id);
  // Asks the controller its rate; a new rate resets the error counters (a controller set up
  // again); a bus-off that has lasted its recovery time ends. true: the node takes part.
  bool refresh(Entry& entry);
  void count_receive_error(Entry& entry);
  void count_transmit_error(Entry& entry);
  static void update_error_state(CanNodeBusStats& node);
};

// A simulated node: a module with a CAN controller. connect() attaches it to a bus; from then on
// its transmitted frames go there and the bus's frames reach its receive path.
class CanBusNode : public CanBusEndpoint {
 public:
  virtual void connect(CanBus& bus) = 0;
  virtual void disconnect() = 0;

 protected:
  ~CanBusNode() = default;
};

}  // namespace motwin::host

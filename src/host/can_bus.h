// The in-process virtual CAN bus: simulated nodes (virtual modules) and client endpoints
// (socketcand connections, later SLCAN and SocketCAN) attach to it, and every frame one of them
// sends reaches every other attached endpoint, never the sender itself (a CAN controller does
// not receive its own frames, and python-canopen's PDO logic is confused by echoes:
// notes/canopen.md). Frames arrive in the order they were sent (no arbitration).
//
// Bus load: with a bit rate set, each frame occupies the bus for its exact bit count (stuff bits
// included, host/can_bit_timing.h) starting when the bus is free. Its timestamp is the simulated
// time its last bit leaves the bus, so back-to-back frames are spaced as on a real bus and an
// offered load above 100 % shows as a growing queueing delay (stats()). Delivery itself stays
// immediate in wall time: the stamps and the statistics carry the bus time (docs/canopen.md).
// Single-threaded, like the rest of the host runtime.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "core/can/can_frame.h"

namespace motwin::host {

class CanBusEndpoint {
 public:
  // A frame sent by another endpoint; `timestamp_us` is the bus clock when it was sent.
  virtual void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) = 0;

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

  // Bit/s of the bus; 0 (the default): frames take no time and are stamped with the send time.
  void set_bit_rate(uint32_t bit_rate) { bit_rate_ = bit_rate; }
  uint32_t bit_rate() const { return bit_rate_; }
  const CanBusStats& stats() const { return stats_; }

 private:
  struct Entry {
    EndpointId id;
    CanBusEndpoint* endpoint;  // nullptr once detached
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

// TMCL over CAN for any TMCL module (core/tmcl/can_link.h): the module's CAN controller as a node
// of a virtual bus. A request on the module's receive ID (GP 71) is served at once, inside the
// bus delivery, as the firmware's receive interrupt plus main loop would within microseconds; the
// reply goes out on the send ID (GP 70). Command 138's delayed replies come back through
// deliver(): either a TmclHostService routes them here (open_event_channel, when the module also
// serves TCP or a pty) or, with no service, deliver_events() collects them after each tick batch.
//
// GP 69 (bit rate) takes effect at power-up (start, command 255), as a CAN controller is set up
// once: while it differs from the bus's bit rate the node neither receives nor sends, like a real
// node on a bus of another speed. GP 70/71 take effect with the next frame.
//
// A module adds TMCL over CAN with one member and two overrides (see tmcm1636_virtual_module.h):
//   TmclCanNode can_{engine};
//   CanBusNode* can_node() override { return &can_; }
//   TmclCanNode* tmcl_can_node() override { return &can_; }
#pragma once

#include <cstdint>

#include "core/tmcl/can_link.h"
#include "core/tmcl/engine.h"
#include "host/can_bus.h"

namespace motwin::host {

class TmclCanNode final : public CanBusNode, public tmcl::ReplySink {
 public:
  // The channel the engine sees for CAN requests until use_event_channel() gives another.
  static constexpr tmcl::ChannelId kStandaloneChannel = 1;

  explicit TmclCanNode(tmcl::TmclEngine& engine) : engine_(engine) {}
  TmclCanNode(const TmclCanNode&) = delete;
  TmclCanNode& operator=(const TmclCanNode&) = delete;
  ~TmclCanNode() { disconnect(); }

  // CanBusNode.
  void connect(CanBus& bus) override;
  void disconnect() override;
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override;
  // The bus cuts the node off while this differs from its rate (host/can_bus.h).
  uint32_t controller_bit_rate() override {
    follow_power_up();
    return active_bit_rate_;
  }

  // tmcl::ReplySink: a command 138 reply for a CAN host.
  void deliver(tmcl::ChannelId channel, const tmcl::Reply& reply) override;
  // Without a TmclHostService: collect the due command 138 replies (after each tick batch).
  void deliver_events() { engine_.collect_events(*this); }

  void use_event_channel(tmcl::ChannelId channel) { channel_ = channel; }
  tmcl::ChannelId channel() const { return channel_; }
  bool connected() const { return bus_ != nullptr; }
  uint64_t served_requests() const { return served_requests_; }
  // Bit/s the controller was set up with at the last power-up (GP 69).
  uint32_t active_bit_rate() const { return active_bit_rate_; }
  // false: its bit rate does not match the bus's (or its controller is bus-off), the node is cut off.
  bool on_speed() const;
  // Current IDs and bit rate (GP 70, 71, 69).
  tmcl::CanSettings settings() const;

 private:
  void transmit(const can::CanFrame& frame);
  void follow_power_up();

  tmcl::TmclEngine& engine_;
  CanBus* bus_ = nullptr;
  CanBus::EndpointId bus_id_ = 0;
  tmcl::ChannelId channel_ = kStandaloneChannel;
  // A 138 reply has the length of the request that asked for it (PyTrinamic reads 8 bytes).
  uint8_t event_reply_length_ = tmcl::kCanRequestLength;
  bool event_reply_extended_ = false;
  uint64_t served_requests_ = 0;
  uint32_t power_ups_seen_ = UINT32_MAX;
  uint32_t active_bit_rate_ = 0;
};

}  // namespace motwin::host

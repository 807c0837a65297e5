// The web console's TMCL over CAN (docs/web-console.md "Protocol"): a TMCL module that is only a
// node of serve's virtual bus (`--node tmcm-1636` beside CANopen nodes) is reached as a CAN host
// reaches it: request frames on the module's receive ID (GP 71), replies on its send ID (GP 70),
// framed by core/tmcl/can_link.h, from a client endpoint of the console's own. The IDs are read
// from the module's settings at every request, as SGP 70/71 take effect with the next frame.
// TMCL over CAN has no request tag, so one request is on the bus at a time; a reply that does not
// come within kReplyTimeoutUs (wall time) ends the request with an error.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>

#include "core/tmcl/can_link.h"
#include "host/can_bus.h"
#include "host/event_loop.h"
#include "tools/web/web_tmcl.h"

namespace motwin::tools::web {

class TmclCanPort final : public host::CanBusEndpoint, public TmclRequests {
 public:
  static constexpr uint64_t kReplyTimeoutUs = 1'000'000;
  using Settings = std::function<tmcl::CanSettings()>;
  using EventListener = std::function<void(const TmclAnswer&)>;

  // `settings`: the module's current IDs; `on_event`: command 138's delayed replies.
  TmclCanPort(host::CanBus& bus, host::EventLoop& loop, Settings settings, EventListener on_event);
  ~TmclCanPort() override;
  TmclCanPort(const TmclCanPort&) = delete;
  TmclCanPort& operator=(const TmclCanPort&) = delete;

  // TmclRequests.
  void request(const tmcl::Instruction& instruction, Done done) override;
  bool hold() override;
  void held_request(const tmcl::Instruction& instruction, Done done) override;
  void release() override;

  // host::CanBusEndpoint.
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override;

 private:
  struct Pending {
    tmcl::Instruction instruction;
    Done done;
  };

  void send_next();
  void finish(TmclAnswer answer);

  host::CanBus& bus_;
  host::EventLoop& loop_;
  Settings settings_;
  EventListener on_event_;
  host::CanBus::EndpointId id_ = 0;
  std::deque<Pending> waiting_;
  bool held_ = false;
  std::deque<Pending> held_back_;
  std::optional<Pending> in_flight_;
  tmcl::CanSettings in_flight_ids_;
  std::optional<host::EventLoop::TimerId> timer_;
  bool sending_ = false;  // inside send_next(): a reply delivered meanwhile must not recurse
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace motwin::tools::web

// A web console (tools/web/web_console.h) on one virtual module run by its host runtime, and a
// page's session on it, without sockets: what the web unit tests (web_*_test.cpp) drive. Requests
// go in as text, replies are collected from a fake connection.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "host/can_bus.h"
#include "host/event_loop.h"
#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "tools/web/web_console.h"

namespace motwin::testing {

// A page's end of a session: keeps what the console sends it.
class FakeWebConnection final : public host::web::WebConnection {
 public:
  void send_text(std::string message) override {
    replies.push_back(nlohmann::json::parse(message));
    messages.push_back(replies.back());
  }
  void send_latest(std::string message) override {
    latest = nlohmann::json::parse(message);
    messages.push_back(*latest);
    ++latest_count;
  }
  size_t queued_bytes() const override { return queued; }

  std::vector<nlohmann::json> replies;   // by send_text: replies and "frames" pushes
  std::optional<nlohmann::json> latest;  // the newest push handed to send_latest
  size_t latest_count = 0;               // pushes handed to send_latest
  std::vector<nlohmann::json> messages;  // everything, in the order it came
  size_t queued = 0;                     // what the fake pretends a page left unread
};

// A module by its registry name that logs nowhere; `motor` as `--motor` names it (empty: the
// module's default), `firmware` as `--firmware` (empty: its default).
inline host::MakeModuleResult make_quiet_module(const char* name, const std::string& motor = "",
                                                const std::string& firmware = "") {
  host::ModuleOptions options;
  options.log = [](const std::string&) {};
  options.motor = motor;
  options.firmware = firmware;
  return host::make_module(name, options);
}

// How WebConsoleRig::ask runs the module while it waits for a reply.
enum class ReplyWait {
  kLoopTurns,  // loop turns without sleeping: replies that come as simulated time runs
  kWallClock,  // turns of up to 1 ms for 10 s: replies that may end on a wall-clock timeout
               // (an SDO transfer or a TMCL-over-CAN request nobody answers)
};

class WebConsoleRig;

// What a test changes in a WebConsoleRig, by the with_ calls:
// `WebConsoleRigSetup().with_can_bus().with_reply_wait(ReplyWait::kWallClock)`.
struct WebConsoleRigSetup {
  using TargetAdapter = std::function<void(WebConsoleRig& rig, tools::web::ConsoleTarget& target)>;

  std::string motor;     // make_quiet_module's
  std::string firmware;  // make_quiet_module's: "tmcl" for the TMCM-3216's TMCL firmware
  bool can_bus = false;  // the module's CAN node on a virtual bus (a CANopen node always is)
  ReplyWait reply_wait = ReplyWait::kLoopTurns;
  // Changes the module's console target before the console is made (a world, TMCL over CAN).
  TargetAdapter adapt_target;

  WebConsoleRigSetup& with_motor(std::string name) {
    motor = std::move(name);
    return *this;
  }
  WebConsoleRigSetup& with_firmware(std::string name) {
    firmware = std::move(name);
    return *this;
  }
  WebConsoleRigSetup& with_can_bus() {
    can_bus = true;
    return *this;
  }
  WebConsoleRigSetup& with_reply_wait(ReplyWait how) {
    reply_wait = how;
    return *this;
  }
  WebConsoleRigSetup& with_target_adapter(TargetAdapter adapter) {
    adapt_target = std::move(adapter);
    return *this;
  }
};

// The console lists the one module: a TMCL module through its TmclHostService, a CANopen node
// (node ID 1) through SDO and NMT on the bus; one session is open and the runtime started.
class WebConsoleRig {
 public:
  using Json = nlohmann::json;

  explicit WebConsoleRig(const char* module_name, WebConsoleRigSetup setup = {}) : wait_(setup.reply_wait) {
    host::MakeModuleResult made = make_quiet_module(module_name, setup.motor, setup.firmware);
    EXPECT_TRUE(made) << made.error();
    module_ = std::move(*made);
    runtime_ = std::make_unique<host::HostRuntime>(*module_, host::Pacing::fast());
    if (setup.can_bus || !module_->has_tmcl()) {
      bus_ = std::make_unique<host::CanBus>([this] { return module_->sim_time_us(); });
      module_->can_node()->connect(*bus_);
    }
    const host::ModuleDescriptor& descriptor = *host::find_module(module_name);
    std::vector<tools::web::ConsoleTarget> targets;
    if (module_->has_tmcl()) {
      targets.push_back(tools::web::tmcl_target(descriptor, std::string(module_->name()),
                                                std::string(module_->firmware_version()), setup.firmware,
                                                module_->engine().device().motor_count(), &runtime_->service()));
    } else {
      targets.push_back(tools::web::canopen_target(descriptor, std::string(module_->name()),
                                                   std::string(module_->firmware_version()), 1));
    }
    if (setup.adapt_target) setup.adapt_target(*this, targets.back());
    console_ = std::make_unique<tools::web::WebConsole>(
        runtime_->loop(), [this] { return module_->sim_time_us(); }, std::move(targets), bus_.get());
    session_ = console_->open_session(connection_);
    runtime_->start();
  }
  ~WebConsoleRig() {
    session_.reset();
    console_.reset();
    if (bus_) module_->can_node()->disconnect();
  }
  WebConsoleRig(const WebConsoleRig&) = delete;
  WebConsoleRig& operator=(const WebConsoleRig&) = delete;

  // Hands `text` to the session as a page sends it; waits for nothing.
  void send_only(const std::string& text) { session_->on_message(text); }
  // Sends `request` with the rig's next id and waits for nothing; returns the id.
  int send(Json request) {
    request["id"] = next_id_;
    send_only(request.dump());
    return next_id_++;
  }
  // The reply with `id` among the replies from `from` on; null while there is none.
  Json find_reply(const Json& id, size_t from = 0) const {
    for (size_t i = from; i < connection_.replies.size(); ++i) {
      if (connection_.replies[i].value("id", Json()) == id) return connection_.replies[i];
    }
    return Json{};
  }
  // Runs the module until the reply with `id` (from reply `from` on) has come.
  Json wait_for_reply(const Json& id, size_t from = 0) {
    const uint64_t give_up_us = host::monotonic_now_us() + 10'000'000;
    for (int turn = 0;; ++turn) {
      Json reply = find_reply(id, from);
      if (!reply.is_null()) return reply;
      if (wait_ == ReplyWait::kLoopTurns ? turn >= 2'000'000 : host::monotonic_now_us() >= give_up_us) break;
      runtime_->step(wait_ == ReplyWait::kLoopTurns ? 0 : 1000);
    }
    ADD_FAILURE() << "no reply with id " << id.dump();
    return Json{};
  }
  // Sends `text` and runs the module until the reply with `id` arrives.
  Json ask_text(const std::string& text, const Json& id) {
    const size_t before = connection_.replies.size();
    send_only(text);
    return wait_for_reply(id, before);
  }
  // Sends `request` with the next id and runs the module until its reply arrives.
  Json ask(Json request) {
    const size_t before = connection_.replies.size();
    return wait_for_reply(send(std::move(request)), before);
  }
  // Runs simulated time forward.
  void run_for_us(uint64_t sim_us) { runtime_->advance_ticks(sim_us / module_->tick_period_us()); }

  host::VirtualModule& module() { return *module_; }
  host::HostRuntime& runtime() { return *runtime_; }
  host::CanBus& bus() { return *bus_; }
  FakeWebConnection& connection() { return connection_; }
  // Another page's session on the same console.
  std::unique_ptr<host::web::WebSessionHandler> open_session(FakeWebConnection& connection) {
    return console_->open_session(connection);
  }
  // The page of the rig's session goes away.
  void close_session() { session_.reset(); }

 private:
  ReplyWait wait_;
  std::unique_ptr<host::VirtualModule> module_;
  std::unique_ptr<host::HostRuntime> runtime_;
  std::unique_ptr<host::CanBus> bus_;
  std::unique_ptr<tools::web::WebConsole> console_;
  FakeWebConnection connection_;
  std::unique_ptr<host::web::WebSessionHandler> session_;
  int next_id_ = 1;
};

}  // namespace motwin::testing

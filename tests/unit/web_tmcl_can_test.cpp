// The web console reaching a TMCL module by TMCL over CAN (tools/web/tmcl_can_port.h) without
// sockets: a TMCM-1636 as a node of a virtual bus, the console a client of that bus. Parameters
// through the module's own checks, the version string, the program ops, new IDs (SGP 70/71)
// followed at once, replies of another CAN host ignored, the bus monitor showing the console's
// frames once, and a module that does not answer.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/tmcl/can_link.h"
#include "host/can_bus.h"
#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "host/tmcl_can_node.h"
#include "support/web_console_rig.h"
#include "tools/web/web_console.h"

namespace motwin::tools::web {
namespace {

using Json = nlohmann::json;

// Another CAN host on the same bus: records what it hears, sends what it is told.
class OtherHost final : public host::CanBusEndpoint {
 public:
  explicit OtherHost(host::CanBus& bus) : bus_(bus) { id_ = bus_.attach(*this); }
  ~OtherHost() { bus_.detach(id_); }
  void on_frame(const can::CanFrame& frame, uint64_t) override { heard.push_back(frame); }
  void send(const can::CanFrame& frame) { bus_.send(id_, frame); }
  std::vector<can::CanFrame> heard;

 private:
  host::CanBus& bus_;
  host::CanBus::EndpointId id_ = 0;
};

// A TMCM-1636 as node tmcm-1636-1 of a virtual bus, the console reaching it by TMCL over CAN.
// Requests are bounded in wall time: an unanswered one ends after TmclCanPort::kReplyTimeoutUs.
class CanRig : public motwin::testing::WebConsoleRig {
 public:
  CanRig()
      : WebConsoleRig("tmcm-1636", motwin::testing::WebConsoleRigSetup()
                                       .with_can_bus()
                                       .with_reply_wait(motwin::testing::ReplyWait::kWallClock)
                                       .with_target_adapter([](WebConsoleRig& rig, ConsoleTarget& target) {
                                         target = tmcl_target(*host::find_module("tmcm-1636"), "tmcm-1636-1",
                                                              std::string(rig.module().firmware_version()), "",
                                                              rig.module().engine().device().motor_count(), nullptr,
                                                              rig.module().tmcl_can_node());
                                       })) {}

  void run_wall_us(uint64_t wall_us) {
    const uint64_t until_us = host::monotonic_now_us() + wall_us;
    while (host::monotonic_now_us() < until_us) runtime().step(1000);
  }
};

TEST(WebTmclOverCan, a_bus_node_is_listed_as_tmcl_with_its_ids_and_answers_with_its_own_checks) {
  CanRig rig;
  OtherHost sniffer(rig.bus());
  const Json listed = rig.ask({{"op", "list"}})["modules"][0];
  EXPECT_EQ(listed["protocol"], "tmcl");
  EXPECT_EQ(listed["tmcl_can"], Json::parse(R"({"receive_id":1,"send_id":2})"));

  EXPECT_EQ(rig.ask({{"op", "set"}, {"number", 11}, {"value", 1500}})["status"], 100);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 11}})["value"], 1500);
  const Json refused = rig.ask({{"op", "set"}, {"number", 11}, {"value", 60001}});
  EXPECT_EQ(refused["ok"], false);
  EXPECT_EQ(refused["status"], 4);
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "136 0"}})["version"].get<std::string>().substr(0, 6), "1636V1");
  // The requests went over the bus on the module's receive ID, 7 bytes each.
  ASSERT_FALSE(sniffer.heard.empty());
  EXPECT_EQ(sniffer.heard[0].id, 1u);
  EXPECT_EQ(sniffer.heard[0].dlc, 7);
  EXPECT_EQ(sniffer.heard[0].data[0], 5);  // SAP
}

TEST(WebTmclOverCan, program_ops_work_over_can) {
  CanRig rig;
  const Json downloaded = rig.ask({{"op", "program_download"}, {"source", "Loop: CALC ADD, 1\n  JA Loop\n"}});
  ASSERT_EQ(downloaded["ok"], true) << downloaded.dump();
  EXPECT_EQ(downloaded["verified"], true);
  const Json read = rig.ask({{"op", "program_read"}});
  ASSERT_EQ(read["instructions"].size(), 3u);
  EXPECT_EQ(read["instructions"][1]["text"], "JA L0");
  EXPECT_EQ(rig.ask({{"op", "app_status"}})["download_pointer"], 4);
}

TEST(WebTmclOverCan, new_ids_are_followed_from_the_reply_to_the_sgp_on) {
  CanRig rig;
  // The reply to SGP 71 already comes with the new IDs (core/tmcl/can_link.cpp).
  EXPECT_EQ(rig.ask({{"op", "set"}, {"kind", "global"}, {"number", 71}, {"value", 5}})["status"], 100);
  EXPECT_EQ(rig.ask({{"op", "set"}, {"kind", "global"}, {"number", 70}, {"value", 6}})["status"], 100);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"kind", "global"}, {"number", 70}})["value"], 6);
  EXPECT_EQ(rig.ask({{"op", "list"}})["modules"][0]["tmcl_can"], Json::parse(R"({"receive_id":5,"send_id":6})"));
}

TEST(WebTmclOverCan, another_hosts_replies_are_not_taken_for_the_consoles) {
  CanRig rig;
  OtherHost other(rig.bus());
  // The other host asks GAP 11 while the console waits for nothing: its reply is no event.
  other.send(tmcl::encode_can_request(1, tmcl::Instruction{tmcl::command::kGap, 11, 0, 0}));
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 11}})["command"], 6);
  for (const Json& message : rig.connection().messages) EXPECT_FALSE(message.contains("push")) << message.dump();
}

TEST(WebTmclOverCan, the_bus_monitor_shows_the_consoles_request_and_the_reply_once_each) {
  CanRig rig;
  ASSERT_EQ(rig.ask({{"op", "monitor"}})["ok"], true);
  rig.ask({{"op", "get"}, {"number", 11}});
  std::vector<Json> frames;
  const uint64_t give_up_us = host::monotonic_now_us() + 5'000'000;
  while (frames.size() < 2 && host::monotonic_now_us() < give_up_us) {
    rig.run_wall_us(10'000);  // "frames" pushes come every 100 ms
    for (const Json& message : rig.connection().messages) {
      if (message.value("push", "") == "frames") {
        for (const Json& frame : message["frames"]) frames.push_back(frame);
      }
    }
    rig.connection().messages.clear();
  }
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0]["id"], 1);
  EXPECT_EQ(frames[0]["data"], "060B0000000000");
  EXPECT_EQ(frames[1]["id"], 2);
}

TEST(WebTmclOverCan, a_module_that_does_not_answer_ends_the_request_with_an_error) {
  CanRig rig;
  rig.module().can_node()->disconnect();
  const Json reply = rig.ask({{"op", "get"}, {"number", 11}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_EQ(reply["error"], "no reply over CAN on ID 2 within 1 s");
  rig.module().can_node()->connect(rig.bus());
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 11}})["status"], 100);
}

}  // namespace
}  // namespace motwin::tools::web

// The web console's protocol (tools/web/web_console.h) without sockets: requests handed in as
// text, replies collected from a fake connection, the module run by its host runtime. Each op on
// a TMCL module (through its TmclHostService) and a CANopen node (SDO and NMT on the virtual
// bus), bad JSON, unknown ops, the module's own status or abort code for a value out of range or
// a refused access, and subscriptions pushing batches with the simulated time.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "support/web_console_rig.h"
#include "tools/web/web_console.h"

namespace motwin::tools::web {
namespace {

using Json = nlohmann::json;
using motwin::testing::FakeWebConnection;

// A console on one module, and a session talking to it. Requests are bounded in wall time: an
// SDO transfer to a silent node ends after WebConsole::kSdoTimeoutUs.
class ConsoleRig : public motwin::testing::WebConsoleRig {
 public:
  explicit ConsoleRig(const char* module_name, const std::string& firmware = "")
      : WebConsoleRig(module_name, motwin::testing::WebConsoleRigSetup()
                                       .with_firmware(firmware)
                                       .with_reply_wait(motwin::testing::ReplyWait::kWallClock)) {}

  void run_until_replies(size_t count) {
    for (int step = 0; step < 1000000 && connection().replies.size() < count; ++step) runtime().step(0);
  }
  // Runs until a push arrives in the latest slot; returns it.
  Json next_push() {
    connection().latest.reset();
    for (int step = 0; step < 2000000 && !connection().latest; ++step) runtime().step(0);
    EXPECT_TRUE(connection().latest.has_value());
    return connection().latest.value_or(Json{});
  }
  // Runs until a "frames" push arrives after reply `from`; returns it (null: none came within
  // `wait_us` of wall time; pushes are due every WebConsole::kMonitorPeriodUs).
  Json next_frames_push(size_t from, uint64_t wait_us = 5'000'000) {
    const uint64_t give_up_us = host::monotonic_now_us() + wait_us;
    while (host::monotonic_now_us() < give_up_us) {
      for (size_t i = from; i < connection().replies.size(); ++i) {
        if (connection().replies[i].value("push", "") == "frames") return connection().replies[i];
      }
      runtime().step(1000);
    }
    return Json{};
  }
  void step() { runtime().step(0); }
  uint64_t served_tmcl_requests() { return runtime().service().served_request_count(); }
};

// --- Messages the console cannot read ---------------------------------------------------------

TEST(WebConsole, bad_json_gets_an_error_reply_with_no_id) {
  ConsoleRig rig("tmcm-1636");
  const Json reply = rig.ask_text("{\"id\": 1, \"op\": ", nullptr);
  EXPECT_EQ(reply["ok"], false);
  EXPECT_EQ(reply["error"], "not a JSON object");
  EXPECT_EQ(rig.ask_text("[1,2]", nullptr)["error"], "not a JSON object");
}

TEST(WebConsole, unknown_op_and_missing_fields_are_errors_with_the_request_id) {
  ConsoleRig rig("tmcm-1636");
  Json reply = rig.ask({{"op", "fly"}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_NE(reply["error"].get<std::string>().find("unknown op \"fly\""), std::string::npos);
  // A TMCL module is no CANopen node: no NMT state to tell.
  EXPECT_EQ(rig.ask({{"op", "nmt_state"}})["nodes"], Json::array());
  reply = rig.ask({{"op", "get"}});
  EXPECT_NE(reply["error"].get<std::string>().find("\"number\""), std::string::npos);
  reply = rig.ask({{"op", "get"}, {"module", 3}, {"number", 1}});
  EXPECT_EQ(reply["error"], "no module 3 (the list has 1)");
  reply = rig.ask({{"op", "set"}, {"number", 4}, {"value", 5000000000LL}});
  EXPECT_EQ(reply["error"], "\"value\": does not fit the 32 bits of a TMCL value");
  reply = rig.ask({{"op", "tmcl"}, {"text", "FLY 1 2 3"}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_NE(reply["error"].get<std::string>().find("FLY"), std::string::npos);
}

// --- A TMCL module ----------------------------------------------------------------------------

TEST(WebConsole, list_gives_the_descriptor_rows_of_a_tmcl_module) {
  ConsoleRig rig("tmcm-1636");
  const Json reply = rig.ask({{"op", "list"}});
  ASSERT_EQ(reply["ok"], true);
  ASSERT_EQ(reply["modules"].size(), 1u);
  const Json& module = reply["modules"][0];
  EXPECT_EQ(module["name"], "tmcm-1636");
  EXPECT_EQ(module["protocol"], "tmcl");
  EXPECT_EQ(module["firmware"], "1636V109");
  const Json& axis = module["sections"][0];
  EXPECT_EQ(axis["kind"], "axis");
  bool found = false;
  for (const Json& parameter : axis["parameters"]) {
    if (parameter["number"] != 11) continue;
    found = true;
    EXPECT_FALSE(parameter["name"].get<std::string>().empty());
    EXPECT_LT(parameter["min"].get<int64_t>(), parameter["max"].get<int64_t>());
    EXPECT_NE(parameter["access"].get<std::string>().find('W'), std::string::npos);
  }
  EXPECT_TRUE(found);
  // User variables (a run of numbers in the descriptor) are listed one by one.
  EXPECT_EQ(module["sections"][2]["bank"], 2);
  EXPECT_GT(module["sections"][2]["parameters"].size(), 1u);
}

TEST(WebConsole, set_in_range_is_taken_and_read_back) {
  ConsoleRig rig("tmcm-1636");
  Json reply = rig.ask({{"op", "set"}, {"number", 11}, {"axis", 0}, {"value", 1234}});
  EXPECT_EQ(reply["ok"], true);
  EXPECT_EQ(reply["status"], 100);
  reply = rig.ask({{"op", "get"}, {"number", 11}});
  EXPECT_EQ(reply["value"], 1234);
  EXPECT_EQ(reply["status_name"], "ok");
}

TEST(WebConsole, out_of_range_value_gets_the_modules_status_and_changes_nothing) {
  ConsoleRig rig("tmcm-1636");
  // Parameter 11, max current: 0..60000 mA.
  const int64_t before = rig.ask({{"op", "get"}, {"number", 11}})["value"];
  const Json reply = rig.ask({{"op", "set"}, {"number", 11}, {"value", 60001}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_EQ(reply["status"], 4);  // what a TMCL host gets for SAP 11, 0, 60001: invalid value
  EXPECT_EQ(reply["status_name"], "invalid value");
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 11}})["value"], before);
}

TEST(WebConsole, a_read_only_parameter_refuses_a_set_with_the_modules_status) {
  ConsoleRig rig("tmcm-1636");
  // Find a row without W in the descriptor.
  const Json list = rig.ask({{"op", "list"}});
  std::optional<int> read_only;
  for (const Json& parameter : list["modules"][0]["sections"][0]["parameters"]) {
    if (parameter["access"].get<std::string>().find('W') == std::string::npos) {
      read_only = parameter["number"];
      break;
    }
  }
  ASSERT_TRUE(read_only.has_value());
  const Json reply = rig.ask({{"op", "set"}, {"number", *read_only}, {"value", 1}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_NE(reply["status"], 100);
}

TEST(WebConsole, global_parameters_store_and_restore_answer_with_status) {
  ConsoleRig rig("tmcm-1636");
  EXPECT_EQ(rig.ask({{"op", "get"}, {"kind", "global"}, {"number", 77}, {"bank", 0}})["status"], 100);
  const Json stored = rig.ask({{"op", "store"}, {"number", 11}, {"axis", 0}});
  EXPECT_EQ(stored["command"], 7);  // STAP
  EXPECT_EQ(stored["status"], 100);
  rig.ask({{"op", "set"}, {"number", 11}, {"value", 777}});
  const Json restored = rig.ask({{"op", "restore"}, {"number", 11}, {"axis", 0}});
  EXPECT_EQ(restored["command"], 8);  // RSAP
  EXPECT_EQ(restored["status"], 100);
  EXPECT_NE(rig.ask({{"op", "get"}, {"number", 11}})["value"], 777);
}

TEST(WebConsole, tmcl_takes_mnemonics_as_motwin_tmcl_does) {
  ConsoleRig rig("tmcm-1636");
  Json reply = rig.ask({{"op", "tmcl"}, {"text", "SAP 11, 0, 2500"}});
  EXPECT_EQ(reply["ok"], true);
  EXPECT_EQ(reply["instruction"], "SAP 11, 0, 2500");
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "gap 11 0"}})["value"], 2500);
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "136 0"}})["version"], "1636V109");
  // 137 (factory defaults) has no reply: the console says so once the module has served it.
  reply = rig.ask({{"op", "tmcl"}, {"text", "137 0 0 1234"}});
  EXPECT_EQ(reply["ok"], true);
  EXPECT_EQ(reply["replied"], false);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 11}})["value"], 2000);  // its default again
  reply = rig.ask({{"op", "tmcl"}, {"text", "139 0"}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_NE(reply["error"].get<std::string>().find("ASCII"), std::string::npos);
}

TEST(WebConsole, subscription_pushes_batches_with_advancing_simulated_time) {
  ConsoleRig rig("tmcm-1636");
  rig.ask({{"op", "set"}, {"number", 11}, {"value", 1111}});
  const Json ack = rig.ask({{"op", "subscribe"},
                            {"items", {{{"kind", "axis"}, {"number", 11}}, {{"kind", "global"}, {"number", 77}}}},
                            {"rate_hz", 50}});
  ASSERT_EQ(ack["ok"], true);
  EXPECT_EQ(ack["items"], 2);
  const Json first = rig.next_push();
  EXPECT_EQ(first["push"], "update");
  ASSERT_EQ(first["values"].size(), 2u);
  EXPECT_EQ(first["values"][0]["number"], 11);
  EXPECT_EQ(first["values"][0]["value"], 1111);
  EXPECT_EQ(first["values"][1]["kind"], "global");
  const Json second = rig.next_push();
  EXPECT_GT(second["sim_time_us"].get<uint64_t>(), first["sim_time_us"].get<uint64_t>());
  EXPECT_EQ(rig.ask({{"op", "unsubscribe"}})["ok"], true);
  EXPECT_EQ(rig.ask({{"op", "subscribe"}, {"items", Json::array()}, {"rate_hz", 1000}})["ok"], false);
}

// Pages showing the same rows: their batches start on the same multiple of the period, and a
// read of a row still waiting to be served answers every session that asks for it, so the
// module serves one read per row and period however many pages are open; each page still gets
// its own push, with the same simulated time and values.
TEST(WebConsole, sessions_subscribed_to_the_same_rows_share_their_reads) {
  ConsoleRig rig("tmcm-1636");
  FakeWebConnection other_connection;
  std::unique_ptr<host::web::WebSessionHandler> other = rig.open_session(other_connection);
  Json items = Json::array();
  for (int number : {0, 1, 2, 3, 4, 5, 6, 11}) items.push_back({{"kind", "axis"}, {"number", number}});
  const Json subscribe = {{"id", 7}, {"op", "subscribe"}, {"items", items}, {"rate_hz", 50}};
  rig.send_only(subscribe.dump());
  other->on_message(subscribe.dump());
  FakeWebConnection& first = rig.connection();
  const auto run_until_both_have = [&](size_t pushes) {
    for (int step = 0; step < 2'000'000 && (first.latest_count < pushes || other_connection.latest_count < pushes);
         ++step) {
      rig.step();
    }
    ASSERT_GE(first.latest_count, pushes);
    ASSERT_GE(other_connection.latest_count, pushes);
  };
  // The first batch of each starts at once (not shared); from the second on they coincide.
  run_until_both_have(3);
  const uint64_t served_before = rig.served_tmcl_requests();
  const size_t pushes_before = std::max(first.latest_count, other_connection.latest_count);
  run_until_both_have(pushes_before + 5);
  const size_t batches = std::max(first.latest_count, other_connection.latest_count) - pushes_before;
  // One read per row and batch (one more batch may be on its way), not one per row, batch and page.
  EXPECT_LE(rig.served_tmcl_requests() - served_before, (batches + 1) * items.size());
  ASSERT_TRUE(first.latest && other_connection.latest);
  EXPECT_EQ((*first.latest)["sim_time_us"], (*other_connection.latest)["sim_time_us"]);
  EXPECT_EQ((*first.latest)["values"], (*other_connection.latest)["values"]);
  other.reset();
}

TEST(WebConsole, too_many_waiting_requests_are_refused_not_queued) {
  ConsoleRig rig("tmcm-1636");
  // No loop turns in between: no reply can come yet, so the requests wait.
  for (size_t i = 0; i < WebConsole::kMaxPendingRequestsPerSession; ++i) {
    rig.send_only(Json{{"id", static_cast<int>(i)}, {"op", "get"}, {"number", 1}}.dump());
  }
  EXPECT_TRUE(rig.connection().replies.empty());
  rig.send_only(Json{{"id", 999}, {"op", "get"}, {"number", 1}}.dump());
  ASSERT_EQ(rig.connection().replies.size(), 1u);
  EXPECT_EQ(rig.connection().replies[0]["id"], 999);
  EXPECT_EQ(rig.connection().replies[0]["ok"], false);
  // The waiting ones are all answered, and the session takes requests again.
  rig.run_until_replies(WebConsole::kMaxPendingRequestsPerSession + 1);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 1}})["ok"], true);
  size_t answered = 0;
  for (const Json& reply : rig.connection().replies) answered += reply["ok"] == true ? 1 : 0;
  EXPECT_EQ(answered, WebConsole::kMaxPendingRequestsPerSession + 1);
}

// --- A module of three motors: the TMCM-3216's TMCL firmware -----------------------------------

TEST(WebConsole, list_says_how_many_motors_a_module_has) {
  EXPECT_EQ(ConsoleRig("tmcm-1636").ask({{"op", "list"}})["modules"][0]["motors"], 1);
  EXPECT_EQ(ConsoleRig("tmcm-142").ask({{"op", "list"}})["modules"][0]["motors"], 1);
  const Json three = ConsoleRig("tmcm-3216", "tmcl").ask({{"op", "list"}})["modules"][0];
  EXPECT_EQ(three["protocol"], "tmcl");
  EXPECT_EQ(three["firmware"], "3216V100");
  EXPECT_EQ(three["motors"], 3);
  EXPECT_EQ(three["sections"][0]["kind"], "axis");  // one table, for every motor
  // A CANopen node: the axes its dictionary lists.
  EXPECT_EQ(ConsoleRig("tmcm-3216").ask({{"op", "list"}})["modules"][0]["motors"], 3);
}

// AP 4 (maximum positioning speed) of each motor is its own: what the console sets on motor 2 a
// TMCL host reads there (GAP 4, 2), and the other way round, motors 0 and 1 untouched.
TEST(WebConsole, each_motors_axis_parameters_are_read_and_written_by_the_axis_field) {
  ConsoleRig rig("tmcm-3216", "tmcl");
  const int64_t motor0 = rig.ask({{"op", "get"}, {"number", 4}, {"axis", 0}})["value"];
  const int64_t motor1 = rig.ask({{"op", "get"}, {"number", 4}, {"axis", 1}})["value"];
  Json reply = rig.ask({{"op", "set"}, {"kind", "axis"}, {"number", 4}, {"axis", 2}, {"value", 12345}});
  EXPECT_EQ(reply["ok"], true) << reply.dump();
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "GAP 4, 2"}})["value"], 12345);
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "GAP 4, 0"}})["value"], motor0);
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "GAP 4, 1"}})["value"], motor1);
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "SAP 4, 1, 23456"}})["status"], 100);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 4}, {"axis", 1}})["value"], 23456);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 4}, {"axis", 2}})["value"], 12345);
  // Store and restore reach the motor asked for: STAP 4, 2 keeps 12345 through a set.
  const Json stored = rig.ask({{"op", "store"}, {"number", 4}, {"axis", 2}});
  EXPECT_EQ(stored["command"], 7);
  EXPECT_EQ(stored["status"], 100);
  rig.ask({{"op", "set"}, {"number", 4}, {"axis", 2}, {"value", 777}});
  EXPECT_EQ(rig.ask({{"op", "restore"}, {"number", 4}, {"axis", 2}})["status"], 100);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"number", 4}, {"axis", 2}})["value"], 12345);
}

// A motor beyond the last is refused by the console with the module's motors named, nothing
// sent; a TMCL host's GAP 4, 3 gets status 4 (invalid value) from the firmware.
TEST(WebConsole, a_motor_beyond_the_last_is_refused_before_anything_is_sent) {
  ConsoleRig rig("tmcm-3216", "tmcl");
  const uint64_t served = rig.served_tmcl_requests();
  for (const char* op : {"get", "set", "store", "restore"}) {
    const Json reply = rig.ask({{"op", op}, {"number", 4}, {"axis", 3}, {"value", 1}});
    EXPECT_EQ(reply["ok"], false);
    EXPECT_EQ(reply["error"], "\"axis\": no motor 3 on tmcm-3216 (3 motors: 0..2)") << op;
  }
  const Json subscribe = rig.ask({{"op", "subscribe"}, {"items", {{{"number", 4}, {"axis", 3}}}}});
  EXPECT_EQ(subscribe["ok"], false);
  EXPECT_EQ(subscribe["error"], "\"axis\": no motor 3 on tmcm-3216 (3 motors: 0..2)");
  EXPECT_EQ(rig.served_tmcl_requests(), served);
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "GAP 4, 3"}})["status"], 4);
  // A global parameter's bank is no motor.
  EXPECT_EQ(rig.ask({{"op", "get"}, {"kind", "global"}, {"number", 0}, {"bank", 2}})["status"], 100);
  // One motor: axis 1 is beyond it.
  EXPECT_EQ(ConsoleRig("tmcm-1636").ask({{"op", "get"}, {"number", 4}, {"axis", 1}})["error"],
            "\"axis\": no motor 1 on tmcm-1636 (one motor: 0)");
}

// A subscription of the same parameter on each motor: each value its motor's, each item echoing
// its axis (the page tells them apart by it).
TEST(WebConsole, a_subscription_reads_each_motor_of_the_same_parameter) {
  ConsoleRig rig("tmcm-3216", "tmcl");
  for (int motor = 0; motor < 3; ++motor) {
    rig.ask({{"op", "set"}, {"number", 4}, {"axis", motor}, {"value", 1000 * (motor + 1)}});
  }
  Json items = Json::array();
  for (int motor = 0; motor < 3; ++motor) items.push_back({{"kind", "axis"}, {"number", 4}, {"axis", motor}});
  ASSERT_EQ(rig.ask({{"op", "subscribe"}, {"items", items}, {"rate_hz", 50}})["ok"], true);
  const Json push = rig.next_push();
  ASSERT_EQ(push["values"].size(), 3u);
  for (int motor = 0; motor < 3; ++motor) {
    EXPECT_EQ(push["values"][motor]["axis"], motor);
    EXPECT_EQ(push["values"][motor]["value"], 1000 * (motor + 1));
  }
}

// --- A CANopen node -----------------------------------------------------------------------------

TEST(WebConsole, canopen_node_objects_sdo_and_nmt) {
  ConsoleRig rig("tmcm-3216");
  rig.run_for_us(400'000);  // past the boot-up
  const Json list = rig.ask({{"op", "list"}});
  const Json& module = list["modules"][0];
  EXPECT_EQ(module["protocol"], "canopen");
  EXPECT_EQ(module["node_id"], 1);
  EXPECT_EQ(module["sections"][0]["kind"], "objects");
  EXPECT_EQ(module["sections"][0]["objects"][0]["index"], 0x1000);

  // 1000: device type, read through an SDO upload.
  Json reply = rig.ask({{"op", "get"}, {"index", 0x1000}, {"sub", 0}});
  EXPECT_EQ(reply["ok"], true);
  EXPECT_EQ(reply["data"].get<std::string>().size(), 8u);
  // A string by a segmented upload.
  reply = rig.ask({{"op", "sdo_read"}, {"index", 0x1008}, {"sub", 0}});
  EXPECT_EQ(reply["text"], "TMCM-3216");
  // Written and read back: 6060 modes of operation (INTEGER8).
  reply = rig.ask({{"op", "set"}, {"index", 0x6060}, {"sub", 0}, {"value", 1}});
  EXPECT_EQ(reply["ok"], true);
  EXPECT_EQ(rig.ask({{"op", "get"}, {"index", 0x6060}})["value"], 1);
  // Read-only: the node's abort code.
  reply = rig.ask({{"op", "set"}, {"index", 0x1000}, {"sub", 0}, {"value", 1}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_EQ(reply["abort"], "0x06010002");
  // No such object.
  reply = rig.ask({{"op", "sdo_read"}, {"index", 0x5FFF}, {"sub", 0}});
  EXPECT_EQ(reply["abort"], "0x06020000");
  // Raw write with a size to another node: nobody answers.
  reply = rig.ask({{"op", "sdo_write"}, {"node", 9}, {"index", 0x6060}, {"sub", 0}, {"value", 1}, {"size", 1}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_EQ(reply["error"], "no answer from node 9");

  // NMT start; a heartbeat shows the new state.
  EXPECT_EQ(rig.ask({{"op", "set"}, {"index", 0x1017}, {"value", 50}})["ok"], true);
  rig.run_for_us(100'000);
  EXPECT_EQ(rig.ask({{"op", "list"}})["modules"][0]["nmt_state"], "pre-operational");
  EXPECT_EQ(rig.ask({{"op", "nmt"}, {"command", "start"}})["ok"], true);
  rig.run_for_us(200'000);
  EXPECT_EQ(rig.ask({{"op", "list"}})["modules"][0]["nmt_state"], "operational");
  // The same state without the tables.
  const Json states = rig.ask({{"op", "nmt_state"}});
  EXPECT_EQ(states["ok"], true);
  EXPECT_EQ(states["nodes"], Json::parse(R"([{"module": 0, "node_id": 1, "nmt_state": "operational"}])"));
  EXPECT_FALSE(states.contains("modules"));
  EXPECT_EQ(rig.ask({{"op", "nmt"}, {"command", "jump"}})["ok"], false);
  EXPECT_EQ(rig.ask({{"op", "tmcl"}, {"text", "GAP 1 0"}})["ok"], false);
}

TEST(WebConsole, canopen_subscription_reads_objects) {
  ConsoleRig rig("tmcm-3216");
  rig.run_for_us(400'000);
  ASSERT_EQ(rig.ask({{"op", "subscribe"}, {"items", {{{"index", 0x6041}}, {{"index", 0x6064}}}}, {"rate_hz", 20}})["ok"],
            true);
  const Json push = rig.next_push();
  ASSERT_EQ(push["values"].size(), 2u);
  EXPECT_EQ(push["values"][0]["index"], 0x6041);
  EXPECT_TRUE(push["values"][0].contains("value"));
  EXPECT_TRUE(push["values"][1].contains("value"));
}

// --- The bus monitor -----------------------------------------------------------------------------

// The frames of pushes from reply `from` on, in order.
std::vector<Json> pushed_frames(const FakeWebConnection& connection, size_t from) {
  std::vector<Json> frames;
  for (size_t i = from; i < connection.replies.size(); ++i) {
    if (connection.replies[i].value("push", "") != "frames") continue;
    for (const Json& frame : connection.replies[i]["frames"]) frames.push_back(frame);
  }
  return frames;
}

TEST(WebConsole, monitor_pushes_the_bus_frames_heard_and_sent) {
  ConsoleRig rig("tmcm-3216");
  const Json on = rig.ask({{"op", "monitor"}});
  EXPECT_EQ(on["ok"], true);
  EXPECT_EQ(on["enable"], true);
  const size_t from = rig.connection().replies.size();
  ASSERT_EQ(rig.ask({{"op", "nmt"}, {"command", "start"}})["ok"], true);
  ASSERT_EQ(rig.ask({{"op", "sdo_read"}, {"index", 0x1008}})["ok"], true);
  Json push;
  std::vector<Json> frames;
  const auto seen = [&frames](uint32_t id, const char* data) {
    return std::any_of(frames.begin(), frames.end(),
                       [&](const Json& frame) { return frame["id"] == id && frame["data"] == data; });
  };
  // The console's NMT start, the node's TPDO 1 (statusword 0x0240) and an SDO upload's request.
  for (int i = 0; i < 20 && !(seen(0x000, "0101") && seen(0x181, "4002") && seen(0x601, "4008100000000000")); ++i) {
    push = rig.next_frames_push(rig.connection().replies.size());
    ASSERT_FALSE(push.is_null());
    frames = pushed_frames(rig.connection(), from);
  }
  EXPECT_TRUE(seen(0x000, "0101"));
  EXPECT_TRUE(seen(0x181, "4002"));
  EXPECT_TRUE(seen(0x601, "4008100000000000"));
  EXPECT_EQ(push["dropped"], 0);
  for (const Json& frame : frames) EXPECT_TRUE(frame["t_us"].is_number_unsigned());
  EXPECT_EQ(rig.ask({{"op", "monitor"}, {"enable", false}})["enable"], false);
  const size_t after_off = rig.connection().replies.size();
  ASSERT_EQ(rig.ask({{"op", "nmt"}, {"command", "stop"}})["ok"], true);
  EXPECT_TRUE(rig.next_frames_push(after_off, 5 * WebConsole::kMonitorPeriodUs).is_null());
  EXPECT_EQ(rig.ask({{"op", "monitor"}, {"enable", 1}})["ok"], false);
}

TEST(WebConsole, monitor_keeps_a_bounded_buffer_for_a_slow_page_and_counts_what_it_drops) {
  ConsoleRig rig("tmcm-3216");
  ASSERT_EQ(rig.ask({{"op", "sdo_write"}, {"index", 0x1017}, {"value", 1}})["ok"], true);  // 1000 frames/s
  rig.connection().queued = WebConsole::kMonitorMaxQueuedBytes + 1;  // the page reads nothing
  ASSERT_EQ(rig.ask({{"op", "monitor"}})["ok"], true);
  const size_t from = rig.connection().replies.size();
  rig.run_for_us(3'000'000);  // 3000 heartbeats
  EXPECT_TRUE(rig.next_frames_push(from, 5 * WebConsole::kMonitorPeriodUs).is_null());  // held: the page is behind
  rig.connection().queued = 0;
  const Json push = rig.next_frames_push(from);
  ASSERT_FALSE(push.is_null());
  EXPECT_EQ(push["frames"].size(), WebConsole::kMaxFramesPerMonitorPush);
  EXPECT_GE(push["dropped"].get<uint64_t>(), 3000 - WebConsole::kMaxMonitorBufferedFrames);
  EXPECT_EQ(push["frames"][0]["id"], 0x701);  // the oldest first
}

TEST(WebConsole, monitor_needs_a_bus) {
  ConsoleRig rig("tmcm-1636");
  const Json reply = rig.ask({{"op", "monitor"}});
  EXPECT_EQ(reply["ok"], false);
  EXPECT_EQ(reply["error"], "no CAN bus on this serve");
}

}  // namespace
}  // namespace motwin::tools::web

namespace motwin::host::web {
namespace {

TEST(WebEndpoint, loopback_by_default_and_elsewhere_only_with_a_token) {
  Result<WebEndpointSpec> spec = parse_web_endpoint("127.0.0.1:0");
  ASSERT_TRUE(spec) << spec.error();
  EXPECT_EQ(spec->host, "127.0.0.1");
  EXPECT_EQ(spec->port, 0);
  spec = parse_web_endpoint("8081");
  ASSERT_TRUE(spec);
  EXPECT_EQ(spec->host, "127.0.0.1");
  EXPECT_EQ(spec->port, 8081);
  EXPECT_FALSE(parse_web_endpoint("0.0.0.0:8080"));
  EXPECT_NE(parse_web_endpoint("192.168.1.5:8080").error().find("--web-token"), std::string::npos);
  spec = parse_web_endpoint("0.0.0.0:8080", "s3cret");
  ASSERT_TRUE(spec);
  EXPECT_EQ(spec->token, "s3cret");
  EXPECT_FALSE(parse_web_endpoint("localhost:8080"));
  EXPECT_FALSE(parse_web_endpoint("127.0.0.1:70000"));
  EXPECT_TRUE(is_loopback_ipv4("127.4.5.6"));
  EXPECT_FALSE(is_loopback_ipv4("128.0.0.1"));
}

}  // namespace
}  // namespace motwin::host::web

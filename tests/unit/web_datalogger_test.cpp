// The web console's "datalogger" op (tools/web/web_datalogger.h) without sockets: a capture set
// up, watched and read out through the module's own TMCL service, and the samples it returns
// equal to what GET_SAMPLE (142 type 9) answers over TMCL for the same capture; the module's own
// refusals; modules without a datalogger.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "host/host_runtime.h"
#include "host/module_registry.h"
#include "support/web_console_rig.h"
#include "tools/web/web_console.h"
#include "tools/web/web_datalogger.h"

namespace motwin::tools::web {
namespace {

using Json = nlohmann::json;
using motwin::testing::FakeWebConnection;

// A console on one module and two sessions (a page's capture and its live values).
class Rig : public motwin::testing::WebConsoleRig {
 public:
  explicit Rig(const char* module_name) : WebConsoleRig(module_name), other_session_(open_session(other_connection_)) {}

  Json datalogger(Json request) {
    request["op"] = "datalogger";
    return ask(std::move(request));
  }
  // Polls the state as the page does until it is `state`; simulated time runs meanwhile.
  Json wait_for_state(const std::string& state) {
    Json reply;
    for (int poll = 0; poll < 2000; ++poll) {
      reply = datalogger({{"action", "state"}});
      if (reply.value("state", "") == state) return reply;
      runtime().advance_ticks(20);  // 1 ms of a TMCM-1636
    }
    ADD_FAILURE() << "the datalogger never reached " << state << ": " << reply.dump();
    return reply;
  }
  bool replied(const Json& id) const { return !find_reply(id).is_null(); }
  FakeWebConnection& other_connection() { return other_connection_; }
  host::web::WebSessionHandler& other_session() { return *other_session_; }

 private:
  FakeWebConnection other_connection_;
  std::unique_ptr<host::web::WebSessionHandler> other_session_;
};

TEST(WebDatalogger, info_gives_the_modules_figures) {
  Rig rig("tmcm-1636");
  const Json info = rig.datalogger({{"action", "info"}});
  ASSERT_EQ(info["ok"], true) << info.dump();
  EXPECT_EQ(info["channels"], 4);
  EXPECT_EQ(info["buffer_words"], 8192);
  EXPECT_EQ(info["base_rate_hz"], 2000);
  EXPECT_TRUE(info.contains("sim_time_us"));
}

TEST(WebDatalogger, modules_without_a_datalogger_say_so) {
  Rig stepper("tmcm-142");
  const Json refused = stepper.datalogger({{"action", "info"}});
  EXPECT_EQ(refused["ok"], false);
  EXPECT_EQ(refused["step"], "GET_INFO");
  EXPECT_EQ(refused["status"], 2);  // invalid command: the TMCM-142 has no command 142
  Rig node("tmcm-3216");
  const Json no_tmcl = node.datalogger({{"action", "info"}});
  EXPECT_EQ(no_tmcl["ok"], false);
  EXPECT_NE(no_tmcl["error"].get<std::string>().find("no datalogger"), std::string::npos) << no_tmcl.dump();
}

TEST(WebDatalogger, malformed_requests_are_refused_before_anything_is_sent) {
  Rig rig("tmcm-1636");
  EXPECT_EQ(rig.datalogger({{"action", "go"}})["ok"], false);
  EXPECT_EQ(rig.datalogger({{"action", "start"}, {"samples", 10}})["ok"], false);  // no channels
  EXPECT_EQ(rig.datalogger({{"action", "start"}, {"channels", {{{"number", 52}}}}})["ok"], false);  // no samples
  const Json bad_trigger = rig.datalogger({{"action", "start"},
                                           {"channels", {{{"number", 52}}}},
                                           {"samples", 10},
                                           {"trigger", {{"channel", 1}, {"level", 0}}}});
  EXPECT_EQ(bad_trigger["ok"], false);
  EXPECT_NE(bad_trigger["error"].get<std::string>().find("trigger"), std::string::npos);
  // A motor the module does not have (the TMCM-1636 has one).
  const Json no_motor = rig.datalogger(
      {{"action", "start"}, {"channels", {{{"number", 52}}, {{"number", 42}, {"axis", 1}}}}, {"samples", 10}});
  EXPECT_EQ(no_motor["ok"], false);
  EXPECT_EQ(no_motor["error"], "\"axis\": no motor 1 on tmcm-1636 (one motor: 0)");
  // Nothing reached the module: it is still idle after power-up.
  EXPECT_EQ(rig.datalogger({{"action", "state"}})["state"], "idle");
}

TEST(WebDatalogger, the_modules_own_status_ends_a_start) {
  Rig rig("tmcm-1636");
  // Five channels: the TMCM-1636 has four slots and refuses the fifth with status 9.
  Json channels = Json::array();
  for (int number : {52, 42, 31, 50, 51}) channels.push_back({{"kind", "axis"}, {"number", number}});
  const Json refused = rig.datalogger({{"action", "start"}, {"channels", channels}, {"samples", 10}});
  EXPECT_EQ(refused["ok"], false);
  EXPECT_EQ(refused["step"], "SET_CHANNEL");
  EXPECT_EQ(refused["status"], 9);
  // An unknown axis parameter: status 3, as GAP answers it.
  const Json unknown = rig.datalogger({{"action", "start"}, {"channels", {{{"number", 254}}}}, {"samples", 10}});
  EXPECT_EQ(unknown["ok"], false);
  EXPECT_EQ(unknown["status"], 3);
  // No capture to read.
  const Json nothing = rig.datalogger({{"action", "read"}});
  EXPECT_EQ(nothing["ok"], false);
  EXPECT_EQ(nothing["state"], "idle");
}

// The op's samples are GET_SAMPLE's, in order, per channel.
TEST(WebDatalogger, read_returns_what_get_sample_answers_over_tmcl) {
  Rig rig("tmcm-1636");
  ASSERT_EQ(rig.ask({{"op", "tmcl"}, {"text", "MVP ABS, 0, 20000"}})["ok"], true);
  const Json started = rig.datalogger({{"action", "start"},
                                       {"channels", {{{"kind", "axis"}, {"number", 52}}, {{"kind", "axis"}, {"number", 42}},
                                                     {{"kind", "global"}, {"number", 132}}}},
                                       {"samples", 300},
                                       {"prescaler", 1}});
  ASSERT_EQ(started["ok"], true) << started.dump();
  rig.wait_for_state("complete");
  const Json read = rig.datalogger({{"action", "read"}});
  ASSERT_EQ(read["ok"], true) << read.dump();
  EXPECT_EQ(read["samples"], 300);
  EXPECT_EQ(read["pretrigger_samples"], 0);
  EXPECT_EQ(read["base_rate_hz"], 2000);
  ASSERT_EQ(read["channels"].size(), 3u);
  EXPECT_EQ(read["channels"][0], (Json{{"type", 1}, {"select", 52}, {"kind", "axis"}, {"number", 52}, {"axis", 0}}));
  EXPECT_EQ(read["channels"][2]["kind"], "global");
  EXPECT_EQ(read["channels"][2]["number"], 132);
  ASSERT_EQ(read["values"].size(), 3u);
  for (size_t row = 0; row < 300; ++row) {
    for (size_t channel = 0; channel < 3; ++channel) {
      const size_t index = row * 3 + channel;
      const Json sample = rig.ask({{"op", "tmcl"}, {"text", "142 9 0 " + std::to_string(index)}});
      ASSERT_EQ(sample["status"], 100);
      ASSERT_EQ(read["values"][channel][row], sample["value"]) << "row " << row << " channel " << channel;
    }
  }
  // The position moves; the systick (GP 132, ms) advances 1 ms every sample at 1000 samples/s.
  EXPECT_GT(read["values"][0][299].get<int64_t>(), read["values"][0][0].get<int64_t>());
  EXPECT_EQ(read["values"][2][299].get<int64_t>() - read["values"][2][0].get<int64_t>(), 299);
}

TEST(WebDatalogger, a_level_trigger_with_pretrigger_captures_the_crossing) {
  Rig rig("tmcm-1636");
  const Json started = rig.datalogger({{"action", "start"},
                                       {"channels", {{{"number", 52}}, {{"number", 42}}}},
                                       {"samples", 400},
                                       {"trigger", {{"channel", 0}, {"level", 1000}, {"edge", "rising"}, {"pretrigger", 100}}}});
  ASSERT_EQ(started["ok"], true) << started.dump();
  EXPECT_EQ(started["instructions"], 8);  // INIT, count, prescaler, 2 channels, trigger channel, pretrigger, enable
  const Json armed = rig.wait_for_state("trigger");
  EXPECT_EQ(rig.datalogger({{"action", "read"}})["ok"], false);  // nothing to read while armed
  ASSERT_EQ(rig.ask({{"op", "tmcl"}, {"text", "MVP ABS, 0, 20000"}})["ok"], true);
  const Json complete = rig.wait_for_state("complete");
  EXPECT_EQ(complete["captured_words"], 800);
  const Json read = rig.datalogger({{"action", "read"}});
  ASSERT_EQ(read["ok"], true) << read.dump();
  EXPECT_EQ(read["samples"], 400);
  EXPECT_EQ(read["pretrigger_samples"], 100);
  const Json& position = read["values"][0];
  EXPECT_LE(position[99].get<int64_t>(), 1000);
  EXPECT_GT(position[100].get<int64_t>(), 1000);
  EXPECT_GT(position[399].get<int64_t>(), position[100].get<int64_t>());
  // Stop: INIT, idle again.
  EXPECT_EQ(rig.datalogger({{"action", "stop"}})["ok"], true);
  EXPECT_EQ(rig.datalogger({{"action", "state"}})["state"], "idle");
}

// A read-out goes a window at a time, so another session's request is answered before it ends.
TEST(WebDatalogger, other_requests_take_turns_during_a_read_out) {
  Rig rig("tmcm-1636");
  ASSERT_EQ(rig.datalogger({{"action", "start"}, {"channels", {{{"number", 52}}, {{"number", 42}}}}, {"samples", 4096}})["ok"],
            true);
  rig.wait_for_state("complete");
  const Json read = rig.datalogger({{"action", "read"}});  // a first, complete read
  ASSERT_EQ(read["samples"], 4096);
  // A second read, and while it runs another session's GAP: the GAP is answered first.
  rig.send_only(Json{{"id", "read"}, {"op", "datalogger"}, {"action", "read"}}.dump());
  for (int step = 0; step < 50; ++step) rig.runtime().step(0);
  ASSERT_FALSE(rig.replied("read"));
  rig.other_session().on_message(Json{{"id", "gap"}, {"op", "get"}, {"number", 52}}.dump());
  for (int step = 0; step < 2'000'000 && rig.other_connection().replies.empty(); ++step) rig.runtime().step(0);
  ASSERT_FALSE(rig.other_connection().replies.empty());
  EXPECT_EQ(rig.other_connection().replies[0]["id"], "gap");
  EXPECT_FALSE(rig.replied("read"));  // 8192 GET_SAMPLEs are not done yet
  for (int step = 0; step < 2'000'000 && !rig.replied("read"); ++step) rig.runtime().step(0);
  const Json again = rig.find_reply("read");
  ASSERT_EQ(again["ok"], true);
  EXPECT_EQ(again["values"], read["values"]);
}

// A page that closes during a read-out: the op sends nothing more, and the module goes on
// answering the console's other sessions.
TEST(WebDatalogger, a_session_closed_during_a_read_out_ends_it) {
  Rig rig("tmcm-1636");
  ASSERT_EQ(rig.datalogger({{"action", "start"}, {"channels", {{{"number", 52}}}}, {"samples", 8192}})["ok"], true);
  rig.wait_for_state("complete");
  rig.send_only(Json{{"id", "read"}, {"op", "datalogger"}, {"action", "read"}}.dump());
  for (int step = 0; step < 50; ++step) rig.runtime().step(0);
  ASSERT_FALSE(rig.replied("read"));
  const uint64_t served_before = rig.runtime().service().served_request_count();
  rig.close_session();
  for (int step = 0; step < 2000; ++step) rig.runtime().step(0);
  // At most the window already queued was served after the close.
  EXPECT_LE(rig.runtime().service().served_request_count() - served_before, kDataloggerReadWindow + 1);
  rig.other_session().on_message(Json{{"id", "gap"}, {"op", "get"}, {"number", 52}}.dump());
  for (int step = 0; step < 2'000'000 && rig.other_connection().replies.empty(); ++step) rig.runtime().step(0);
  ASSERT_FALSE(rig.other_connection().replies.empty());
  EXPECT_EQ(rig.other_connection().replies[0]["ok"], true);
}

}  // namespace
}  // namespace motwin::tools::web

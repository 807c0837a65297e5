// The web console's program ops (tools/web/web_program.h) without sockets, on a TMCM-1636 and
// a TMCM-142 run by their host runtime: a source assembled, downloaded and verified, read back
// and disassembled one line per address, assembly errors with line numbers (nothing reaches the
// module), run / stop / step / reset, the application status (135) after each step, the
// console's other requests held back during a download, and bad requests.
#include <gtest/gtest.h>

#include <memory>
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

class ProgramRig : public motwin::testing::WebConsoleRig {
 public:
  using WebConsoleRig::WebConsoleRig;

  // Runs the module until the reply with `id` has arrived.
  Json reply_to(int id) { return wait_for_reply(id); }
  Json status() { return ask({{"op", "app_status"}}); }
};

// Counts in the accumulator and copies it to user variable 0 (GGP 0, 2).
constexpr const char* kCounter =
    "// counter\n"
    "Loop:  CALC ADD, 1\n"
    "       AGP 0, 2\n"
    "       JA Loop\n";

class WebProgram : public ::testing::TestWithParam<const char*> {};

TEST_P(WebProgram, download_is_verified_and_reads_back_one_line_per_address) {
  ProgramRig rig(GetParam());
  const Json downloaded = rig.ask({{"op", "program_download"}, {"source", kCounter}, {"file_name", "counter.tmc"}});
  ASSERT_EQ(downloaded["ok"], true) << downloaded.dump();
  EXPECT_EQ(downloaded["count"], 4);  // with the STOP the assembler appends
  EXPECT_EQ(downloaded["verified"], true);
  EXPECT_EQ(downloaded["labels"], Json::parse(R"([{"name":"Loop","address":0}])"));

  const Json read = rig.ask({{"op", "program_read"}});
  ASSERT_EQ(read["ok"], true) << read.dump();
  EXPECT_EQ(read["end"], "nop");  // the NOP the download ends with
  const Json& lines = read["instructions"];
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0]["address"], 0);
  EXPECT_EQ(lines[0]["label"], "L0");
  EXPECT_EQ(lines[0]["text"], "CALC ADD, 1");
  EXPECT_EQ(lines[0]["command"], 19);
  EXPECT_EQ(lines[1]["text"], "AGP 0, 2");
  EXPECT_EQ(lines[2]["text"], "JA L0");
  EXPECT_EQ(lines[2]["value"], 0);
  EXPECT_FALSE(lines[1].contains("label"));
  EXPECT_EQ(lines[3]["text"], "STOP");
  EXPECT_NE(read["source"].get<std::string>().find("JA L0"), std::string::npos);

  // `count` reads exactly that many, past the NOP.
  const Json five = rig.ask({{"op", "program_read"}, {"count", 5}});
  ASSERT_EQ(five["instructions"].size(), 5u);
  EXPECT_EQ(five["instructions"][4]["command"], 0);
  EXPECT_EQ(five["end"], "count");
}

TEST_P(WebProgram, step_run_stop_reset_and_the_application_status) {
  ProgramRig rig(GetParam());
  ASSERT_EQ(rig.ask({{"op", "program_download"}, {"source", kCounter}})["ok"], true);
  Json status = rig.status();
  ASSERT_EQ(status["ok"], true) << status.dump();
  EXPECT_EQ(status["mode_name"], "stop");
  EXPECT_EQ(status["download_pointer"], 5);  // after the trailing NOP

  EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "reset"}})["status"], 100);
  status = rig.status();
  EXPECT_EQ(status["mode_name"], "reset");
  EXPECT_EQ(status["program_counter"], 0);
  EXPECT_EQ(status["stop_reason"], 0);
  EXPECT_FALSE(status.contains("stop_address"));

  // One instruction per 130, at the next control tick: PC 1 with A = 1, PC 2, back to 0, PC 1 with A = 2.
  const int expected_pc[] = {1, 2, 0, 1};
  const int expected_accumulator[] = {1, 1, 1, 2};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "step"}})["ok"], true);
    rig.run_for_us(5000);
    status = rig.status();
    EXPECT_EQ(status["mode_name"], "step");
    EXPECT_EQ(status["program_counter"], expected_pc[i]) << "step " << i;
    EXPECT_EQ(status["accumulator"], expected_accumulator[i]) << "step " << i;
    EXPECT_EQ(status["x_register"], 0);
    EXPECT_EQ(status["waiting"], false);
  }
  EXPECT_EQ(rig.ask({{"op", "get"}, {"kind", "global"}, {"number", 0}, {"bank", 2}})["value"], 1);

  EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "continue"}})["ok"], true);
  rig.run_for_us(10'000);
  status = rig.status();
  EXPECT_EQ(status["mode_name"], "run");
  EXPECT_GT(status["accumulator"].get<int64_t>(), 10);
  EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "stop"}})["status"], 100);
  status = rig.status();
  EXPECT_EQ(status["mode_name"], "stop");
  EXPECT_EQ(status["stop_reason"], 2);
  EXPECT_TRUE(status.contains("stop_address"));

  // From an address: 2 is JA, so the first instruction run jumps to 0.
  EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "run"}, {"address", 2}})["status"], 100);
  EXPECT_EQ(rig.status()["mode_name"], "run");
  // Outside program memory: the module's own status 4.
  const Json outside = rig.ask({{"op", "program_control"}, {"action", "run"}, {"address", 5000}});
  EXPECT_EQ(outside["ok"], false);
  EXPECT_EQ(outside["status"], 4);
}

INSTANTIATE_TEST_SUITE_P(TmclModules, WebProgram, ::testing::Values("tmcm-1636", "tmcm-142"),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                           return std::string(param.param).substr(5);  // "1636", "142"
                         });

TEST(WebProgramOps, assembly_errors_come_with_line_numbers_and_nothing_is_downloaded) {
  ProgramRig rig("tmcm-1636");
  ASSERT_EQ(rig.ask({{"op", "program_download"}, {"source", kCounter}})["ok"], true);
  const Json failed = rig.ask({{"op", "program_download"},
                               {"file_name", "bad.tmc"},
                               {"source", "  MVP ABS, 0, 1000\n  FLY 1\n  JA Nowhere\n"}});
  EXPECT_EQ(failed["ok"], false);
  EXPECT_EQ(failed["error"], "2 assembly errors");
  ASSERT_EQ(failed["errors"].size(), 2u);
  EXPECT_EQ(failed["errors"][0]["line"], 2);
  EXPECT_EQ(failed["errors"][0]["file"], "bad.tmc");
  EXPECT_NE(failed["errors"][0]["message"].get<std::string>().find("FLY"), std::string::npos);
  EXPECT_EQ(failed["errors"][1]["line"], 3);
  EXPECT_EQ(failed["errors"][1]["text"].get<std::string>().rfind("bad.tmc:3:", 0), 0u);
  // The module still holds the counter.
  const Json read = rig.ask({{"op", "program_read"}});
  ASSERT_EQ(read["instructions"].size(), 4u);
  EXPECT_EQ(read["instructions"][0]["text"], "CALC ADD, 1");
}

TEST(WebProgramOps, includes_come_only_from_the_request) {
  ProgramRig rig("tmcm-1636");
  const std::string source = "#include lib.tmc\n  SAP 4, 0, Speed\n";
  Json failed = rig.ask({{"op", "program_download"}, {"source", source}});
  EXPECT_EQ(failed["ok"], false);
  EXPECT_EQ(failed["errors"][0]["line"], 1);
  // Not from the server's file system either.
  failed = rig.ask({{"op", "program_download"}, {"source", "#include /etc/hostname\n"}});
  EXPECT_EQ(failed["ok"], false);
  const Json done = rig.ask({{"op", "program_download"}, {"source", source}, {"files", {{"lib.tmc", "Speed = 1234\n"}}}});
  ASSERT_EQ(done["ok"], true) << done.dump();
  EXPECT_EQ(rig.ask({{"op", "program_read"}})["instructions"][0]["value"], 1234);
}

TEST(WebProgramOps, the_consoles_other_requests_wait_for_the_end_of_a_download) {
  ProgramRig rig("tmcm-1636");
  // A live value read while the download runs would be stored as an instruction (status 101)
  // if it reached the module in download mode.
  const int download = rig.send({{"op", "program_download"}, {"source", kCounter}});
  const int get = rig.send({{"op", "get"}, {"number", 4}});
  const int second = rig.send({{"op", "program_download"}, {"source", kCounter}});
  const Json refused = rig.reply_to(second);
  EXPECT_EQ(refused["ok"], false);
  EXPECT_EQ(refused["error"], "a download to this module is in progress");
  EXPECT_EQ(rig.reply_to(download)["verified"], true);
  EXPECT_EQ(rig.reply_to(get)["status"], 100);
  EXPECT_EQ(rig.ask({{"op", "program_read"}})["instructions"].size(), 4u);
  EXPECT_EQ(rig.status()["download_pointer"], 5);
}

TEST(WebProgramOps, factory_memory_reads_to_its_end) {
  ProgramRig rig("tmcm-1636");
  // Empty memory holds STOP everywhere and no NOP: the read ends at the end of memory.
  const Json read = rig.ask({{"op", "program_read"}});
  ASSERT_EQ(read["ok"], true);
  EXPECT_EQ(read["end"], "memory_end");
  ASSERT_EQ(read["instructions"].size(), 2048u);
  EXPECT_EQ(read["instructions"][2047]["text"], "STOP");
}

TEST(WebProgramOps, bad_requests_are_errors) {
  ProgramRig rig("tmcm-1636");
  EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "fly"}})["error"],
            "\"action\": expected run, continue, stop, step or reset");
  EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "stop"}, {"address", 3}})["error"],
            "\"address\": only with \"action\": \"run\"");
  EXPECT_EQ(rig.ask({{"op", "program_control"}, {"action", "run"}, {"address", -1}})["error"],
            "\"address\": expected 0..65535");
  EXPECT_EQ(rig.ask({{"op", "program_download"}})["error"], "\"source\": expected the program's text");
  EXPECT_EQ(rig.ask({{"op", "program_download"}, {"source", ""}, {"verify", 1}})["error"],
            "\"verify\": expected true or false");
  EXPECT_EQ(rig.ask({{"op", "program_read"}, {"count", 0}})["error"], "\"count\": expected 1..2048");
  EXPECT_NE(rig.ask({{"op", "fly"}})["error"].get<std::string>().find("program_download"), std::string::npos);
  // Requests that could not start leave no request counted as waiting.
  for (int i = 0; i < 80; ++i) rig.ask({{"op", "program_control"}, {"action", "fly"}});
  EXPECT_EQ(rig.status()["ok"], true);
}

TEST(WebProgramOps, a_canopen_node_takes_no_program_ops) {
  host::MakeModuleResult made = motwin::testing::make_quiet_module("tmcm-3216");
  ASSERT_TRUE(made);
  host::HostRuntime runtime(**made, host::Pacing::fast());
  std::vector<ConsoleTarget> targets{canopen_target(*host::find_module("tmcm-3216"), "tmcm-3216", "x", 1)};
  WebConsole console(runtime.loop(), [] { return uint64_t{0}; }, std::move(targets), nullptr);
  FakeWebConnection connection;
  auto session = console.open_session(connection);
  session->on_message(R"({"id": 7, "op": "app_status"})");
  ASSERT_EQ(connection.replies.size(), 1u);
  EXPECT_EQ(connection.replies[0]["error"], "module tmcm-3216 takes no TMCL from the console");
}

}  // namespace
}  // namespace motwin::tools::web

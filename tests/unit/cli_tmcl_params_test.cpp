// `motwin tmcl` and `motwin params` as a user runs them: the real binary, a scripted module
// on 127.0.0.1 behind it.
#include <gtest/gtest.h>

#include <mutex>
#include <string>
#include <vector>

#include "support/motwin_cli.h"
#include "tools/child_process.h"
#include "tools/loopback_frame_server.h"
#include "tools/serve_process.h"
#include "tools/tmcl_client.h"

namespace motwin::tools {
namespace {

using motwin::testing::run_motwin;

using namespace std::chrono_literals;

bool contains(const std::string& text, std::string_view part) { return text.find(part) != std::string::npos; }

// Answers like a TMCM-1636 would for the few frames these tests send, and records them.
class ScriptedModule {
 public:
  ScriptedModule() {
    Result<std::unique_ptr<LoopbackFrameServer>> started =
        LoopbackFrameServer::start([this](const tmcl::Frame& request, tmcl::Frame& reply) { return answer(request, reply); });
    EXPECT_TRUE(started);
    if (started) server_ = std::move(started.value());
  }
  std::string address() const { return server_->address(); }
  std::vector<std::string> requests() {
    std::lock_guard lock(mutex_);
    return requests_;
  }

 private:
  size_t answer(const tmcl::Frame& request, tmcl::Frame& reply) {
    {
      std::lock_guard lock(mutex_);
      requests_.push_back(hex_bytes(request.data(), request.size()));
    }
    const tmcl::Instruction in = tmcl::decode_instruction(request);
    if (in.command == 136 && in.type == 0) {
      reply = {2, '1', '6', '3', '6', 'V', '1', '0', '9'};
      return reply.size();
    }
    if (in.command == 6 && in.type == 52) {
      reply = tmcl::encode_reply(2, 1, tmcl::Reply{100, 6, 12345});
    } else if (in.command == 6) {
      reply = tmcl::encode_reply(2, 1, tmcl::Reply{3, 6, 0});  // unknown parameter
    } else if (in.command == 10) {
      return 0;  // silence
    } else {
      reply = tmcl::encode_reply(2, 1, tmcl::Reply{100, in.command, in.value});
    }
    return reply.size();
  }

  std::mutex mutex_;
  std::vector<std::string> requests_;
  std::unique_ptr<LoopbackFrameServer> server_;
};

TEST(CliTmcl, sends_the_instruction_and_prints_status_and_value) {
  ScriptedModule module;
  const CompletedProcess gap = run_motwin({"tmcl", "--tcp", module.address(), "GAP", "52", "0"});
  EXPECT_EQ(gap.exit_status, 0) << gap.output;
  EXPECT_EQ(gap.output, "status 100 (ok) value 12345\n");

  // A negative operand is an operand, not an option.
  const CompletedProcess move = run_motwin({"tmcl", "--tcp", module.address(), "MVP", "REL", "0", "-10000"});
  EXPECT_EQ(move.exit_status, 0) << move.output;
  EXPECT_EQ(move.output, "status 100 (ok) value -10000\n");
  const CompletedProcess commas = run_motwin({"tmcl", "--tcp", module.address(), "MVP", "ABS,", "0,", "90000"});
  EXPECT_EQ(commas.exit_status, 0) << commas.output;
  const std::vector<std::string> sent = module.requests();
  ASSERT_EQ(sent.size(), 3u);
  EXPECT_EQ(sent[1], "01 04 01 00 FF FF D8 F0 CC");
  EXPECT_EQ(sent[2], "01 04 00 00 00 01 5F 90 F5");
}

TEST(CliTmcl, prints_the_version_string_of_command_136_type_0) {
  ScriptedModule module;
  const CompletedProcess version = run_motwin({"tmcl", "--tcp", module.address(), "136", "0"});
  EXPECT_EQ(version.exit_status, 0) << version.output;
  EXPECT_EQ(version.output, "version 1636V109\n");
}

TEST(CliTmcl, exit_status_1_on_an_error_status) {
  ScriptedModule module;
  const CompletedProcess wrong = run_motwin({"tmcl", "--tcp", module.address(), "GAP", "250", "0"});
  EXPECT_EQ(wrong.exit_status, 1) << wrong.output;
  EXPECT_TRUE(contains(wrong.output, "status 3 (wrong type) value 0\n")) << wrong.output;
  EXPECT_TRUE(contains(wrong.output, "motwin: error: the module answered status 3 (wrong type)\n")) << wrong.output;
}

TEST(CliTmcl, exit_status_2_on_usage_and_connection_errors) {
  ScriptedModule module;
  struct Case {
    std::vector<std::string> arguments;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"tmcl", "--tcp", module.address(), "--timeout-ms", "100", "GGP", "66", "0"},
       "motwin: error: no reply from tcp " + module.address() + " within 100 ms"},
      {{"tmcl", "--tcp", module.address(), "FOO", "1"}, "motwin: error: unknown mnemonic 'FOO'"},
      {{"tmcl", "--tcp", module.address(), "GAP", "52"}, "motwin: error: GAP takes 2 operands (param, motor), got 1"},
      {{"tmcl", "GAP", "52", "0"}, "motwin: error: give exactly one of --tcp HOST:PORT or --serial DEVICE"},
      {{"tmcl", "--tcp", module.address()}, "motwin: error: no instruction given"},
      {{"tmcl", "--tcp", "127.0.0.1", "GAP", "52", "0"}, "motwin: error: invalid TCP address '127.0.0.1'"},
      {{"tmcl", "--tcp", module.address(), "--module-address", "300", "GAP", "52", "0"},
       "motwin: error: --module-address: Value 300 not in range 0 to 255"},
      {{"tmcl", "--tcp", module.address(), "--bogus", "GAP", "52", "0"}, "motwin: error: "},
  };
  for (const Case& c : cases) {
    const CompletedProcess run = run_motwin(c.arguments);
    EXPECT_EQ(run.exit_status, 2) << c.message << "\n" << run.output;
    EXPECT_TRUE(contains(run.output, c.message)) << c.message << "\n" << run.output;
  }
}

// The real thing: `motwin tmcl` against `motwin serve`, over TCP and over its pseudo-terminal.
TEST(CliTmcl, drives_motwin_serve_over_tcp_and_the_pseudo_terminal) {
  Result<TemporaryDirectory> state_dir = TemporaryDirectory::create("motwin-cli-test-");
  ASSERT_TRUE(state_dir) << state_dir.error();
  const std::string pty_link = (state_dir->path() / "tmcl.tty").string();
  Result<RunningServe> serve =
      start_serve(MOTWIN_BINARY, {"--module", "tmcm-1636", "--tmcl-tcp", "127.0.0.1:0", "--tmcl-pty", pty_link,
                                  "--state-dir", state_dir->path().string(), "--speed", "fast"});
  ASSERT_TRUE(serve) << serve.error();
  const std::optional<std::string> tcp = serve->endpoint("tmcl-tcp");
  ASSERT_TRUE(tcp);

  const CompletedProcess move = run_motwin({"tmcl", "--tcp", *tcp, "MVP", "ABS,", "0,", "90000"});
  EXPECT_EQ(move.exit_status, 0) << move.output;
  EXPECT_EQ(move.output, "status 100 (ok) value 90000\n");
  const CompletedProcess target = run_motwin({"tmcl", "--serial", pty_link, "GAP", "50", "0"});
  EXPECT_EQ(target.exit_status, 0) << target.output;
  EXPECT_EQ(target.output, "status 100 (ok) value 90000\n");
  const CompletedProcess version = run_motwin({"tmcl", "--serial", pty_link, "136", "0"});
  EXPECT_EQ(version.output, "version 1636V109\n");
  const CompletedProcess binary_version = run_motwin({"tmcl", "--tcp", *tcp, "136", "1"});
  EXPECT_EQ(binary_version.output, "status 100 (ok) value 107217161\n");  // 0x06640109
}

TEST(CliParams, lists_tmcm1636_parameters_in_each_format) {
  const CompletedProcess table = run_motwin({"params", "--module", "tmcm-1636"});
  EXPECT_EQ(table.exit_status, 0) << table.output;
  EXPECT_TRUE(contains(table.output, "max velocity")) << table.output;
  const CompletedProcess csv = run_motwin({"params", "--module", "tmcm-1636", "--format", "csv"});
  EXPECT_EQ(csv.exit_status, 0);
  EXPECT_TRUE(contains(csv.output, "\naxis,,43,max velocity,0,200000,4000,RWEX,rpm,")) << csv.output;
  const CompletedProcess markdown = run_motwin({"params", "--module", "tmcm-1636", "--format", "markdown"});
  EXPECT_EQ(markdown.exit_status, 0);
  EXPECT_TRUE(contains(markdown.output, "| 43 | max velocity | 0..200000 | 4000 | RWEX | rpm |"));
}

TEST(CliParams, lists_the_rows_of_a_firmware_generation) {
  const CompletedProcess v113 = run_motwin({"params", "--module", "tmcm-1636", "--firmware", "1.13", "--format", "csv"});
  EXPECT_EQ(v113.exit_status, 0) << v113.output;
  for (const char* row : {"\naxis,,13,motor direction,0,1,0,RWEX,", "\naxis,,26,velocity sensor selection,0,2,0,RWEX,",
                          "\naxis,,56,position scaler,1,16777215,65536,RWEX,", "\naxis,,94,hall sensor inputs,0,7,0,R,",
                          "\naxis,,109,encoder inputs,0,7,0,R,", "\naxis,,165,absolute encoder data length,",
                          "\naxis,,166,absolute encoder position start,", "\naxis,,167,absolute encoder position length,"}) {
    EXPECT_TRUE(contains(v113.output, row)) << row;
  }
  EXPECT_FALSE(contains(v113.output, "dual shunt factor"));
  const CompletedProcess v109 = run_motwin({"params", "--module", "tmcm-1636", "--firmware", "1.09", "--format", "csv"});
  EXPECT_EQ(v109.exit_status, 0);
  EXPECT_TRUE(contains(v109.output, "\naxis,,7,dual shunt factor,"));
  EXPECT_FALSE(contains(v109.output, "velocity sensor selection"));
  EXPECT_EQ(v109.output, run_motwin({"params", "--module", "tmcm-1636", "--format", "csv"}).output) << "1.09 is the default";
  const CompletedProcess unknown = run_motwin({"params", "--module", "tmcm-1636", "--firmware", "9.99"});
  EXPECT_EQ(unknown.exit_status, 2);
  EXPECT_EQ(unknown.output, "motwin: error: unknown firmware \"9.99\" for tmcm-1636 (choices: 1.09, 1.13, canopen)\n");
  const CompletedProcess one = run_motwin({"params", "--module", "tmcm-142", "--firmware", "1.13"});
  EXPECT_EQ(one.exit_status, 2);
  EXPECT_TRUE(contains(one.output, "tmcm-142 has one firmware")) << one.output;
}

TEST(CliServe, unknown_firmware_is_refused_with_the_choices) {
  const CompletedProcess serve = run_motwin({"serve", "--firmware", "9.99", "--state-dir", "none"});
  EXPECT_EQ(serve.exit_status, 2);
  EXPECT_EQ(serve.output, "motwin: error: unknown firmware \"9.99\" for tmcm-1636 (choices: 1.09, 1.13, canopen)\n");
  const CompletedProcess other = run_motwin({"serve", "--module", "tmcm-3216", "--firmware", "1.13", "--state-dir", "none"});
  EXPECT_EQ(other.exit_status, 2);
  EXPECT_EQ(other.output, "motwin: error: unknown firmware \"1.13\" for tmcm-3216 (choices: canopen, tmcl)\n");
  const CompletedProcess run = run_motwin({"run", "missing.tmc", "--for", "1s", "--firmware", "9.99"});
  EXPECT_EQ(run.exit_status, 2);
  EXPECT_TRUE(contains(run.output, "unknown firmware \"9.99\"")) << run.output;
}

TEST(CliServe, firmware_1_13_answers_as_1636V113) {
  Result<RunningServe> serve = start_serve(
      MOTWIN_BINARY, {"--module", "tmcm-1636", "--firmware", "1.13", "--tmcl-tcp", "127.0.0.1:0", "--state-dir", "none"});
  ASSERT_TRUE(serve) << serve.error();
  const std::optional<std::string> tcp = serve->endpoint("tmcl-tcp");
  ASSERT_TRUE(tcp);
  EXPECT_EQ(run_motwin({"tmcl", "--tcp", *tcp, "136", "0"}).output, "version 1636V113\n");
  EXPECT_EQ(run_motwin({"tmcl", "--tcp", *tcp, "136", "1"}).output, "status 100 (ok) value 107217165\n");  // 0x0664010D
  // What PyTrinamic's print(motor.drive_settings) reads: GAP 15, 14, 10, 12, 11, 25, 26, 54, 53.
  for (const char* number : {"15", "14", "10", "12", "11", "25", "26", "54", "53"}) {
    const CompletedProcess gap = run_motwin({"tmcl", "--tcp", *tcp, "GAP", number, "0"});
    EXPECT_EQ(gap.exit_status, 0) << "GAP " << number << ": " << gap.output;
  }
  EXPECT_EQ(run_motwin({"tmcl", "--tcp", *tcp, "GAP", "7", "0"}).exit_status, 1);
}

TEST(CliParams, unknown_module_or_format_exits_2) {
  const CompletedProcess module = run_motwin({"params", "--module", "tmcm-9999"});
  EXPECT_EQ(module.exit_status, 2);
  EXPECT_EQ(module.output, "motwin: error: unknown module 'tmcm-9999' (known modules: tmcm-1636, tmcm-142, tmcm-3216)\n");
  const CompletedProcess format = run_motwin({"params", "--module", "tmcm-1636", "--format", "json"});
  EXPECT_EQ(format.exit_status, 2);
  EXPECT_TRUE(contains(format.output, "unknown format 'json'"));
  const CompletedProcess missing = run_motwin({"params"});
  EXPECT_EQ(missing.exit_status, 2);
  EXPECT_TRUE(contains(missing.output, "--module is required"));
}

}  // namespace
}  // namespace motwin::tools

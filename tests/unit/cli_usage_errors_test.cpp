// Usage errors that point at the fix (src/cli/usage_hints.h), and a second `serve` that is
// refused a pty link a live one owns: the real binary, as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli/usage_hints.h"
#include "support/motwin_cli.h"
#include "tools/child_process.h"
#include "tools/serve_process.h"

namespace motwin::tools {
namespace {

using motwin::testing::run_motwin;


TEST(UsageHints, the_closest_name_is_a_unique_extension_or_a_near_spelling) {
  const std::vector<std::string> commands{"serve", "status", "start", "stop", "step", "sdo"};
  EXPECT_EQ(cli::closest_name("serv", commands), "serve");
  EXPECT_EQ(cli::closest_name("sreve", commands), "serve") << "two letters swapped";
  EXPECT_EQ(cli::closest_name("stat", commands), "status") << "the only one it begins";
  EXPECT_EQ(cli::closest_name("st", commands), "") << "begins four: none is meant more than the others";
  EXPECT_EQ(cli::closest_name("canopen", commands), "");
  EXPECT_EQ(cli::closest_name("--tmcl-tpc", {"--tmcl-tcp", "--tmcl-pty"}), "--tmcl-tcp");
}

TEST(UsageErrors, a_mistyped_command_names_the_closest_one) {
  const CompletedProcess serv = run_motwin({"serv"});
  EXPECT_EQ(serv.exit_status, 2);
  EXPECT_EQ(serv.output, "motwin: error: unknown command \"serv\"; did you mean \"serve\"? (see --help)\n");
  const CompletedProcess far = run_motwin({"canopen"});
  EXPECT_EQ(far.exit_status, 2);
  EXPECT_NE(far.output.find("unknown command \"canopen\" (commands: serve, tmcl, params"), std::string::npos)
      << far.output;
  const CompletedProcess none = run_motwin({});
  EXPECT_EQ(none.exit_status, 2);
  EXPECT_NE(none.output.find("a command is required: serve, tmcl"), std::string::npos) << none.output;
}

TEST(UsageErrors, a_repeated_single_use_option_says_which_and_a_mistyped_one_its_closest) {
  const CompletedProcess twice = run_motwin({"serve", "--can-capture", "a.log", "--can-capture", "b.log"});
  EXPECT_EQ(twice.exit_status, 2);
  EXPECT_EQ(twice.output, "motwin: error: --can-capture is given 2 times; it takes one value (see --help)\n");
  const CompletedProcess typo = run_motwin({"serve", "--tmcl-tpc", "127.0.0.1:0"});
  EXPECT_EQ(typo.exit_status, 2);
  EXPECT_EQ(typo.output, "motwin: error: unknown option --tmcl-tpc of serve; did you mean --tmcl-tcp? (see --help)\n");
}

// Two servers, one link: the second is refused loudly and leaves the first one's link alone; a
// link the first leaves behind when it is killed is free again (tests/unit/host_pty_endpoint_test.cpp
// covers the stale link).
TEST(UsageErrors, a_second_serve_is_refused_the_pty_link_a_live_one_owns) {
  Result<TemporaryDirectory> directory = TemporaryDirectory::create("motwin-pty-claim");
  ASSERT_TRUE(directory) << directory.error();
  const std::string link = (directory->path() / "tmcm1636").string();
  Result<RunningServe> first = start_serve(MOTWIN_BINARY, {"--state-dir", "none", "--tmcl-pty", link});
  ASSERT_TRUE(first) << first.error();
  const std::filesystem::path target = std::filesystem::read_symlink(link);
  const CompletedProcess second = run_motwin({"serve", "--state-dir", "none", "--tmcl-pty", link});
  EXPECT_EQ(second.exit_status, 2) << second.output;
  EXPECT_NE(second.output.find(link + " is the serial port of a running motwin; not taking it over"), std::string::npos)
      << second.output;
  EXPECT_EQ(std::filesystem::read_symlink(link), target) << "the first server's link is untouched";
}

}  // namespace
}  // namespace motwin::tools

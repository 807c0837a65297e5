// The TMCL ASCII interface (core/tmcl/ascii_link.h) on a TMCM-1636: echo modes of GP 67,
// line editing, error statuses, resynchronisation after bad lines, BIN, RUN and STOP.
#include "core/tmcl/ascii_link.h"

#include <gtest/gtest.h>

#include <string>

#include "support/tmcm1636_rig.h"

namespace motwin::testing {
namespace {

using namespace std::string_literals;
using tmcl::AsciiCommand;
using tmcl::AsciiLink;
namespace cmd = tmcl::command;

// A terminal on the link: what it types goes through the AsciiLink, each complete line is
// served at once, and `transcript` is everything the module sends back (echo and replies).
struct Terminal {
  explicit Terminal(Tmcm1636Rig& r) : rig(r) {}

  Tmcm1636Rig& rig;
  AsciiLink link;
  std::string transcript;
  int lines = 0;
  bool left_ascii_mode = false;

  std::string type(const std::string& text) {
    transcript.clear();
    for (const char c : text) {
      const bool complete = link.push(static_cast<uint8_t>(c), tmcl::ascii_settings(rig.module));
      transcript.append(reinterpret_cast<const char*>(link.echo()), link.echo_length());
      if (!complete) continue;
      ++lines;
      const tmcl::AsciiResponse response = tmcl::serve_ascii_command(rig.engine, link.command(), 1);
      transcript.append(reinterpret_cast<const char*>(response.bytes), response.length);
      left_ascii_mode = left_ascii_mode || response.leave_ascii_mode;
    }
    return transcript;
  }
};

void set_echo_mode(Tmcm1636Rig& rig, int32_t gp67) { ASSERT_EQ(rig.command(cmd::kSgp, 67, 0, gp67).status, 100); }

TEST(AsciiLink, echoes_each_character_by_default_and_answers_like_the_manual) {
  Tmcm1636Rig rig;
  Terminal terminal{rig};
  ASSERT_EQ(rig.command(cmd::kSap, 241, 0, 1234).status, 100);
  // Manual 6.6.2: after "AGAP ..." the reply is "BA 100 <value>".
  EXPECT_EQ(terminal.type("AGAP 241, 0\r"), "AGAP 241, 0\rBA 100 1234\r");
  EXPECT_EQ(terminal.type("A SAP 241, 0, -5000\r"), "A SAP 241, 0, -5000\rBA 100 -5000\r");
  EXPECT_EQ(rig.gap(241), -5000);
}

TEST(AsciiLink, gp67_bit_4_echoes_the_whole_line_after_cr) {
  Tmcm1636Rig rig;
  set_echo_mode(rig, 0x10);
  Terminal terminal{rig};
  for (const char c : std::string("AGAP 241, 0")) {
    EXPECT_FALSE(terminal.link.push(static_cast<uint8_t>(c), tmcl::ascii_settings(rig.module)));
    EXPECT_EQ(terminal.link.echo_length(), 0u) << "no echo while typing";
  }
  EXPECT_EQ(terminal.type("\r"), "AGAP 241, 0\rBA 100 0\r");
  // The edited line is what comes back.
  EXPECT_EQ(terminal.type("AGAP 241x\b, 0\r"), "AGAP 241, 0\rBA 100 0\r");
}

TEST(AsciiLink, gp67_bit_5_sends_only_the_reply) {
  Tmcm1636Rig rig;
  set_echo_mode(rig, 0x20);
  Terminal terminal{rig};
  EXPECT_EQ(terminal.type("AGAP 241, 0\r"), "BA 100 0\r");
  set_echo_mode(rig, 0x30);  // both bits: no echo either
  EXPECT_EQ(terminal.type("AGAP 241, 0\r"), "BA 100 0\r");
  // Bit 0 (start mode) does not change the echo.
  set_echo_mode(rig, 0x21);
  EXPECT_EQ(terminal.type("AGAP 241, 0\r"), "BA 100 0\r");
}

TEST(AsciiLink, backspace_and_delete_edit_the_line) {
  Tmcm1636Rig rig;
  Terminal terminal{rig};
  EXPECT_EQ(terminal.type("ASAP 241, 0, 12\b3\r"), "ASAP 241, 0, 12\b \b3\rBA 100 13\r");
  EXPECT_EQ(rig.gap(241), 13);
  EXPECT_EQ(terminal.type("ASAP 241, 0, 77\x7f"
                          "8\r"),
            "ASAP 241, 0, 77\b \b8\rBA 100 78\r");
  // Erasing everything, the address letter included, leaves no line: the next letter starts one.
  // A backspace between lines is ignored.
  EXPECT_EQ(terminal.type("AG\b\b\bAGAP 241, 0\r"), "AG\b \b\b \bAGAP 241, 0\rBA 100 78\r");
  EXPECT_EQ(terminal.lines, 3);
}

TEST(AsciiLink, error_statuses_are_answered_in_the_reply_line) {
  Tmcm1636Rig rig;
  set_echo_mode(rig, 0x20);
  Terminal terminal{rig};
  EXPECT_EQ(terminal.type("AFOO 1, 2\r"), "BA 2 0\r") << "unknown mnemonic";
  EXPECT_EQ(terminal.type("A\r"), "BA 2 0\r") << "empty line";
  EXPECT_EQ(terminal.type("A136 0\r"), "BA 2 0\r") << "numbers are not mnemonics";
  EXPECT_EQ(terminal.type("AGAP 241\r"), "BA 4 0\r") << "missing operand";
  EXPECT_EQ(terminal.type("AGAP 241, 0, 0\r"), "BA 4 0\r") << "surplus operand";
  EXPECT_EQ(terminal.type("AGAP 241,, 0\r"), "BA 4 0\r") << "empty operand";
  EXPECT_EQ(terminal.type("AGAP x4, 0\r"), "BA 4 0\r") << "not a number";
  EXPECT_EQ(terminal.type("AGAP 256, 0\r"), "BA 4 0\r") << "type byte out of range";
  EXPECT_EQ(terminal.type("ASAP 241, 0, 99999999999\r"), "BA 4 0\r") << "value beyond 32 bits";
  EXPECT_EQ(terminal.type("AMVP SIDEWAYS, 0, 5\r"), "BA 4 0\r") << "unknown symbol";
  EXPECT_EQ(terminal.type("AGAP 241, 7\r"), "BA 4 0\r") << "motor out of range: the engine's status 4";
  EXPECT_EQ(terminal.type("AGAP 254, 0\r"), "BA 3 0\r") << "unknown parameter: the engine's status 3";
  EXPECT_EQ(terminal.type("AJA 5\r"), "BA 6 5\r") << "program flow in direct mode";
  EXPECT_EQ(terminal.type("ABIN 1\r"), "BA 4 0\r");
  EXPECT_FALSE(terminal.left_ascii_mode);
}

TEST(AsciiLink, mnemonics_symbols_and_numbers_as_in_tmcl_ide) {
  Tmcm1636Rig rig;
  set_echo_mode(rig, 0x20);
  Terminal terminal{rig};
  EXPECT_EQ(terminal.type("amvp abs 0 0x10\r"), "BA 100 16\r");
  EXPECT_EQ(rig.gap(50), 16);
  EXPECT_EQ(terminal.type("A\tMVP REL,0,-6\r\n"), "BA 100 -6\r") << "tab, no blanks after commas, CR LF";
  EXPECT_EQ(rig.gap(50), -6);
  EXPECT_EQ(terminal.type("ACALC LOAD, 41\rACALC ADD, 1\rAAGP 7, 2\rAGGP 7, 2\n"),
            "BA 100 41\rBA 100 1\rBA 100 0\rBA 100 42\r")
      << "LF alone ends a line too";
}

TEST(AsciiLink, an_over_long_line_is_answered_with_status_2_and_the_next_line_works) {
  Tmcm1636Rig rig;
  Terminal terminal{rig};
  const std::string long_line = "A" + std::string(1000, 'X');
  const std::string out = terminal.type(long_line + "\r");
  // Echo stops at the buffer (80 characters after the letter), then the error reply.
  EXPECT_EQ(out, "A" + std::string(AsciiLink::kMaxLineLength, 'X') + "\rBA 2 0\r");
  EXPECT_EQ(terminal.type("AGAP 241, 0\r"), "AGAP 241, 0\rBA 100 0\r");
  // A line exactly at the limit is still read.
  const std::string padded = "GAP 241, 0" + std::string(AsciiLink::kMaxLineLength - 10, ' ');
  set_echo_mode(rig, 0x20);
  EXPECT_EQ(terminal.type("A" + padded + "\r"), "BA 100 0\r");
  // Backspacing after an overflow does not rescue the line: characters were lost.
  EXPECT_EQ(terminal.type("A" + padded + "X\b\r"), "BA 2 0\r");
}

TEST(AsciiLink, garbage_is_ignored_or_answered_and_never_blocks_the_next_line) {
  Tmcm1636Rig rig;
  Terminal terminal{rig};
  // A line that does not start with our address letter is not ours: no echo, no reply.
  EXPECT_EQ(terminal.type("\xff\xfe\x01 junk \x80\r"), "");
  EXPECT_EQ(terminal.type("BGAP 241, 0\r"), "") << "module B's line on a shared bus";
  EXPECT_EQ(terminal.type("9GAP 241, 0\r"), "");
  // Ours, with control or 8-bit bytes in it: answered with status 2 at CR (the bytes not echoed).
  EXPECT_EQ(terminal.type("AGAP\x01\xff 4, 0\r"), "AGAP 4, 0\rBA 2 0\r");
  EXPECT_EQ(terminal.type("\x1b[AAGAP 241, 0\r"), "") << "an escape sequence starts a foreign line";
  EXPECT_EQ(terminal.type("\r\n\n  \0AGAP 241, 0\r"s), "AGAP 241, 0\rBA 100 0\r");
  EXPECT_EQ(terminal.lines, 2);
}

TEST(AsciiLink, the_address_letter_follows_gp66_and_gp76) {
  Tmcm1636Rig rig;
  Terminal terminal{rig};
  set_echo_mode(rig, 0x20);
  ASSERT_EQ(rig.command(cmd::kSgp, 76, 0, 4).status, 100);  // host address 4: letter D
  EXPECT_EQ(terminal.type("AGAP 241, 0\r"), "DA 100 0\r");
  // SGP 66 from the terminal: the reply already comes from C, and A is not us any more.
  EXPECT_EQ(terminal.type("ASGP 66, 0, 3\r"), "DC 100 3\r");
  EXPECT_EQ(terminal.type("AGAP 241, 0\r"), "");
  EXPECT_EQ(terminal.type("cGAP 241, 0\r"), "DC 100 0\r") << "letters are case-insensitive";
}

TEST(AsciiLink, bin_leaves_ascii_mode_after_its_reply) {
  Tmcm1636Rig rig;
  Terminal terminal{rig};
  EXPECT_EQ(terminal.type("ABIN\r"), "ABIN\rBA 100 0\r");
  EXPECT_TRUE(terminal.left_ascii_mode);
  EXPECT_EQ(tmcl::parse_ascii_command("bin", 3).kind, AsciiCommand::Kind::kBinary);
}

TEST(AsciiLink, command_139_answers_first_in_binary_and_asks_the_link_to_switch) {
  Tmcm1636Rig rig;
  const tmcl::SerialResponse response = rig.send(tmcl::encode_request(1, tmcl::Instruction{cmd::kEnterAsciiMode, 0, 0, 0}));
  ASSERT_EQ(response.length, 9u);
  EXPECT_EQ(response.bytes[2], 100);
  EXPECT_EQ(response.bytes[3], cmd::kEnterAsciiMode);
  EXPECT_TRUE(response.enter_ascii_mode);
  // Other commands never switch the link.
  EXPECT_FALSE(rig.send(tmcl::encode_request(1, tmcl::Instruction{cmd::kGap, 4, 0, 0})).enter_ascii_mode);
}

TEST(AsciiLink, run_and_stop_start_and_stop_the_stored_program) {
  Tmcm1636Rig rig;
  // 0: CALC ADD 1; 1: AGP 0, 2; 2: JA 0 -- counts in user variable 0 while it runs.
  ASSERT_EQ(rig.command(cmd::kEnterDownloadMode, 0, 0, 0).status, 100);
  ASSERT_EQ(rig.command(cmd::kCalc, 0, 0, 1).status, 101);
  ASSERT_EQ(rig.command(cmd::kAgp, 0, 2, 0).status, 101);
  ASSERT_EQ(rig.command(cmd::kJa, 0, 0, 0).status, 101);
  ASSERT_EQ(rig.command(cmd::kExitDownloadMode, 0, 0, 0).status, 100);
  rig.run_ms(1);
  Terminal terminal{rig};
  set_echo_mode(rig, 0x20);
  EXPECT_EQ(terminal.type("ARUN\r"), "BA 100 0\r");
  EXPECT_EQ(rig.command(cmd::kGgp, 128, 0, 0).value, 1) << "running";
  rig.run_ms(1);
  EXPECT_EQ(terminal.type("ASTOP\r"), "BA 100 0\r");
  EXPECT_EQ(rig.command(cmd::kGgp, 128, 0, 0).value, 0) << "stopped";
  const int32_t count = rig.command(cmd::kGgp, 0, 2, 0).value;
  EXPECT_GT(count, 0);
  rig.run_ms(1);
  EXPECT_EQ(rig.command(cmd::kGgp, 0, 2, 0).value, count) << "nothing runs after STOP";
  // RUN with an address starts there; beyond program memory: status 4.
  EXPECT_EQ(terminal.type("ARUN 2\r"), "BA 100 2\r");
  EXPECT_EQ(rig.command(cmd::kGgp, 130, 0, 0).value, 2);
  EXPECT_EQ(terminal.type("ARUN 2048\r"), "BA 4 2048\r");
  EXPECT_EQ(terminal.type("ARUN 1 2\r"), "BA 4 0\r");
}

TEST(AsciiLink, settings_come_from_gp67) {
  Tmcm1636Rig rig;
  tmcl::AsciiSettings settings = tmcl::ascii_settings(rig.module);
  EXPECT_TRUE(settings.available);
  EXPECT_FALSE(settings.start_in_ascii_mode);
  EXPECT_EQ(settings.echo, tmcl::AsciiEcho::kEachCharacter);
  set_echo_mode(rig, 0x11);
  settings = tmcl::ascii_settings(rig.module);
  EXPECT_TRUE(settings.start_in_ascii_mode);
  EXPECT_EQ(settings.echo, tmcl::AsciiEcho::kWholeLine);
  EXPECT_EQ(tmcl::ascii_address_letter(1), 'A');
  EXPECT_EQ(tmcl::ascii_address_letter(26), 'Z');
  EXPECT_EQ(tmcl::ascii_address_letter(27), '\0');
}

}  // namespace
}  // namespace motwin::testing

#include "tools/tmcl_mnemonics.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "core/tmcl/serial_link.h"
#include "tools/tmcl_client.h"

namespace motwin::tools {
namespace {

constexpr uint8_t kModuleAddress = 1;

std::string encoded_frame(std::string_view text) {
  const Result<tmcl::Instruction> instruction = parse_instruction(text);
  if (!instruction) return "error: " + instruction.error();
  const tmcl::Frame frame = tmcl::encode_request(kModuleAddress, instruction.value());
  return hex_bytes(frame.data(), frame.size());
}

std::string parse_error(std::string_view text) {
  const Result<tmcl::Instruction> instruction = parse_instruction(text);
  return instruction ? "no error" : instruction.error();
}

struct ManualFrame {
  const char* text;
  const char* frame;
};

// The "Binary Form" examples of the TMCM-1636 manual chapter 2 (RSAP with its checksum
// corrected, docs/decisions.md "Errata in the manuals"; STAP as its binary form shows it), and
// docs/tmcl-protocol.md "Test vectors".
constexpr ManualFrame kManualFrames[] = {
    {"ROR 0, 51200", "01 01 00 00 00 00 C8 00 CA"},
    {"ROR 0, 350", "01 01 00 00 00 00 01 5E 61"},
    {"ROL 0, 51200", "01 02 00 00 00 00 C8 00 CB"},
    {"MST 0", "01 03 00 00 00 00 00 00 04"},
    {"MVP ABS, 0, 90000", "01 04 00 00 00 01 5F 90 F5"},
    {"MVP REL, 0, -10000", "01 04 01 00 FF FF D8 F0 CC"},
    {"SAP 4, 0, 51200", "01 05 04 00 00 00 C8 00 D2"},
    {"GAP 1, 0", "01 06 01 00 00 00 00 00 08"},
    {"STAP 6, 0", "01 07 06 00 00 00 00 00 0E"},
    {"RSAP 6, 0", "01 08 06 00 00 00 00 00 0F"},
    {"SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F"},
    {"GGP 66, 0", "01 0A 42 00 00 00 00 00 4D"},
    {"STGP 42, 2", "01 0B 2A 02 00 00 00 00 38"},
    {"RSGP 42, 2", "01 0C 2A 02 00 00 00 00 39"},
    {"RFS START, 0", "01 0D 00 00 00 00 00 00 0E"},
    {"SIO 0, 2, 1", "01 0E 00 02 00 00 00 01 12"},
    {"GIO 0, 1", "01 0F 00 01 00 00 00 00 11"},
    {"CALC MUL, -5000", "01 13 02 00 FF FF EC 78 78"},
    {"COMP 1000", "01 14 00 00 00 00 03 E8 00"},
    {"JC GE, 10", "01 15 05 00 00 00 00 0A 25"},
    {"JA 10", "01 16 00 00 00 00 00 0A 21"},
    {"CSUB 100", "01 17 00 00 00 00 00 64 7C"},
    {"RSUB", "01 18 00 00 00 00 00 00 19"},
    {"WAIT POS, 0, 0", "01 1B 01 00 00 00 00 00 1D"},
    {"STOP", "01 1C 00 00 00 00 00 00 1D"},
    {"CALCX MUL", "01 21 02 00 00 00 00 00 24"},
    {"AAP 0, 0", "01 22 00 00 00 00 00 00 23"},
    {"AGP 42, 2", "01 23 2A 02 00 00 00 00 50"},
    {"CLE ETO", "01 24 01 00 00 00 00 00 26"},
};

TEST(TmclMnemonics, encodes_every_binary_form_example_of_the_manual) {
  for (const ManualFrame& example : kManualFrames) {
    EXPECT_EQ(encoded_frame(example.text), example.frame) << example.text;
  }
}

TEST(TmclMnemonics, commas_are_optional_and_mnemonics_and_symbols_case_insensitive) {
  const std::string expected = "01 04 00 00 00 01 5F 90 F5";
  EXPECT_EQ(encoded_frame("MVP ABS 0 90000"), expected);
  EXPECT_EQ(encoded_frame("mvp abs, 0,90000"), expected);
  EXPECT_EQ(encoded_frame("  Mvp\tAbs ,0 , 90000  "), expected);
  EXPECT_EQ(encoded_frame("MVP ABS, 0, 90000 // move out"), expected);
  EXPECT_EQ(encoded_frame("GAP 52 0"), "01 06 34 00 00 00 00 00 3B");
}

TEST(TmclMnemonics, reads_hexadecimal_and_negative_numbers) {
  const Result<tmcl::Instruction> hex = parse_instruction("SAP 0x2B, 0, 0x1F40");
  ASSERT_TRUE(hex) << hex.error();
  EXPECT_EQ(hex->type, 43);
  EXPECT_EQ(hex->value, 8000);
  const Result<tmcl::Instruction> negative_hex = parse_instruction("ROL 0 -0x10");
  ASSERT_TRUE(negative_hex) << negative_hex.error();
  EXPECT_EQ(negative_hex->value, -16);
  // Unsigned 32-bit values (GP 132's range reaches 4294967295) travel as their bit pattern.
  const Result<tmcl::Instruction> unsigned_value = parse_instruction("SGP 132, 0, 4294967295");
  ASSERT_TRUE(unsigned_value) << unsigned_value.error();
  EXPECT_EQ(unsigned_value->value, -1);
  EXPECT_EQ(encoded_frame("SGP 132 0 -2147483648"), "01 09 84 00 80 00 00 00 0E");
}

TEST(TmclMnemonics, numeric_form_encodes_control_commands) {
  EXPECT_EQ(encoded_frame("136 1"), "01 88 01 00 00 00 00 00 8A");
  EXPECT_EQ(encoded_frame("136"), "01 88 00 00 00 00 00 00 89");
  EXPECT_EQ(encoded_frame("255 0 0 1234"), "01 FF 00 00 00 00 04 D2 D6");
  EXPECT_EQ(encoded_frame("129, 1, 0, 0x10"), "01 81 01 00 00 00 00 10 93");
  // Commands that have a mnemonic may be written numerically too.
  EXPECT_EQ(encoded_frame("6 52 0"), encoded_frame("GAP 52, 0"));
}

TEST(TmclMnemonics, symbolic_operands_follow_the_code_tables) {
  struct Case {
    const char* text;
    uint8_t command;
    uint8_t type;
  };
  const Case cases[] = {
      {"MVP COORD, 0, 3", 4, 2},  {"CALC ADD, 1", 19, 0},   {"CALC LOAD, 1", 19, 9},  {"CALCX SWAP", 33, 10},
      {"CALCX LOAD", 33, 9},      {"JC ZE, 0", 21, 0},      {"JC LE, 0", 21, 7},      {"JC ESD, 0", 21, 12},
      {"WAIT TICKS, 0, 50", 27, 0}, {"WAIT RFS, 0, 0", 27, 4}, {"CLE ALL", 36, 0},     {"CLE ESD", 36, 5},
      {"RFS STOP, 0", 13, 1},     {"RFS STATUS, 0", 13, 2}, {"EI 255", 25, 255},      {"DI 0", 26, 0},
      {"VECT 2, 30", 37, 2},      {"RETI", 38, 0},          {"SCO 1, 0, 5000", 30, 1}, {"GCO 1, 0", 31, 1},
      {"CCO 1, 0", 32, 1},        {"ACO 1, 0", 39, 1},
  };
  for (const Case& c : cases) {
    const Result<tmcl::Instruction> instruction = parse_instruction(c.text);
    ASSERT_TRUE(instruction) << c.text << ": " << instruction.error();
    EXPECT_EQ(instruction->command, c.command) << c.text;
    EXPECT_EQ(instruction->type, c.type) << c.text;
  }
  const Result<tmcl::Instruction> coordinate = parse_instruction("SCO 1, 0, 5000");
  ASSERT_TRUE(coordinate);
  EXPECT_EQ(coordinate->value, 5000);
  const Result<tmcl::Instruction> vector = parse_instruction("VECT 2, 30");
  ASSERT_TRUE(vector);
  EXPECT_EQ(vector->value, 30);
  // A number is accepted where a symbol is expected.
  EXPECT_EQ(encoded_frame("MVP 1, 0, -10000"), encoded_frame("MVP REL, 0, -10000"));
}

TEST(TmclMnemonics, errors_say_what_was_expected) {
  EXPECT_EQ(parse_error("FOO 1 2"),
            "unknown mnemonic 'FOO': expected a TMCL mnemonic (such as MVP, SAP, GAP) or a command number");
  EXPECT_EQ(parse_error("MVP ABS, 0"), "MVP takes 3 operands (ABS|REL|COORD, motor, value), got 2");
  EXPECT_EQ(parse_error("GAP 52"), "GAP takes 2 operands (param, motor), got 1");
  EXPECT_EQ(parse_error("MST"), "MST takes 1 operand (motor), got 0");
  EXPECT_EQ(parse_error("RSUB 1"), "RSUB takes no operands, got 1");
  EXPECT_EQ(parse_error("GAP 256, 0"),
            "GAP operand 1 (param): 256 is out of range for the byte field type (0..255)");
  EXPECT_EQ(parse_error("SAP 4, -1, 0"),
            "SAP operand 2 (motor): -1 is out of range for the byte field motor/bank (0..255)");
  EXPECT_EQ(parse_error("ROR 0, 4294967296"),
            "ROR operand 2 (velocity): 4294967296 is out of range for the 32-bit value field "
            "(-2147483648..4294967295)");
  EXPECT_EQ(parse_error("MVP ABX, 0, 1"),
            "MVP operand 1 (ABS|REL|COORD): unknown symbol 'ABX', expected ABS, REL, COORD or a number");
  EXPECT_EQ(parse_error("JA Loop"), "JA operand 1 (address): unknown symbol 'Loop', expected a number");
  EXPECT_EQ(parse_error("GAP 5x, 0"),
            "GAP operand 1 (param): '5x' is not a number (decimal or 0x hexadecimal, at most 64 bits)");
  EXPECT_EQ(parse_error(""), "empty instruction: expected a mnemonic (such as MVP, SAP, GAP) or a command number");
  EXPECT_EQ(parse_error("GAP 52,,0"), "empty operand after '52'");
  EXPECT_EQ(parse_error("GAP 52, 0,"), "empty operand after '0'");
  EXPECT_EQ(parse_error("256 0"), "command number 256 is out of range (0..255)");
  EXPECT_EQ(parse_error("136 0 0 0 0"), "the numeric form takes at most 4 numbers (CMD TYPE MOTOR VALUE), got 5");
  EXPECT_EQ(parse_error("136 300"), "type: 300 is out of range for the byte field type (0..255)");
}

TEST(TmclMnemonics, identifiers_resolve_through_the_callers_resolver) {
  ParseOptions options;
  options.resolve_identifier = [](std::string_view name) -> std::optional<int64_t> {
    if (name == "Loop") return 17;
    return std::nullopt;
  };
  const Result<tmcl::Instruction> jump = parse_instruction("JC GE, Loop", options);
  ASSERT_TRUE(jump) << jump.error();
  EXPECT_EQ(jump->type, 5);
  EXPECT_EQ(jump->value, 17);
  EXPECT_FALSE(parse_instruction("JA Elsewhere", options));
}

TEST(TmclMnemonics, table_is_sorted_and_has_unique_mnemonics) {
  std::set<std::string_view> mnemonics;
  int previous_command = -1;
  for (const MnemonicSpec& spec : mnemonic_table()) {
    EXPECT_TRUE(mnemonics.insert(spec.mnemonic).second) << spec.mnemonic;
    EXPECT_GT(spec.command, previous_command) << spec.mnemonic;
    previous_command = spec.command;
    EXPECT_EQ(find_mnemonic(spec.mnemonic), &spec);
    EXPECT_EQ(find_command(spec.command), &spec);
  }
  EXPECT_EQ(mnemonics.size(), 35u);
}

TEST(TmclMnemonics, format_instruction_round_trips_through_the_parser) {
  for (const ManualFrame& example : kManualFrames) {
    const Result<tmcl::Instruction> parsed = parse_instruction(example.text);
    ASSERT_TRUE(parsed) << example.text;
    const std::string text = format_instruction(parsed.value());
    EXPECT_EQ(encoded_frame(text), example.frame) << example.text << " -> " << text;
  }
  EXPECT_EQ(format_instruction({4, 1, 0, -10000}), "MVP REL, 0, -10000");
  EXPECT_EQ(format_instruction({27, 0, 0, 50}), "WAIT TICKS, 0, 50");
  EXPECT_EQ(format_instruction({136, 1, 0, 0}), "136 1 0 0");
  // A field the mnemonic cannot show (MST has no value operand) forces the numeric form.
  EXPECT_EQ(format_instruction({3, 0, 0, 5}), "3 0 0 5");
}

TEST(TmclMnemonics, parse_integer_accepts_only_whole_numbers) {
  EXPECT_EQ(parse_integer("0"), 0);
  EXPECT_EQ(parse_integer("-5000"), -5000);
  EXPECT_EQ(parse_integer("+7"), 7);
  EXPECT_EQ(parse_integer("0xFFFFFFFF"), 4294967295);
  EXPECT_EQ(parse_integer("0X1f"), 31);
  EXPECT_FALSE(parse_integer(""));
  EXPECT_FALSE(parse_integer("-"));
  EXPECT_FALSE(parse_integer("0x"));
  EXPECT_FALSE(parse_integer("12 "));
  EXPECT_FALSE(parse_integer("1.5"));
  EXPECT_FALSE(parse_integer("99999999999999999999"));
}

}  // namespace
}  // namespace motwin::tools

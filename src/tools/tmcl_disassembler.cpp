#include "tools/tmcl_disassembler.h"

#include <set>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "tools/tmcl_binary.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::tools {
namespace {

// Commands whose value is a program address.
bool has_address_operand(uint8_t command) {
  return command == tmcl::command::kJa || command == tmcl::command::kJc || command == tmcl::command::kCsub ||
         command == tmcl::command::kVect;
}

// Whether format_instruction writes the mnemonic form (the numeric form shows no labels).
bool has_mnemonic_form(const tmcl::Instruction& instruction) {
  const MnemonicSpec* spec = find_command(instruction.command);
  return spec != nullptr && std::string_view(format_instruction(instruction)).starts_with(spec->mnemonic);
}

std::string label_name(int64_t address) { return fmt::format("L{}", address); }

// format_instruction's text with the trailing address replaced by its label, when the
// instruction is in mnemonic form (the numeric form of odd fields keeps its number).
std::string with_label(const tmcl::Instruction& instruction, const std::string& text) {
  const MnemonicSpec* spec = find_command(instruction.command);
  const std::string number = std::to_string(instruction.value);
  if (spec == nullptr || !std::string_view(text).starts_with(spec->mnemonic) || text.size() <= number.size() ||
      !std::string_view(text).ends_with(number)) {
    return text;
  }
  const char before = text[text.size() - number.size() - 1];
  if (before != ' ' && before != ',') return text;
  return text.substr(0, text.size() - number.size()) + label_name(instruction.value);
}

}  // namespace

std::vector<DisassembledLine> disassemble_lines(std::span<const tmcl::Instruction> instructions) {
  // Targets inside the program get labels.
  std::set<int64_t> targets;
  for (const tmcl::Instruction& instruction : instructions) {
    if (has_address_operand(instruction.command) && instruction.value >= 0 &&
        static_cast<size_t>(instruction.value) < instructions.size() && has_mnemonic_form(instruction)) {
      targets.insert(instruction.value);
    }
  }
  std::vector<DisassembledLine> lines;
  lines.reserve(instructions.size());
  for (size_t address = 0; address < instructions.size(); ++address) {
    const tmcl::Instruction& instruction = instructions[address];
    DisassembledLine line;
    line.address = static_cast<uint32_t>(address);
    if (targets.contains(static_cast<int64_t>(address))) line.label = label_name(static_cast<int64_t>(address));
    line.text = format_instruction(instruction);
    if (has_address_operand(instruction.command) && targets.contains(instruction.value) &&
        has_mnemonic_form(instruction)) {
      line.text = with_label(instruction, line.text);
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

std::string disassemble(std::span<const tmcl::Instruction> instructions, const DisassemblyOptions& options) {
  const bool final_stop_omitted =
      options.omit_final_stop && !instructions.empty() && instructions.back().command == tmcl::command::kStop &&
      instructions.back().type == 0 && instructions.back().motor_bank == 0 && instructions.back().value == 0;
  const std::vector<DisassembledLine> lines = disassemble_lines(instructions);
  const size_t written = lines.size() - (final_stop_omitted ? 1 : 0);

  std::string out = fmt::format("// {} instruction{}, disassembled by motwin\n", instructions.size(),
                                instructions.size() == 1 ? "" : "s");
  for (size_t address = 0; address < written; ++address) {
    const DisassembledLine& line = lines[address];
    if (!line.label.empty()) out += line.label + ":\n";
    out += options.address_comments ? fmt::format("    {:<32} // {}\n", line.text, address)
                                    : fmt::format("    {}\n", line.text);
  }
  if (final_stop_omitted) {
    if (!lines.back().label.empty()) out += lines.back().label + ":\n";
    out += fmt::format("// STOP at address {}: appended by the assembler\n", written);
  }
  return out;
}

Result<std::string> disassemble_binary(std::span<const uint8_t> bytes, const DisassemblyOptions& options) {
  Result<std::vector<tmcl::Instruction>> instructions = decode_program_binary(bytes);
  if (!instructions) return Error{instructions.error()};
  return disassemble(instructions.value(), options);
}

}  // namespace motwin::tools

// The disassembler: instructions (from a .bin file or read back from a module) to TMCL-IDE
// source that `motwin asm` turns back into the same bytes. Jump, call and interrupt-vector
// targets (JA, JC, CSUB, VECT) inside the program get labels "L<address>:".
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/tmcl/instruction.h"
#include "types/result.h"

namespace motwin::tools {

struct DisassemblyOptions {
  // A program that ends with STOP most likely got it from the assembler, which appends one:
  // write it as a comment so that assembling the output gives the same instructions.
  bool omit_final_stop = true;
  // "// 12" after each instruction: its address.
  bool address_comments = true;
};

// One instruction of a disassembly, for a view with one line per address (the web console's
// Program view): the same text and labels as disassemble() writes.
struct DisassembledLine {
  uint32_t address = 0;
  std::string label;  // "L12" when a jump, call or vector of the program targets this address
  std::string text;   // the instruction; an address operand inside the program as its label
};
// Every instruction, a final STOP included.
std::vector<DisassembledLine> disassemble_lines(std::span<const tmcl::Instruction> instructions);

std::string disassemble(std::span<const tmcl::Instruction> instructions, const DisassemblyOptions& options = {});
// The bytes of a .bin file (tmcl_binary.h); fails as decode_program_binary does.
Result<std::string> disassemble_binary(std::span<const uint8_t> bytes, const DisassemblyOptions& options = {});

}  // namespace motwin::tools

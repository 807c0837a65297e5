// Moving a TMCL program between a host and a module's program memory over a TmclClient.
//
// Download, as the TMCL-IDE does it (docs/tmcl-protocol.md "Control commands"): 132 with the start
// address (reply 100), each instruction in turn (reply 101, "stored"), a trailing NOP (command
// 0, reply 101), then 133 (reply 100).
//
// Read back with 134 (the manual calls its reply "special" without documenting it; Motwin
// decided, docs/assembler.md): for the address in the value field,
//   134 type 0 -> reply command byte = the stored opcode, reply value = the stored value;
//   134 type 1 -> reply value = (stored type << 8) | stored motor/bank.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/tmcl/instruction.h"
#include "tools/tmcl_client.h"
#include "types/result.h"

namespace motwin::tools {

// The requests of a transfer, for hosts that do not block on a TmclClient (the web console,
// src/tools/web/web_program.cpp): the same requests and checks as the functions below.

// One request of a download and the status its reply must carry; `what` names it in errors.
struct TransferStep {
  tmcl::Instruction request;
  uint8_t expected_status = 100;
  std::string what;
};

// 132 with `start`, each instruction (101), the trailing NOP (101), 133 (100).
std::vector<TransferStep> download_steps(std::span<const tmcl::Instruction> instructions, uint32_t start);
// Leaves download mode after a refused step (its reply must carry status 100).
tmcl::Instruction leave_download_request();

// The two 134 requests that read the instruction at `address`: type 0, then type 1.
tmcl::Instruction read_back_request(uint32_t address, uint8_t type);
// The instruction from the replies to both (status 100 each): type 0 gives the opcode (reply
// command byte) and the value, type 1 the value (type << 8) | motor.
Result<tmcl::Instruction> decode_read_back(uint32_t address, uint8_t opcode, int32_t value, int32_t type_and_motor);

// Reads `count` instructions from address `start` on (2 requests per instruction).
Result<std::vector<tmcl::Instruction>> read_program(TmclClient& client, uint32_t start, uint32_t count,
                                                    uint8_t module_address = kDefaultModuleAddress);

// Reads from `start` until the first instruction with command 0 (the NOP that ends every
// download, and what empty memory holds), for at most `max_count` instructions; the NOP is
// not included. An "invalid value" status (4) after the first address also ends the read: the
// address is past the end of the module's program memory.
Result<std::vector<tmcl::Instruction>> read_stored_program(TmclClient& client, uint32_t start, uint32_t max_count,
                                                           uint8_t module_address = kDefaultModuleAddress);

// Downloads `instructions` to addresses `start`... Returns the number of instructions stored.
// When the module refuses an instruction, 133 is still sent (best effort) so that the module
// does not stay in download mode; the error says so, as program memory may then hold part of
// the new program.
Result<size_t> download_program(TmclClient& client, std::span<const tmcl::Instruction> instructions, uint32_t start = 0,
                                uint8_t module_address = kDefaultModuleAddress);

}  // namespace motwin::tools

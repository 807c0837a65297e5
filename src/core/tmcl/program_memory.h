// TMCL program memory: instructions in the EEPROM image, 8 bytes each (command, type, motor,
// value big-endian, checksum of those 7 bytes: the TMCL-IDE .bin format), with a RAM mirror
// that the interpreter executes from and that a download fills. A download becomes permanent
// in one EEPROM write when the host leaves download mode (command 133), so an interrupted
// download never leaves half a program in the image.
#pragma once

#include <cstddef>
#include <cstdint>

#include "board/non_volatile_memory.h"
#include "core/tmcl/instruction.h"

namespace motwin::tmcl {

inline constexpr size_t kProgramRecordBytes = 8;

void encode_program_record(const Instruction& instruction, uint8_t* out);
// False when the record's checksum does not match.
bool decode_program_record(const uint8_t* in, Instruction& instruction);

class ProgramMemory {
 public:
  // `mirror` must hold capacity * 8 bytes and live as long as this object.
  ProgramMemory(board::NonVolatileMemory& nvm, uint32_t nvm_offset, uint32_t capacity, uint8_t* mirror)
      : nvm_(nvm), nvm_offset_(nvm_offset), capacity_(capacity), mirror_(mirror) {}

  uint32_t capacity() const { return capacity_; }

  // Copies the stored program into RAM (power-up); a pending download is dropped.
  void load();
  // Reads from RAM. False: address outside memory or a damaged record.
  bool read(uint32_t address, Instruction& instruction) const;

  // Download (commands 132/133): stores into RAM and remembers what changed.
  bool stage(uint32_t address, const Instruction& instruction);
  // Writes the changed range to the EEPROM image. False when the image could not be written
  // (the RAM copy is then reloaded from the image: nothing half-stored is executed).
  bool commit();
  bool has_staged_changes() const { return dirty_begin_ < dirty_end_; }

 private:
  board::NonVolatileMemory& nvm_;
  uint32_t nvm_offset_;
  uint32_t capacity_;
  uint8_t* mirror_;
  uint32_t dirty_begin_ = UINT32_MAX;
  uint32_t dirty_end_ = 0;
};

}  // namespace motwin::tmcl

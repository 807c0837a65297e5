// Process data objects (CiA-301 7.2.2), in the shape of CANopenNode's CO_PDO: receive PDOs write
// every mapped object through the object dictionary, transmit PDOs read them. The communication
// and mapping parameters (1400.., 1600.., 1800.., 1A00..) are the module's data, written by SDO
// with the checks of its object table; this service only reads them, every time it uses them, so
// a reconfiguration applies at once. Each mapping is resolved to its objects (ObjectRef) once and
// the references kept with a copy of the entries they came from; a use that finds the module's
// mapping different from that copy resolves it again (docs/canopen.md, "How mappings are
// resolved"); the per-frame work is then a compare and the object accesses themselves.
//
// Receive PDO (valid COB-ID, frame with that identifier, NMT operational):
//   transmission type 254/255   the mapped objects are written at once
//   1..240 (synchronous)        the data is kept and written at the next SYNC (the latest wins)
//   shorter than the mapping    nothing is written; the caller sends EMCY 8210
//   longer than the mapping     the mapped bytes are written; the caller sends EMCY 8220
// Transmit PDO:
//   254/255   sent when a mapped value changed, when the event timer (ms) expires and once on
//             entering operational; never two closer together than the inhibit time (100 µs)
//   1..240    sent at every n-th SYNC (the count starts at entering operational)
// Mapping entries name `index << 16 | sub << 8 | bits`; dummy entries (index 0002..0007, sub 0)
// are skipped by RPDOs and sent as zeros by TPDOs (as CANopenNode). A PDO whose mapping names an
// object the dictionary does not have or cannot read (TPDO) or write (RPDO) is inactive: never
// sent, its frames ignored, until its mapping changes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "board/can_controller.h"
#include "core/canopen/object_dictionary.h"
#include "core/canopen/sdo_abort.h"
#include "types/can_frame.h"

namespace motwin::canopen {

inline constexpr uint8_t kMaxPdoMappedObjects = 8;  // byte-granular mapping: at most 8 objects
inline constexpr uint32_t kPdoCobIdInvalid = 0x8000'0000;
inline constexpr uint32_t kPdoCobIdNoRtr = 0x4000'0000;
inline constexpr uint8_t kPdoEventDrivenManufacturer = 0xFE;
inline constexpr uint8_t kPdoEventDrivenProfile = 0xFF;
inline constexpr uint8_t kPdoMaxSynchronousType = 240;

// EMCY codes of the PDO service (CiA-301 table 21).
inline constexpr uint16_t kEmcyPdoLength = 0x8210;          // PDO not processed: too short
inline constexpr uint16_t kEmcyPdoLengthExceeded = 0x8220;  // PDO longer than its mapping

struct PdoCommunication {
  uint32_t cob_id;               // sub 1: bit 31 = not valid, bit 30 = no RTR
  uint8_t transmission_type;     // sub 2: 1..240 synchronous, 254/255 event driven
  uint16_t inhibit_time_100us;   // sub 3 (TPDO)
  uint16_t event_timer_ms;       // sub 5 (TPDO)
};

struct PdoMapping {
  uint8_t count;                                 // sub 0
  uint32_t entries[kMaxPdoMappedObjects];        // index << 16 | sub << 8 | bits
};

constexpr bool pdo_valid(const PdoCommunication& pdo) { return (pdo.cob_id & kPdoCobIdInvalid) == 0; }
constexpr bool pdo_synchronous(const PdoCommunication& pdo) {
  return pdo.transmission_type >= 1 && pdo.transmission_type <= kPdoMaxSynchronousType;
}
constexpr bool is_dummy_mapping(uint32_t entry) {
  const uint16_t index = static_cast<uint16_t>(entry >> 16);
  return index >= 0x0002 && index <= 0x0007 && ((entry >> 8) & 0xFF) == 0;
}

// The checks of SDO writes to the PDO parameters (CiA-301 7.5.2.35..38, the rules the
// TMCM-3216 manual relies on); communication_objects.h binds them to the rows.
// A COB-ID: 11-bit only, no restricted ID, and its ID does not change while it is valid (set bit
// 31 first, as python-canopen does). Bit 30 (RTR) is accepted either way: RTR is never answered.
SdoAbort check_pdo_cob_id(uint32_t current, int64_t value);
// FF or FE (event driven) or 1..240 (synchronous); other values are not supported.
SdoAbort check_pdo_transmission_type(int64_t value);
// Inhibit time: not changeable while the PDO is valid.
SdoAbort check_pdo_inhibit_time(const PdoCommunication& pdo);
// A mapping entry `index << 16 | sub << 8 | bits`: the object exists, may be mapped in this
// direction, and its size is `bits`; the dummy types 0002..0007 (sub 0) where `dummies_allowed`.
SdoAbort check_pdo_mapping_entry(ObjectDictionary& dictionary, bool receive, uint32_t entry,
                                 bool dummies_allowed = true);
// Sub 0 of a mapping: only while the PDO is not valid; entries 1..count must be valid and fit in
// 8 bytes.
SdoAbort check_pdo_mapping_count(ObjectDictionary& dictionary, bool receive, const PdoCommunication& pdo,
                                 const PdoMapping& mapping, int64_t count, bool dummies_allowed = true);
// An entry: only while the PDO is not valid and sub 0 is 0.
SdoAbort check_pdo_mapping_write(ObjectDictionary& dictionary, bool receive, const PdoCommunication& pdo,
                                 const PdoMapping& mapping, int64_t value, bool dummies_allowed = true);

// What a received frame meant to the RPDOs.
enum class RpdoReception : uint8_t {
  kNotPdo,     // no valid RPDO has this identifier (or not operational)
  kAccepted,   // written (or kept for the next SYNC)
  kTooShort,   // EMCY 8210
  kTooLong,    // EMCY 8220; the mapped bytes were used
};

class PdoService {
 public:
  static constexpr size_t kMaxPdos = 16;  // per direction

  // The parameter arrays belong to the module and outlive the service; at most kMaxPdos each.
  PdoService(ObjectDictionary& dictionary, board::CanController& can, std::span<const PdoCommunication> rpdo,
             std::span<const PdoMapping> rpdo_mapping, std::span<const PdoCommunication> tpdo,
             std::span<const PdoMapping> tpdo_mapping);

  // Back to the state after a reset: nothing pending, timers stopped, mappings resolved afresh.
  void reset();
  // Entering NMT operational: every active event-driven TPDO is due, the SYNC counts start over.
  void enter_operational();

  // A frame while operational.
  RpdoReception on_frame(const can::CanFrame& frame);
  // A SYNC (received or produced) while operational: synchronous RPDOs are written first, then
  // the synchronous TPDOs whose count is reached are sampled and sent.
  void on_sync();
  // Event-driven TPDOs while operational: changes, event timers, inhibit times.
  void process(uint32_t elapsed_us);

  uint64_t transmitted() const { return transmitted_; }
  // RPDO writes of which the dictionary refused at least one value (out of range, not allowed in
  // the present state): the other mapped values were written. The module reports them (EMCY 6320).
  uint64_t refused_writes() const { return refused_writes_; }
  // RPDO writes made (received frames of event-driven RPDOs, synchronous ones at their SYNC).
  uint64_t rpdo_writes() const { return rpdo_writes_; }

 private:
  struct ReceiveState {
    bool pending = false;  // synchronous data waiting for the SYNC
    uint8_t dlc = 0;
    uint8_t data[8] = {};
  };
  struct TransmitState {
    bool due = false;            // send as soon as the inhibit time allows
    bool sent = false;           // `last` holds what went out
    uint8_t sync_count = 0;
    uint64_t inhibit_remaining_us = 0;
    uint64_t event_remaining_us = 0;
    uint8_t length = 0;
    uint8_t last[8] = {};
  };

  // A mapping resolved to the dictionary's objects. Valid while `entries[0..count)` equal the
  // module's mapping: the dictionary's find() gives the same object for an index/sub-index for
  // its lifetime (a TableDictionary's rows are constant).
  struct MappedObject {
    const EntryInfo* info = nullptr;  // nullptr: a dummy entry
    uint32_t row = 0;
    uint16_t index = 0;
    uint8_t axis = 0;
  };
  struct ResolvedMapping {
    bool resolved = false;  // false: resolve before use
    bool active = false;    // every entry byte-sized and usable, at most 8 bytes in all
    uint8_t count = 0;
    uint8_t bytes = 0;
    uint32_t entries[kMaxPdoMappedObjects] = {};
    MappedObject objects[kMaxPdoMappedObjects] = {};
  };

  // The resolution of `mapping` kept in `cache`, redone when the mapping differs from it.
  const ResolvedMapping& resolve(ResolvedMapping& cache, const PdoMapping& mapping, bool receive);
  void write_mapped(const ResolvedMapping& mapping, const uint8_t* data);
  // Reads the mapped objects of TPDO `i` into `out`; false when the PDO is inactive.
  bool sample(size_t i, uint8_t (&out)[8], size_t& length);
  void transmit(size_t i, const uint8_t* data, size_t length);

  ObjectDictionary& dictionary_;
  board::CanController& can_;
  std::span<const PdoCommunication> rpdo_;
  std::span<const PdoMapping> rpdo_mapping_;
  std::span<const PdoCommunication> tpdo_;
  std::span<const PdoMapping> tpdo_mapping_;
  ReceiveState receive_[kMaxPdos] = {};
  TransmitState transmit_[kMaxPdos] = {};
  ResolvedMapping rpdo_resolved_[kMaxPdos] = {};
  ResolvedMapping tpdo_resolved_[kMaxPdos] = {};
  uint64_t transmitted_ = 0;
  uint64_t refused_writes_ = 0;
  uint64_t rpdo_writes_ = 0;
};

}  // namespace motwin::canopen

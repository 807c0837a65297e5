#include "core/canopen/pdo.h"

#include "core/canopen/cob_id.h"

namespace motwin::canopen {
namespace {

uint16_t mapped_index(uint32_t entry) { return static_cast<uint16_t>(entry >> 16); }
uint8_t mapped_sub(uint32_t entry) { return static_cast<uint8_t>(entry >> 8); }
uint8_t mapped_bits(uint32_t entry) { return static_cast<uint8_t>(entry); }

constexpr uint32_t kCobIdExtended = 0x2000'0000;  // bit 29: 29-bit identifier
constexpr uint32_t kCobIdMask = 0x7FF;

}  // namespace

SdoAbort check_pdo_cob_id(uint32_t current, int64_t value) {
  const uint32_t v = static_cast<uint32_t>(value);
  if ((v & kCobIdExtended) != 0 || (v & 0x1FFF'F800) != 0) return SdoAbort::kInvalidValue;
  const bool valid_now = (current & kPdoCobIdInvalid) == 0;
  const bool valid_next = (v & kPdoCobIdInvalid) == 0;
  if (!valid_next) return SdoAbort::kNone;
  if (restricted_can_id(v & kCobIdMask)) return SdoAbort::kInvalidValue;
  if (valid_now && ((v ^ current) & kCobIdMask) != 0) return SdoAbort::kInvalidValue;
  return SdoAbort::kNone;
}

SdoAbort check_pdo_transmission_type(int64_t value) {
  return (value >= 1 && value <= kPdoMaxSynchronousType) || value == kPdoEventDrivenManufacturer ||
                 value == kPdoEventDrivenProfile
             ? SdoAbort::kNone
             : SdoAbort::kInvalidValue;
}

SdoAbort check_pdo_inhibit_time(const PdoCommunication& pdo) {
  return pdo_valid(pdo) ? SdoAbort::kInvalidValue : SdoAbort::kNone;
}

SdoAbort check_pdo_mapping_entry(ObjectDictionary& dictionary, bool receive, uint32_t entry, bool dummies_allowed) {
  const uint16_t index = mapped_index(entry);
  const uint8_t bits = mapped_bits(entry);
  if (bits == 0 || bits % 8 != 0) return SdoAbort::kNotMappable;
  // Both directions may map the dummy types: an RPDO skips their bytes, a TPDO sends zeros.
  if (is_dummy_mapping(entry)) {
    if (!dummies_allowed) return SdoAbort::kNotMappable;
    return type_size(static_cast<DataType>(index)) * 8 == bits ? SdoAbort::kNone : SdoAbort::kNotMappable;
  }
  ObjectRef ref;
  if (dictionary.find(index, mapped_sub(entry), ref) != SdoAbort::kNone) return SdoAbort::kNotMappable;
  const EntryInfo& info = *ref.info;
  if (!info.pdo_mappable || type_size(info.type) * 8 != bits) return SdoAbort::kNotMappable;
  if (receive ? !writable(info.access) : !readable(info.access)) return SdoAbort::kNotMappable;
  return SdoAbort::kNone;
}

SdoAbort check_pdo_mapping_count(ObjectDictionary& dictionary, bool receive, const PdoCommunication& pdo,
                                 const PdoMapping& mapping, int64_t count, bool dummies_allowed) {
  if (pdo_valid(pdo)) return SdoAbort::kDeviceState;
  uint32_t bits = 0;
  for (int64_t i = 0; i < count; ++i) {
    const uint32_t entry = mapping.entries[i];
    if (entry == 0) return SdoAbort::kNotMappable;
    if (const SdoAbort abort = check_pdo_mapping_entry(dictionary, receive, entry, dummies_allowed);
        abort != SdoAbort::kNone) {
      return abort;
    }
    bits += mapped_bits(entry);
  }
  return bits > 64 ? SdoAbort::kMappingTooLong : SdoAbort::kNone;
}

SdoAbort check_pdo_mapping_write(ObjectDictionary& dictionary, bool receive, const PdoCommunication& pdo,
                                 const PdoMapping& mapping, int64_t value, bool dummies_allowed) {
  if (pdo_valid(pdo) || mapping.count != 0) return SdoAbort::kDeviceState;
  if (value == 0) return SdoAbort::kNone;
  return check_pdo_mapping_entry(dictionary, receive, static_cast<uint32_t>(value), dummies_allowed);
}

PdoService::PdoService(ObjectDictionary& dictionary, board::CanController& can,
                       std::span<const PdoCommunication> rpdo, std::span<const PdoMapping> rpdo_mapping,
                       std::span<const PdoCommunication> tpdo, std::span<const PdoMapping> tpdo_mapping)
    : dictionary_(dictionary),
      can_(can),
      rpdo_(rpdo.first(rpdo.size() < kMaxPdos ? rpdo.size() : kMaxPdos)),
      rpdo_mapping_(rpdo_mapping),
      tpdo_(tpdo.first(tpdo.size() < kMaxPdos ? tpdo.size() : kMaxPdos)),
      tpdo_mapping_(tpdo_mapping) {}

void PdoService::reset() {
  for (ReceiveState& r : receive_) r = ReceiveState{};
  for (TransmitState& t : transmit_) t = TransmitState{};
  for (ResolvedMapping& m : rpdo_resolved_) m.resolved = false;
  for (ResolvedMapping& m : tpdo_resolved_) m.resolved = false;
}

void PdoService::enter_operational() {
  reset();
  for (size_t i = 0; i < tpdo_.size(); ++i) {
    const PdoCommunication& pdo = tpdo_[i];
    if (!pdo_valid(pdo) || pdo_synchronous(pdo)) continue;
    transmit_[i].due = true;
    transmit_[i].event_remaining_us = static_cast<uint64_t>(pdo.event_timer_ms) * 1000u;
  }
}

const PdoService::ResolvedMapping& PdoService::resolve(ResolvedMapping& cache, const PdoMapping& mapping,
                                                       bool receive) {
  // The module's mapping is checked against the copy at every use: a few word compares, and no
  // notification to miss whichever way the mapping changed (SDO, restore, reset, a test).
  const uint8_t count = mapping.count < kMaxPdoMappedObjects ? mapping.count : kMaxPdoMappedObjects;
  bool same = cache.resolved && cache.count == mapping.count;
  for (uint8_t e = 0; e < count && same; ++e) same = cache.entries[e] == mapping.entries[e];
  if (same) return cache;

  cache = ResolvedMapping{};
  cache.resolved = true;
  cache.count = mapping.count;
  for (uint8_t e = 0; e < count; ++e) cache.entries[e] = mapping.entries[e];
  if (mapping.count > kMaxPdoMappedObjects) return cache;  // inactive
  size_t bytes = 0;
  for (uint8_t e = 0; e < count; ++e) {
    const uint32_t entry = mapping.entries[e];
    const uint8_t bits = mapped_bits(entry);
    if (bits == 0 || bits % 8 != 0) return cache;
    if (!is_dummy_mapping(entry)) {
      ObjectRef ref;
      if (dictionary_.find(mapped_index(entry), mapped_sub(entry), ref) != SdoAbort::kNone) return cache;
      if (receive ? !writable(ref.info->access) : !readable(ref.info->access)) return cache;
      if (type_size(ref.info->type) * 8u != bits) return cache;
      // Not a row of any real table (a size_t row only exceeds 32 bits on a 64-bit host).
      if constexpr (sizeof(ref.row) > sizeof(uint32_t)) {
        if (ref.row > UINT32_MAX) return cache;
      }
      cache.objects[e] = MappedObject{ref.info, static_cast<uint32_t>(ref.row), ref.index, ref.axis};
    }
    bytes += bits / 8u;
  }
  if (bytes > 8) return cache;
  cache.active = true;
  cache.bytes = static_cast<uint8_t>(bytes);
  return cache;
}

RpdoReception PdoService::on_frame(const can::CanFrame& frame) {
  if (frame.extended || frame.rtr) return RpdoReception::kNotPdo;
  for (size_t i = 0; i < rpdo_.size(); ++i) {
    const PdoCommunication& pdo = rpdo_[i];
    if (!pdo_valid(pdo) || (pdo.cob_id & 0x7FF) != frame.id) continue;
    const ResolvedMapping& mapping = resolve(rpdo_resolved_[i], rpdo_mapping_[i], true);
    if (!mapping.active) return RpdoReception::kAccepted;  // inactive: ignored
    if (frame.dlc < mapping.bytes) return RpdoReception::kTooShort;
    if (pdo_synchronous(pdo)) {
      ReceiveState& state = receive_[i];
      state.pending = true;
      state.dlc = frame.dlc;
      for (uint8_t b = 0; b < 8; ++b) state.data[b] = frame.data[b];
    } else {
      write_mapped(mapping, frame.data);
    }
    return frame.dlc > mapping.bytes ? RpdoReception::kTooLong : RpdoReception::kAccepted;
  }
  return RpdoReception::kNotPdo;
}

void PdoService::write_mapped(const ResolvedMapping& mapping, const uint8_t* data) {
  size_t offset = 0;
  bool refused = false;
  for (uint8_t e = 0; e < mapping.count; ++e) {
    const size_t bytes = mapped_bits(mapping.entries[e]) / 8u;
    const MappedObject& object = mapping.objects[e];
    // A value the object refuses (out of its range) is dropped; the other objects are written.
    if (object.info != nullptr) {
      const ObjectRef ref{object.info, object.row, object.index, object.axis};
      if (dictionary_.write(ref, data + offset, bytes) != SdoAbort::kNone) refused = true;
    }
    offset += bytes;
  }
  ++rpdo_writes_;
  if (refused) ++refused_writes_;
}

bool PdoService::sample(size_t i, uint8_t (&out)[8], size_t& length) {
  length = 0;
  const ResolvedMapping& mapping = resolve(tpdo_resolved_[i], tpdo_mapping_[i], false);
  if (!mapping.active) return false;
  for (uint8_t e = 0; e < mapping.count; ++e) {
    const size_t size = mapped_bits(mapping.entries[e]) / 8u;
    const MappedObject& object = mapping.objects[e];
    if (object.info == nullptr) {  // dummy
      for (size_t b = 0; b < size; ++b) out[length + b] = 0;
    } else {
      size_t read = 0;
      const ObjectRef ref{object.info, object.row, object.index, object.axis};
      if (dictionary_.read(ref, out + length, 8 - length, read) != SdoAbort::kNone || read != size) return false;
    }
    length += size;
  }
  return true;
}

void PdoService::transmit(size_t i, const uint8_t* data, size_t length) {
  TransmitState& state = transmit_[i];
  const can::CanFrame frame = can::make_frame(tpdo_[i].cob_id & 0x7FF, data, static_cast<uint8_t>(length));
  can_.transmit(frame);
  ++transmitted_;
  state.sent = true;
  state.due = false;
  state.length = static_cast<uint8_t>(length);
  for (size_t b = 0; b < length; ++b) state.last[b] = data[b];
  state.inhibit_remaining_us = static_cast<uint64_t>(tpdo_[i].inhibit_time_100us) * 100u;
  state.event_remaining_us = static_cast<uint64_t>(tpdo_[i].event_timer_ms) * 1000u;
}

void PdoService::on_sync() {
  for (size_t i = 0; i < rpdo_.size(); ++i) {
    ReceiveState& state = receive_[i];
    if (!state.pending) continue;
    state.pending = false;
    if (!pdo_valid(rpdo_[i]) || !pdo_synchronous(rpdo_[i])) continue;
    // The mapping of the SYNC's time; data kept for another mapping (remapped in between) that
    // is too short for this one is dropped.
    const ResolvedMapping& mapping = resolve(rpdo_resolved_[i], rpdo_mapping_[i], true);
    if (mapping.active && state.dlc >= mapping.bytes) write_mapped(mapping, state.data);
  }
  for (size_t i = 0; i < tpdo_.size(); ++i) {
    const PdoCommunication& pdo = tpdo_[i];
    if (!pdo_valid(pdo) || !pdo_synchronous(pdo)) continue;
    TransmitState& state = transmit_[i];
    if (++state.sync_count < pdo.transmission_type) continue;
    state.sync_count = 0;
    uint8_t data[8] = {};
    size_t length = 0;
    if (sample(i, data, length)) transmit(i, data, length);
  }
}

void PdoService::process(uint32_t elapsed_us) {
  for (size_t i = 0; i < tpdo_.size(); ++i) {
    const PdoCommunication& pdo = tpdo_[i];
    TransmitState& state = transmit_[i];
    if (!pdo_valid(pdo) || pdo_synchronous(pdo)) continue;
    state.inhibit_remaining_us = elapsed_us < state.inhibit_remaining_us ? state.inhibit_remaining_us - elapsed_us : 0;
    if (pdo.event_timer_ms != 0) {
      if (elapsed_us >= state.event_remaining_us) {
        state.due = true;
        state.event_remaining_us = 0;
      } else {
        state.event_remaining_us -= elapsed_us;
      }
    }
    uint8_t data[8] = {};
    size_t length = 0;
    if (!sample(i, data, length)) continue;
    bool changed = !state.sent || length != state.length;
    for (size_t b = 0; b < length && !changed; ++b) changed = data[b] != state.last[b];
    if (changed) state.due = true;
    if (state.due && state.inhibit_remaining_us == 0) transmit(i, data, length);
  }
}

}  // namespace motwin::canopen

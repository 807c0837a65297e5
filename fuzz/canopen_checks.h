// Checks shared by the CANopen fuzz targets: the SDO client's view of every transfer and the
// object dictionary's ranges. Each works on any module with a canopen::Node and a TableDictionary
// (`Device`: the TMCM-3216, the TMCM-1636's CANopen firmware): node(), node_id(), nmt_state() and
// dictionary().
#pragma once

#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include "core/canopen/sdo_abort.h"
#include "core/canopen/sdo_server.h"
#include "fuzz_support.h"

namespace motwin::fuzz {

inline uint32_t le32(const uint8_t* b) {
  return static_cast<uint32_t>(b[0]) | static_cast<uint32_t>(b[1]) << 8 | static_cast<uint32_t>(b[2]) << 16 |
         static_cast<uint32_t>(b[3]) << 24;
}

// CRC-16 of CiA-301 block transfers (CCITT polynomial 0x1021, initial 0), bit by bit: the
// server's is table-driven.
inline uint16_t crc16_bitwise(const uint8_t* data, size_t length) {
  uint16_t crc = 0;
  for (size_t i = 0; i < length; ++i) {
    crc = static_cast<uint16_t>(crc ^ (data[i] << 8));
    for (int bit = 0; bit < 8; ++bit) {
      crc = static_cast<uint16_t>((crc & 0x8000) != 0 ? (crc << 1) ^ 0x1021 : crc << 1);
    }
  }
  return crc;
}

// The objects of a module's dictionary by index and sub-index, for the checks' own lookups:
// what TableDictionary::find answers, from a table sorted once per process (the rows and the axis
// count are constants) and searched without libFuzzer's tracing. Looking up through find() for
// every snapshot and read-back of the SDO client view was a seventh of canopen_pdo's time; the
// server's own lookups stay find(). The table is checked when it is built: every entry is what
// find() gives, and every index and sub-index that find() knows is in it. One per module type and
// process.
class ObjectLookup {
 public:
  template <class Device>
  static const ObjectLookup& of(Device& device) {
    static const ObjectLookup lookup(device);
    FUZZ_CHECK(device.dictionary().rows().data() == lookup.rows_, "ObjectLookup: another object table");
    return lookup;
  }

  FUZZ_UNTRACED bool find(uint16_t index, uint8_t sub, canopen::ObjectRef& out) const {
    const uint32_t key = static_cast<uint32_t>(index) << 8 | sub;
    size_t low = 0;
    size_t high = entries_.size();
    while (low < high) {
      const size_t mid = low + (high - low) / 2;
      if (entries_[mid].key < key) {
        low = mid + 1;
      } else {
        high = mid;
      }
    }
    if (low == entries_.size() || entries_[low].key != key) return false;
    out = entries_[low].ref;
    return true;
  }

 private:
  struct Entry {
    uint32_t key;
    canopen::ObjectRef ref;
  };

  template <class Device>
  explicit ObjectLookup(Device& device) {
    auto& dictionary = device.dictionary();
    const auto rows = dictionary.rows();
    rows_ = rows.data();
    // The first row in table order for each index and sub-index, as find() answers.
    for (size_t row = 0; row < rows.size(); ++row) {
      const canopen::EntryInfo& info = rows[row].info;
      const uint8_t axes = info.axis_stride == 0 ? 1 : dictionary.axis_count();
      for (uint8_t axis = 0; axis < axes; ++axis) {
        const auto index = static_cast<uint16_t>(info.index + axis * info.axis_stride);
        entries_.push_back(Entry{static_cast<uint32_t>(index) << 8 | info.sub, canopen::ObjectRef{&info, row, index, axis}});
      }
    }
    std::stable_sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return a.key < b.key; });
    entries_.erase(std::unique(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return a.key == b.key; }),
                   entries_.end());
    for (const Entry& entry : entries_) {
      canopen::ObjectRef found;
      FUZZ_CHECK(dictionary.find(entry.ref.index, entry.ref.info->sub, found) == canopen::SdoAbort::kNone &&
                     found.row == entry.ref.row && found.axis == entry.ref.axis && found.index == entry.ref.index,
                 "ObjectLookup: find() answers %04x sub %u otherwise", entry.ref.index, entry.ref.info->sub);
    }
    std::vector<uint16_t> indices;
    for (const Entry& entry : entries_) {
      if (indices.empty() || indices.back() != entry.ref.index) indices.push_back(entry.ref.index);
    }
    canopen::ObjectRef ignored;
    for (uint16_t index : indices) {
      for (int sub = 0; sub < 256; ++sub) {
        FUZZ_CHECK(find(index, static_cast<uint8_t>(sub), ignored) ==
                       (dictionary.find(index, static_cast<uint8_t>(sub), ignored) == canopen::SdoAbort::kNone),
                   "ObjectLookup: %04x sub %d", index, sub);
      }
    }
    for (uint32_t index = 0; index <= 0xFFFF; ++index) {
      FUZZ_CHECK(find(static_cast<uint16_t>(index), 0, ignored) ==
                     (dictionary.find(static_cast<uint16_t>(index), 0, ignored) == canopen::SdoAbort::kNone),
                 "ObjectLookup: %04x sub 0", index);
    }
  }

  const void* rows_ = nullptr;
  std::vector<Entry> entries_;
};

// A readable numeric object's value as an upload gives it: the row's getter (or its constant
// default) encoded in the type's size, as TableDictionary::read does (value(), encode_value()),
// untraced. Checked, not assumed: on the first call of a process and then every 2^16th, the bytes
// must equal what read() gives.
template <class Device>
FUZZ_UNTRACED size_t read_numeric(Device& device, const canopen::ObjectRef& ref, uint8_t (&bytes)[8]) {
  static uint64_t calls = 0;
  auto& dictionary = device.dictionary();
  const auto get = dictionary.rows()[ref.row].binding.get;
  const int64_t value = get != nullptr ? get(device, ref.axis) : dictionary.default_value(*ref.info, ref.axis);
  const size_t length = canopen::type_size(ref.info->type);
  for (size_t i = 0; i < 8; ++i) bytes[i] = i < length ? static_cast<uint8_t>(static_cast<uint64_t>(value) >> (8 * i)) : 0;
  if (calls++ % kRigComparisonPeriod == 0) {
    uint8_t as_read[8] = {};
    size_t read_length = 0;
    FUZZ_CHECK(dictionary.read(ref, as_read, sizeof(as_read), read_length) == canopen::SdoAbort::kNone &&
                   read_length == length && std::memcmp(as_read, bytes, length) == 0,
               "read_numeric: %04x sub %u differs from read()", ref.index, ref.info->sub);
  }
  return length;
}

// The SDO client's side of a module's server (CiA-301 7.2.4.3): the transfer state as the
// client sees it from its requests and the server's responses, against which every response is
// checked. Around each step of a target: before(frame or nullptr, elapsed µs), then the step
// (receive, process), then after(every frame the device sent).
// - A request gets exactly one response (a valid one for the state, or an abort), except: a
//   remote frame and a client abort get none; a block download segment gets one only at the end
//   of its sub-block (the last sequence number of the block, or c set); a block upload start or
//   acknowledgement gets a sub-block of segments (or one end response, or an abort); the client's
//   block upload end gets none. Nothing answers a frame the server does not get (node stopped).
// - Responses: server command specifiers with reserved bits and bytes 0; initiate responses and
//   their aborts echo the request's index and sub-index, later aborts the transfer's; abort codes
//   from CiA-301's table.
// - Segmented: the response's toggle bit is the request's, a request whose toggle did not
//   alternate is aborted with 05030000; upload segments add up to the indicated size, c set
//   exactly on the one that reaches it; a download whose bytes miss the indicated size is aborted.
// - Block download: an out-of-range sequence number is aborted with 05040003; each sub-block
//   response acknowledges the last segment received in order, blksize 1..127; the end is aborted
//   when the length or (both sides supporting it) the CRC does not match the data sent.
// - Block upload: a block size 0 or above 127 is aborted (initiate and acknowledgement, 05040002),
//   an acknowledgement beyond the segments sent with 05040003; segments numbered 1..n with
//   n <= blksize, c only on the last one and exactly when the data ends; a resent segment carries
//   the bytes it carried before; the end response gives the unused bytes of the last segment and
//   the CRC of all the data.
// - Aborts only for a reason: a download segment or block segment within the indicated size (and
//   SdoServer::kBufferSize) is not aborted before the write at the end; upload segments and
//   sub-blocks only when the value streams through the buffer in windows.
// - A transfer idle for SdoServer::kTimeoutUs is aborted with 05040000 (and only then is there a
//   response without a request); an NMT or LSS reset ends it silently.
// - An expedited download acknowledged without abort reads back as the written value (a numeric
//   read-write object written with its type's size); an aborted one changes nothing.
template <class Device>
class SdoClientView {
 public:
  explicit SdoClientView(Device& device) : device_(device) {}

  void before(const can::CanFrame* frame, uint32_t elapsed_us) {
    node_ = device_.node_id();
    const canopen::NmtState nmt = device_.nmt_state();
    serving_before_ = node_ >= 1 && node_ <= 127 &&
                      (nmt == canopen::NmtState::kPreOperational || nmt == canopen::NmtState::kOperational);
    has_request_ = frame != nullptr && !frame->extended && frame->id == canopen::kSdoRequestCobIdBase + node_ &&
                   serving_before_;
    elapsed_us_ = elapsed_us;
    snapshot_ = Snapshot{};
    if (!has_request_) return;
    request_ = *frame;
    const uint8_t d0 = frame->data[0];
    if (!frame->rtr && frame->dlc == 8 && d0 >> 5 == 1 && (d0 & 0x02) != 0 && state_ != State::kDownloadBlock) {
      snapshot_.taken = read(mux_of(frame->data), snapshot_.ref, snapshot_.bytes);
    }
  }

  void after(const std::vector<can::CanFrame>& sent) {
    std::vector<can::CanFrame> out;
    for (const can::CanFrame& frame : sent) {
      if (frame.extended || frame.id != canopen::kSdoResponseCobIdBase + node_) continue;
      FUZZ_CHECK(!frame.rtr && frame.dlc == 8, "SDO response with dlc %u", frame.dlc);
      out.push_back(frame);
    }
    if (has_request_) {
      idle_us_ = 0;
      on_request(out);
      return;
    }
    if (state_ != State::kIdle) idle_us_ += elapsed_us_;
    const canopen::NmtState nmt = device_.nmt_state();
    const bool serving_after =
        device_.node_id() == node_ &&
        (nmt == canopen::NmtState::kPreOperational || nmt == canopen::NmtState::kOperational);
    if (out.empty()) {
      // An NMT command, an LSS reset or a heartbeat timeout ended the transfer without a frame.
      if (device_.node().sdo().state() == canopen::SdoState::kIdle) state_ = State::kIdle;
      FUZZ_CHECK(!(state_ != State::kIdle && idle_us_ >= canopen::SdoServer::kTimeoutUs && serving_before_ &&
                   serving_after && elapsed_us_ > 0),
                 "a transfer idle for %llu us was not aborted", static_cast<unsigned long long>(idle_us_));
      return;
    }
    FUZZ_CHECK(out.size() == 1 && state_ != State::kIdle && idle_us_ >= canopen::SdoServer::kTimeoutUs,
               "%zu SDO responses without a request (state %d, idle %llu us)", out.size(), static_cast<int>(state_),
               static_cast<unsigned long long>(idle_us_));
    check_abort(out[0], mux_, canopen::SdoAbort::kTimeout);
    state_ = State::kIdle;
  }

 private:
  // The server's states as the client sees them (the client's own bookkeeping, not the server's).
  using State = canopen::SdoState;
  struct Mux {
    uint16_t index = 0;
    uint8_t sub = 0;
    bool operator==(const Mux&) const = default;
  };
  struct Snapshot {
    bool taken = false;
    canopen::ObjectRef ref;
    std::vector<uint8_t> bytes;
  };
  using Frames = std::vector<can::CanFrame>;

  static Mux mux_of(const uint8_t* data) { return Mux{static_cast<uint16_t>(data[1] | data[2] << 8), data[3]}; }
  static bool is_abort(const can::CanFrame& frame) { return frame.data[0] == 0x80; }
  static bool zeros(const can::CanFrame& frame, size_t from) {
    for (size_t i = from; i < 8; ++i) {
      if (frame.data[i] != 0) return false;
    }
    return true;
  }

  // A readable numeric object's current bytes (ObjectLookup and read_numeric: find() and read()
  // as they answer, untraced).
  FUZZ_UNTRACED bool read(Mux mux, canopen::ObjectRef& ref, std::vector<uint8_t>& bytes) {
    if (!ObjectLookup::of(device_).find(mux.index, mux.sub, ref)) return false;
    if (!canopen::is_numeric(ref.info->type) || !canopen::readable(ref.info->access)) return false;
    uint8_t buffer[8] = {};
    const size_t length = read_numeric(device_, ref, buffer);
    bytes.assign(buffer, buffer + length);
    return true;
  }

  // `mux` null: the abort may name anything (a request outside a transfer).
  void check_abort(const can::CanFrame& frame, std::optional<Mux> mux,
                   canopen::SdoAbort expected = canopen::SdoAbort::kNone) {
    FUZZ_CHECK(is_abort(frame), "an abort expected, the server sent 0x%02x", frame.data[0]);
    const uint32_t abort = le32(&frame.data[4]);
    FUZZ_CHECK(abort != 0 && canopen::describe(abort)[0] != '\0', "abort code %08x is not in CiA-301's table", abort);
    if (mux) {
      FUZZ_CHECK(mux_of(frame.data) == *mux, "abort for %04x sub %u, the transfer is %04x sub %u",
                 mux_of(frame.data).index, mux_of(frame.data).sub, mux->index, mux->sub);
    }
    if (expected != canopen::SdoAbort::kNone) {
      FUZZ_CHECK(abort == canopen::code(expected), "abort code %08x, CiA-301 asks for %08x", abort,
                 canopen::code(expected));
    }
  }

  std::optional<Mux> transfer_mux() const { return state_ == State::kIdle ? std::nullopt : std::optional<Mux>(mux_); }

  // The request may only be refused: one abort, the transfer ends.
  void refused(const Frames& out, std::optional<Mux> mux, canopen::SdoAbort expected = canopen::SdoAbort::kNone) {
    FUZZ_CHECK(out.size() == 1, "%zu responses where an abort is due (state %d)", out.size(), static_cast<int>(state_));
    check_abort(out[0], mux, expected);
    state_ = State::kIdle;
  }

  void on_request(const Frames& out) {
    const can::CanFrame& r = request_;
    if (r.rtr) {
      FUZZ_CHECK(out.empty(), "an SDO response to a remote frame");
      return;
    }
    uint8_t d[8] = {};
    for (uint8_t i = 0; i < r.dlc && i < 8; ++i) d[i] = r.data[i];
    const bool block_segment = state_ == State::kDownloadBlock && d[0] != 0x80;
    const uint8_t ccs = d[0] >> 5;
    if (!block_segment && ccs == 4) {  // the client aborts
      FUZZ_CHECK(out.empty(), "a response to the client's abort");
      state_ = State::kIdle;
      return;
    }
    if (r.dlc != 8) {
      refused(out, transfer_mux());
      return;
    }
    if (block_segment) {
      download_block_segment(d, out);
      return;
    }
    const uint8_t ss = d[0] & 0x03;
    switch (ccs) {
      case 1: initiate_download(d, out); return;
      case 2: initiate_upload(d, out); return;
      case 0:
        if (state_ == State::kDownloadSegments) return download_segment(d, out);
        break;
      case 3:
        if (state_ == State::kUploadSegments) return upload_segment(d, out);
        break;
      case 6:
        if ((d[0] & 0x01) == 0) return initiate_block_download(d, out);
        if (state_ == State::kDownloadBlockEnd) return end_block_download(d, out);
        break;
      case 5:
        if (ss == 0) return initiate_block_upload(d, out);
        if (ss == 3 && state_ == State::kUploadBlockStart) return upload_sub_block(out);
        if (ss == 2 && state_ == State::kUploadBlockAck) return acknowledge_upload_block(d, out);
        if (ss == 1 && state_ == State::kUploadBlockEnd) {
          FUZZ_CHECK(out.empty(), "a response to the client's block upload end");
          state_ = State::kIdle;
          return;
        }
        break;
      default: break;
    }
    refused(out, transfer_mux());
  }

  // An initiate request starts a new transfer (ending any other): exactly one response; an abort
  // names the request's index and sub-index. The response, or nullptr for an abort.
  const can::CanFrame* initiate(const uint8_t* d, const Frames& out, const char* what) {
    state_ = State::kIdle;
    mux_ = mux_of(d);
    FUZZ_CHECK(out.size() == 1, "%zu responses to %s", out.size(), what);
    if (!is_abort(out[0])) return &out[0];
    check_abort(out[0], mux_);
    return nullptr;
  }

  void initiate_download(const uint8_t* d, const Frames& out) {
    const bool expedited = (d[0] & 0x02) != 0;
    const can::CanFrame* answer = initiate(d, out, "an initiate download");
    if (answer == nullptr) {
      if (expedited && snapshot_.taken) {
        std::vector<uint8_t> now;
        FUZZ_CHECK(read(mux_, snapshot_.ref, now) && now == snapshot_.bytes,
                   "an aborted expedited download changed %04x sub %u", mux_.index, mux_.sub);
      }
      return;
    }
    const can::CanFrame& response = *answer;
    FUZZ_CHECK(response.data[0] == 0x60 && mux_of(response.data) == mux_ && zeros(response, 4),
               "initiate download response %02x for %04x sub %u", response.data[0], mux_of(response.data).index,
               mux_of(response.data).sub);
    if (expedited) {
      check_read_back(d);
      return;
    }
    size_known_ = (d[0] & 0x01) != 0;
    size_ = size_known_ ? le32(d + 4) : 0;
    transferred_ = 0;
    toggle_ = 0;
    state_ = State::kDownloadSegments;
  }

  // A numeric read-write object written with its type's size reads back as written.
  void check_read_back(const uint8_t* d) {
    if (!snapshot_.taken) return;
    const canopen::EntryInfo& info = *snapshot_.ref.info;
    const size_t length = (d[0] & 0x01) != 0 ? 4u - ((d[0] >> 2) & 0x03) : 4u;
    if (info.access != canopen::Access::kRw || length != canopen::type_size(info.type) || !plain(info)) return;
    std::vector<uint8_t> now;
    FUZZ_CHECK(read(mux_, snapshot_.ref, now) && now.size() == length && std::memcmp(now.data(), d + 4, length) == 0,
               "%04x sub %u (%.*s) acknowledged %d but reads %lld", mux_.index, mux_.sub,
               static_cast<int>(info.name.size()), info.name.data(), static_cast<int>(le32(d + 4)),
               now.size() == length ? static_cast<long long>(canopen::decode_value(info.type, now.data())) : -1LL);
  }

  // Not plain: the store and restore commands (1010, 1011, 2706 sub 1) take a signature, and a read
  // gives what the device can store or restore (CiA-301 7.5.2.13/14), not the last signature; the
  // TMCM-1636 CANopen firmware's 5FFF (Enter Boot Mode) takes a key and reads 0
  // (docs/tmcm-1636-canopen.md). No TMCM-3216 object has that index.
  static bool plain(const canopen::EntryInfo& info) {
    return info.index != 0x1010 && info.index != 0x1011 && info.index != 0x2706 && info.index != 0x5FFF;
  }

  void download_segment(const uint8_t* d, const Frames& out) {
    if ((d[0] & 0x10) != toggle_) return refused(out, mux_, canopen::SdoAbort::kToggleBit);
    const bool last = (d[0] & 0x01) != 0;
    transferred_ += 7u - ((d[0] >> 1) & 0x07);
    FUZZ_CHECK(out.size() == 1, "%zu responses to a download segment", out.size());
    const can::CanFrame& response = out[0];
    const bool too_long = transferred_ > (size_known_ ? size_ : canopen::SdoServer::kBufferSize);
    // Aborted only at the end (the write) or for more bytes than indicated or than fit.
    if (is_abort(response)) {
      FUZZ_CHECK(last || too_long, "download segment %zu aborted", transferred_);
      return refused(out, mux_);
    }
    FUZZ_CHECK(response.data[0] == (0x20 | toggle_) && zeros(response, 1), "download segment response %02x (toggle %x)",
               response.data[0], toggle_);
    FUZZ_CHECK(!size_known_ || (last ? transferred_ == size_ : transferred_ <= size_),
               "a download of %zu bytes where %zu were indicated was acknowledged", transferred_, size_);
    toggle_ ^= 0x10;
    if (last) state_ = State::kIdle;
  }

  void initiate_upload(const uint8_t* d, const Frames& out) {
    if (const can::CanFrame* response = initiate(d, out, "an initiate upload")) expect_upload_response(*response);
  }

  // An initiate upload response (also the answer to a block upload that switched protocols).
  void expect_upload_response(const can::CanFrame& response) {
    const uint8_t h = response.data[0];
    const bool expedited = (h & 0x02) != 0;
    const bool size_indicated = (h & 0x01) != 0;
    FUZZ_CHECK(h >> 5 == 2 && (h & 0x10) == 0 && mux_of(response.data) == mux_ &&
                   (((h >> 2) & 0x03) == 0 || (expedited && size_indicated)),
               "initiate upload response %02x for %04x sub %u", h, mux_of(response.data).index,
               mux_of(response.data).sub);
    if (expedited) {
      const size_t length = size_indicated ? 4u - ((h >> 2) & 0x03) : 4u;
      canopen::ObjectRef ref;
      std::vector<uint8_t> value;
      if (size_indicated && read(mux_, ref, value)) {
        FUZZ_CHECK(value.size() == length && std::memcmp(value.data(), &response.data[4], length) == 0,
                   "expedited upload of %04x sub %u: %zu bytes, not the object's value", mux_.index, mux_.sub, length);
      }
      return;
    }
    size_known_ = size_indicated;
    size_ = size_indicated ? le32(&response.data[4]) : 0;
    FUZZ_CHECK(size_indicated || zeros(response, 4), "initiate upload response without size, data %08x",
               le32(&response.data[4]));
    transferred_ = 0;
    toggle_ = 0;
    state_ = State::kUploadSegments;
  }

  void upload_segment(const uint8_t* d, const Frames& out) {
    if ((d[0] & 0x10) != toggle_) return refused(out, mux_, canopen::SdoAbort::kToggleBit);
    FUZZ_CHECK(out.size() == 1, "%zu responses to an upload segment request", out.size());
    const can::CanFrame& response = out[0];
    if (is_abort(response)) {  // only a value streamed in windows can fail to be read on the way
      FUZZ_CHECK(size_ > canopen::SdoServer::kBufferSize, "upload segment of %zu bytes aborted", size_);
      return refused(out, mux_);
    }
    const uint8_t h = response.data[0];
    const bool last = (h & 0x01) != 0;
    FUZZ_CHECK(h >> 5 == 0 && (h & 0x10) == toggle_, "upload segment %02x, toggle %x expected", h, toggle_);
    transferred_ += 7u - ((h >> 1) & 0x07);
    if (size_known_) {
      FUZZ_CHECK(transferred_ <= size_ && last == (transferred_ == size_),
                 "upload segment: %zu of %zu bytes, c %d", transferred_, size_, last);
    }
    toggle_ ^= 0x10;
    if (last) state_ = State::kIdle;
  }

  void initiate_block_download(const uint8_t* d, const Frames& out) {
    const can::CanFrame* answer = initiate(d, out, "a block download initiate");
    if (answer == nullptr) return;
    const can::CanFrame& response = *answer;
    const uint8_t h = response.data[0];
    FUZZ_CHECK((h & 0xFB) == 0xA0 && mux_of(response.data) == mux_ && response.data[4] >= 1 &&
                   response.data[4] <= 127 && zeros(response, 5),
               "block download initiate response %02x blksize %u", h, response.data[4]);
    size_known_ = (d[0] & 0x02) != 0;
    size_ = size_known_ ? le32(d + 4) : 0;
    crc_ = (d[0] & 0x04) != 0 && (h & 0x04) != 0;
    block_size_ = response.data[4];
    in_order_ = 0;
    data_.clear();
    state_ = State::kDownloadBlock;
  }

  void download_block_segment(const uint8_t* d, const Frames& out) {
    const uint8_t sequence = d[0] & 0x7F;
    const bool last = (d[0] & 0x80) != 0;
    if (sequence == 0 || sequence > block_size_) return refused(out, mux_, canopen::SdoAbort::kInvalidSequence);
    bool too_long = false;  // a segment beyond the indicated size (an empty value takes one) or the buffer
    if (sequence == in_order_ + 1) {
      too_long = data_.size() >= (size_known_ ? std::max<size_t>(size_, 1) : canopen::SdoServer::kBufferSize);
      in_order_ = sequence;
      data_.insert(data_.end(), d + 1, d + 8);
    }
    if (!out.empty() && is_abort(out[0])) {
      FUZZ_CHECK(too_long, "block download segment %u aborted after %zu bytes", sequence, data_.size());
      return refused(out, mux_);
    }
    if (!(last || sequence == block_size_)) {
      FUZZ_CHECK(out.empty(), "%zu responses within a sub-block", out.size());
      return;
    }
    FUZZ_CHECK(out.size() == 1, "%zu responses at the end of a sub-block", out.size());
    const can::CanFrame& response = out[0];
    FUZZ_CHECK(response.data[0] == 0xA2 && response.data[1] == in_order_ && response.data[2] >= 1 &&
                   response.data[2] <= 127 && zeros(response, 3),
               "sub-block response %02x ackseq %u (in order: %u) blksize %u", response.data[0], response.data[1],
               in_order_, response.data[2]);
    if (last && sequence == in_order_) {
      state_ = State::kDownloadBlockEnd;
    } else {
      block_size_ = response.data[2];
    }
    in_order_ = 0;
  }

  void end_block_download(const uint8_t* d, const Frames& out) {
    const size_t unused = (d[0] >> 2) & 0x07;
    const size_t length = data_.size() >= unused ? data_.size() - unused : 0;
    const bool length_wrong = data_.size() < unused || (size_known_ && length != size_);
    const bool crc_wrong = crc_ && (d[1] | d[2] << 8) != crc16_bitwise(data_.data(), length);
    FUZZ_CHECK(out.size() == 1, "%zu responses to a block download end", out.size());
    const can::CanFrame& response = out[0];
    if (length_wrong || crc_wrong) {
      return refused(out, mux_, length_wrong ? canopen::SdoAbort::kNone : canopen::SdoAbort::kCrc);
    }
    if (is_abort(response)) return refused(out, mux_);
    FUZZ_CHECK(response.data[0] == 0xA1 && zeros(response, 1), "block download end response %02x", response.data[0]);
    state_ = State::kIdle;
  }

  void initiate_block_upload(const uint8_t* d, const Frames& out) {
    const uint8_t block_size = d[4];
    const uint8_t switch_threshold = d[5];
    const can::CanFrame* answer = initiate(d, out, "a block upload initiate");
    if (answer == nullptr) return;
    const can::CanFrame& response = *answer;
    FUZZ_CHECK(block_size >= 1 && block_size <= 127, "a block upload with blksize %u was not aborted", block_size);
    const uint8_t h = response.data[0];
    if (h >> 5 == 2) {  // protocol switch to a normal upload
      expect_upload_response(response);
      const size_t length = (h & 0x02) != 0 ? 4u - ((h >> 2) & 0x03) : size_;
      FUZZ_CHECK(switch_threshold != 0 && length <= switch_threshold,
                 "switched to a normal upload of %zu bytes with threshold %u", length, switch_threshold);
      return;
    }
    FUZZ_CHECK((h & 0xF9) == 0xC0 && mux_of(response.data) == mux_, "block upload initiate response %02x for %04x sub %u",
               h, mux_of(response.data).index, mux_of(response.data).sub);
    size_known_ = (h & 0x02) != 0;
    size_ = size_known_ ? le32(&response.data[4]) : 0;
    if (!size_known_) FUZZ_CHECK(zeros(response, 4), "block upload initiate without size, data %08x", le32(&response.data[4]));
    crc_ = (d[0] & 0x04) != 0 && (h & 0x04) != 0;
    block_size_ = block_size;
    transferred_ = 0;  // acknowledged bytes
    data_.clear();     // every byte sent so far
    state_ = State::kUploadBlockStart;
  }

  // A sub-block from the first unacknowledged byte on.
  void upload_sub_block(const Frames& out) {
    FUZZ_CHECK(!out.empty(), "no sub-block");
    if (is_abort(out[0])) {  // only a value streamed in windows can fail to be read on the way
      FUZZ_CHECK(size_ > canopen::SdoServer::kBufferSize, "block upload of %zu bytes aborted", size_);
      return refused(out, mux_);
    }
    const size_t n = out.size();
    FUZZ_CHECK(n <= block_size_, "%zu segments in a sub-block of %u", n, block_size_);
    for (size_t i = 0; i < n; ++i) {
      const uint8_t h = out[i].data[0];
      const bool last = (h & 0x80) != 0;
      FUZZ_CHECK((h & 0x7F) == i + 1 && (!last || i + 1 == n), "segment %zu of %zu: %02x", i + 1, n, h);
      const size_t position = transferred_ + 7 * i;
      for (size_t j = 0; j < 7; ++j) {
        if (size_known_ && position + j >= size_) break;
        if (position + j < data_.size()) {
          FUZZ_CHECK(data_[position + j] == out[i].data[1 + j], "byte %zu sent again as %02x, first as %02x",
                     position + j, out[i].data[1 + j], data_[position + j]);
        } else {
          data_.push_back(out[i].data[1 + j]);
        }
      }
    }
    sent_ = static_cast<uint8_t>(n);
    last_sent_ = (out[n - 1].data[0] & 0x80) != 0;
    if (size_known_) {
      const size_t end = transferred_ + 7 * n;
      FUZZ_CHECK(last_sent_ ? size_ <= end && (size_ > end - 7 || size_ == 0) : n == block_size_ && size_ > end,
                 "a sub-block of %zu segments from byte %zu, c %d, size %zu", n, transferred_, last_sent_, size_);
    }
    state_ = State::kUploadBlockAck;
  }

  void acknowledge_upload_block(const uint8_t* d, const Frames& out) {
    const uint8_t acknowledged = d[1];
    const uint8_t next_block_size = d[2];
    if (acknowledged > sent_) return refused(out, mux_, canopen::SdoAbort::kInvalidSequence);
    if (next_block_size == 0 || next_block_size > 127) return refused(out, mux_, canopen::SdoAbort::kInvalidBlockSize);
    size_t advanced = 7u * acknowledged;
    if (size_known_ && advanced > size_ - transferred_) advanced = size_ - transferred_;
    transferred_ += advanced;
    block_size_ = next_block_size;
    if (!(acknowledged == sent_ && last_sent_)) return upload_sub_block(out);
    FUZZ_CHECK(out.size() == 1, "%zu responses to the last acknowledgement", out.size());
    const can::CanFrame& response = out[0];
    const uint8_t h = response.data[0];
    FUZZ_CHECK((h & 0xE3) == 0xC1 && zeros(response, 3), "block upload end %02x", h);
    if (size_known_) {
      const size_t in_last = size_ % 7 == 0 && size_ > 0 ? 7 : size_ % 7;
      FUZZ_CHECK(((h >> 2) & 0x07) == 7 - in_last, "block upload end: %u unused bytes, size %zu", (h >> 2) & 0x07,
                 size_);
      if (crc_) {
        const uint16_t crc = crc16_bitwise(data_.data(), size_);
        FUZZ_CHECK((response.data[1] | response.data[2] << 8) == crc, "block upload CRC %04x, the data's %04x",
                   response.data[1] | response.data[2] << 8, crc);
      }
    }
    state_ = State::kUploadBlockEnd;
  }

  Device& device_;
  uint8_t node_ = 0;
  bool serving_before_ = false;
  bool has_request_ = false;
  can::CanFrame request_{};
  uint32_t elapsed_us_ = 0;
  Snapshot snapshot_;

  State state_ = State::kIdle;
  uint64_t idle_us_ = 0;  // since the last request of the transfer
  Mux mux_;
  bool size_known_ = false;
  size_t size_ = 0;
  size_t transferred_ = 0;  // segmented: bytes so far; block upload: bytes acknowledged
  uint8_t toggle_ = 0;
  bool crc_ = false;
  uint8_t block_size_ = 0;
  uint8_t in_order_ = 0;  // block download: the last segment of the sub-block received in order
  uint8_t sent_ = 0;      // block upload: segments of the last sub-block
  bool last_sent_ = false;
  std::vector<uint8_t> data_;  // block download: the bytes received in order; upload: sent
};

// The value of a numeric object as an SDO upload gives it: the getter's value cut to the type's
// size and sign-extended (what TableDictionary::read encodes and decode_value reads back).
FUZZ_UNTRACED inline int64_t as_uploaded(canopen::DataType type, int64_t value) {
  const uint8_t size = canopen::type_size(type);
  if (size == 0 || size >= 8) return value;
  const uint64_t mask = (uint64_t{1} << (8 * size)) - 1;
  uint64_t bits = static_cast<uint64_t>(value) & mask;
  if (canopen::is_signed(type) && (bits & ((mask >> 1) + 1)) != 0) bits |= ~mask;
  return static_cast<int64_t>(bits);
}

// Every writable numeric object of every axis as TableDictionary::read and decode_value give it
// (the row itself, as find() answers for its index and sub-index: the dictionary's unit tests
// hold find() to that), in table order. The reference check_dictionary_ranges is held to.
template <class Device>
std::vector<int64_t> writable_values_as_read(Device& device) {
  std::vector<int64_t> values;
  auto& dictionary = device.dictionary();
  const auto rows = dictionary.rows();
  for (size_t row = 0; row < rows.size(); ++row) {
    const canopen::EntryInfo& info = rows[row].info;
    if (!canopen::is_numeric(info.type) || info.access != canopen::Access::kRw) continue;
    const uint8_t axes = info.axis_stride == 0 ? 1 : dictionary.axis_count();
    for (uint8_t axis = 0; axis < axes; ++axis) {
      const uint16_t index = static_cast<uint16_t>(info.index + axis * info.axis_stride);
      const canopen::ObjectRef ref{&info, row, index, axis};
      uint8_t bytes[8] = {};
      size_t length = 0;
      if (dictionary.read(ref, bytes, sizeof(bytes), length) != canopen::SdoAbort::kNone) continue;
      values.push_back(canopen::decode_value(info.type, bytes));
    }
  }
  return values;
}

// Every writable numeric object of every axis holds a value inside its row's range. The values
// come from each row's getter directly (what TableDictionary::value calls) and are cut to the
// type as an upload cuts them, and the loop is left out of libFuzzer's tracing (FUZZ_UNTRACED;
// the getters stay traced): reading through TableDictionary::read, decode_value and check_range
// traced a third of the CANopen targets' time and guides nothing, the values coming from the
// module. fuzz/README.md, Speed. The shortcut is checked, not assumed: on the first call of a
// process and then every 2^16th, the values must equal those that read() gives.
template <class Device>
FUZZ_UNTRACED void check_dictionary_ranges(Device& device) {
  static uint64_t calls = 0;
  const bool compare = calls++ % kRigComparisonPeriod == 0;
  std::vector<int64_t> checked;
  auto& dictionary = device.dictionary();
  const auto rows = dictionary.rows();
  for (size_t row = 0; row < rows.size(); ++row) {
    const canopen::EntryInfo& info = rows[row].info;
    if (!canopen::is_numeric(info.type) || info.access != canopen::Access::kRw) continue;
    const auto get = rows[row].binding.get;
    const uint8_t axes = info.axis_stride == 0 ? 1 : dictionary.axis_count();
    for (uint8_t axis = 0; axis < axes; ++axis) {
      const int64_t value =
          as_uploaded(info.type, get != nullptr ? get(device, axis) : dictionary.default_value(info, axis));
      if (compare) checked.push_back(value);
      if (value >= info.min && value <= info.max) continue;
      const uint16_t index = static_cast<uint16_t>(info.index + axis * info.axis_stride);
      FUZZ_CHECK(false, "object %04x sub %u (%.*s) holds %lld, range %lld..%lld", index, info.sub,
                 static_cast<int>(info.name.size()), info.name.data(), static_cast<long long>(value),
                 static_cast<long long>(info.min), static_cast<long long>(info.max));
    }
  }
  if (compare) {
    FUZZ_CHECK(checked == writable_values_as_read(device),
               "check_dictionary_ranges: the getters' values differ from what read() gives");
  }
}


// An expedited SDO download of `size` bytes (1 to 4) to node `node_id`; the bytes of `value` past
// `size` go out too (CiA-301 leaves them undefined: the server must ignore them).
inline can::CanFrame expedited_download(uint8_t node_id, uint16_t index, uint8_t sub, uint32_t value, uint8_t size) {
  can::CanFrame frame;
  frame.id = canopen::kSdoRequestCobIdBase + node_id;
  frame.dlc = 8;
  frame.data[0] = static_cast<uint8_t>(0x23 | ((4 - size) << 2));
  frame.data[1] = static_cast<uint8_t>(index);
  frame.data[2] = static_cast<uint8_t>(index >> 8);
  frame.data[3] = sub;
  for (int i = 0; i < 4; ++i) frame.data[4 + i] = static_cast<uint8_t>(value >> (8 * i));
  return frame;
}

// An expedited SDO download of `value` to index/sub with the size of its type (4 bytes for an
// object the table lacks or a string), as a master sends it.
template <class Device>
can::CanFrame expedited_download(Device& device, uint16_t index, uint8_t sub, int64_t value) {
  canopen::ObjectRef ref;
  uint8_t size = 4;
  if (ObjectLookup::of(device).find(index, sub, ref) && canopen::is_numeric(ref.info->type)) {
    size = canopen::type_size(ref.info->type);
    if (size > 4) size = 4;
  }
  const uint32_t bits = static_cast<uint32_t>(value) & (size == 4 ? 0xFFFF'FFFFu : (1u << (8 * size)) - 1);
  return expedited_download(device.node_id(), index, sub, bits, size);
}

// A raw SDO request a client could plausibly send: any command specifier and bytes (sometimes a
// short frame), mostly on a real object of the table, of one of `axes` axes (1: what the input
// picks for the axis is not consumed).
template <class Device>
can::CanFrame raw_sdo_request(FuzzedDataProvider& in, Device& device, int axes) {
  can::CanFrame frame;
  frame.id = canopen::kSdoRequestCobIdBase + device.node_id();
  frame.dlc = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegralInRange<uint8_t>(0, 8) : 8;
  for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
  if (in.ConsumeBool()) {
    const auto rows = device.dictionary().rows();
    const auto& info = rows[in.ConsumeIntegralInRange<size_t>(0, rows.size() - 1)].info;
    const uint16_t index = static_cast<uint16_t>(info.index + in.ConsumeIntegralInRange<int>(0, axes - 1) * info.axis_stride);
    frame.data[1] = static_cast<uint8_t>(index);
    frame.data[2] = static_cast<uint8_t>(index >> 8);
    frame.data[3] = info.sub;
  }
  return frame;
}

// An NMT command to a drive under test: mostly start (so that PDOs flow), sometimes stop,
// pre-operational, reset communication or (rarely) reset node, to this node or to all.
inline can::CanFrame drive_nmt_command(FuzzedDataProvider& in, uint8_t node_id) {
  can::CanFrame frame;
  frame.id = 0;
  frame.dlc = 2;
  const uint8_t commands[] = {0x01, 0x01, 0x01, 0x80, 0x02, 0x82, 0x81};
  frame.data[0] = commands[in.ConsumeIntegralInRange<int>(0, 6)];
  frame.data[1] = in.ConsumeBool() ? 0 : node_id;
  return frame;
}

// A frame on one of axis 0's four default RPDOs (6040; 6040+6060; 6040+607A; 6040+60FF): mostly
// 2, 3 or 6 bytes, a controlword of `controlwords` and, on RPDO 2, a mode of `modes`.
template <size_t kControlwordCount, size_t kModeCount>
can::CanFrame drive_rpdo_frame(FuzzedDataProvider& in, uint8_t node_id, const uint16_t (&controlwords)[kControlwordCount],
                               const int8_t (&modes)[kModeCount]) {
  can::CanFrame frame;
  frame.id = in.PickValueInArray({0x200u, 0x300u, 0x400u, 0x500u}) + node_id;
  frame.dlc = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? in.ConsumeIntegralInRange<uint8_t>(0, 8)
                                                         : in.PickValueInArray({2, 3, 6});
  for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
  const uint16_t cw = controlwords[in.ConsumeIntegralInRange<size_t>(0, kControlwordCount - 1)];
  frame.data[0] = static_cast<uint8_t>(cw);
  frame.data[1] = static_cast<uint8_t>(cw >> 8);
  if (frame.id == 0x300u + node_id) frame.data[2] = static_cast<uint8_t>(modes[frame.data[2] % kModeCount]);
  return frame;
}

// SYNC, sometimes with a counter byte.
inline can::CanFrame sync_frame(FuzzedDataProvider& in) {
  can::CanFrame frame;
  frame.id = 0x80;
  frame.dlc = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? 1 : 0;
  frame.data[0] = in.ConsumeIntegral<uint8_t>();
  return frame;
}

// Any 11-bit frame: any identifier, a remote frame now and then, any length and data.
inline can::CanFrame any_frame(FuzzedDataProvider& in) {
  can::CanFrame frame;
  frame.id = in.ConsumeIntegralInRange<uint32_t>(0, 0x7FF);
  frame.rtr = in.ConsumeIntegralInRange<int>(0, 7) == 0;
  frame.dlc = in.ConsumeIntegralInRange<uint8_t>(0, 8);
  for (auto& b : frame.data) b = in.ConsumeIntegral<uint8_t>();
  return frame;
}

// MOTWIN_FUZZ_TRACE=1 prints every frame in and out: for reading a saved crash input.
inline void trace(const char* direction, const can::CanFrame& frame) {
  static const bool enabled = std::getenv("MOTWIN_FUZZ_TRACE") != nullptr;
  if (!enabled) return;
  std::fprintf(stderr, "%s %03x [%u]", direction, frame.id, frame.dlc);
  for (uint8_t i = 0; i < frame.dlc && i < 8; ++i) std::fprintf(stderr, " %02x", frame.data[i]);
  std::fprintf(stderr, "\n");
}


}  // namespace motwin::fuzz

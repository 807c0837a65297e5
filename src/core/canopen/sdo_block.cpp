// SDO block transfer (CiA-301 7.2.4.3.9 - 7.2.4.3.16), the part of SdoServer that moves data in
// sub-blocks of up to 127 segments, each segment `last << 7 | seqno` followed by 7 data bytes,
// acknowledged per sub-block with the last sequence number received in order. Both directions
// end with the number of unused bytes of the last segment and, when both sides support it, the
// CRC of the data. A download passes whole through buffer_; an upload longer than buffer_ streams
// through it in windows that each hold at least one whole sub-block, so that a sub-block can be
// sent again after a partial acknowledgement.
#include <array>

#include "core/canopen/sdo_server.h"

namespace motwin::canopen {
namespace {

constexpr uint8_t kCrcSupported = 0x04;     // cc / sc bit of the initiate frames
constexpr uint8_t kSizeIndicated = 0x02;    // s bit
constexpr uint8_t kLastSegment = 0x80;      // c bit of a segment
constexpr uint8_t kSequenceMask = 0x7F;
constexpr size_t kSegmentData = 7;

// Server command bytes (scs << 5 | flags).
constexpr uint8_t kDownloadInitiateResponse = 0xA0 | kCrcSupported;  // scs 5, ss 0
constexpr uint8_t kDownloadEndResponse = 0xA1;                       // scs 5, ss 1
constexpr uint8_t kDownloadSubBlockResponse = 0xA2;                  // scs 5, ss 2
constexpr uint8_t kUploadInitiateResponse = 0xC0 | kCrcSupported | kSizeIndicated;  // scs 6, ss 0
constexpr uint8_t kUploadEndRequest = 0xC1;                                          // scs 6, ss 1
// Client sub-commands of ccs 5 (block upload).
constexpr uint8_t kUploadEnd = 1;
constexpr uint8_t kUploadAck = 2;
constexpr uint8_t kUploadStart = 3;
constexpr uint8_t kInitiateUploadRequest = 0x40;  // ccs 2: what a protocol switch answers

uint32_t le32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}

// CRC-16/CCITT one byte at a time: entry b is the CRC register after shifting b through the
// polynomial 0x1021 bit by bit (512 bytes of flash instead of 8 shifts per byte).
constexpr std::array<uint16_t, 256> make_crc16_table() {
  std::array<uint16_t, 256> table{};
  for (unsigned byte = 0; byte < 256; ++byte) {
    auto crc = static_cast<uint16_t>(byte << 8);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x8000) != 0 ? static_cast<uint16_t>((crc << 1) ^ 0x1021) : static_cast<uint16_t>(crc << 1);
    }
    table[byte] = crc;
  }
  return table;
}
constexpr std::array<uint16_t, 256> kCrc16Table = make_crc16_table();

}  // namespace

uint16_t crc16_ccitt(const uint8_t* data, size_t length, uint16_t crc) {
  for (size_t i = 0; i < length; ++i) {
    crc = static_cast<uint16_t>((crc << 8) ^ kCrc16Table[((crc >> 8) ^ data[i]) & 0xFF]);
  }
  return crc;
}

// --- Download ------------------------------------------------------------------------------------

void SdoServer::initiate_block_download(const uint8_t* data) {
  if (!open_object(data, Direction::kDownload)) return;
  size_indicated_ = (data[0] & kSizeIndicated) != 0;
  size_ = size_indicated_ ? le32(data + 4) : 0;
  const size_t object_size = dictionary_.size(object_);
  if (size_indicated_ && is_numeric(object_.info->type) && size_ != object_size) {
    abort(index_, sub_, size_ > object_size ? SdoAbort::kDataTooLong : SdoAbort::kDataTooShort);
    return;
  }
  if (size_ > kBufferSize) {
    abort(index_, sub_, SdoAbort::kDataTooLong);
    return;
  }
  block_crc_ = (data[0] & kCrcSupported) != 0;
  block_size_ = kMaxBlockSize;
  block_sequence_ = 0;
  offset_ = 0;
  state_ = SdoState::kDownloadBlock;
  const uint8_t response[8] = {kDownloadInitiateResponse, data[1], data[2], data[3], block_size_, 0, 0, 0};
  respond(response);
}

void SdoServer::download_block_segment(const uint8_t* data) {
  const uint8_t sequence = data[0] & kSequenceMask;
  const bool last = (data[0] & kLastSegment) != 0;
  if (sequence == 0 || sequence > block_size_) {
    abort(index_, sub_, SdoAbort::kInvalidSequence);
    return;
  }
  if (sequence == block_sequence_ + 1) {
    // All 7 bytes are kept; the end request says how many of the last segment are padding.
    // A segment beyond the announced size (an empty value still takes one segment) or the buffer.
    const size_t limit = size_indicated_ ? (size_ == 0 ? 1 : size_) : kBufferSize;
    if (offset_ >= limit) {
      abort(index_, sub_, size_indicated_ ? SdoAbort::kTypeMismatch : SdoAbort::kDataTooLong);
      return;
    }
    for (size_t i = 0; i < kSegmentData; ++i) {
      if (offset_ + i < kBufferSize) buffer_[offset_ + i] = data[1 + i];
    }
    offset_ += kSegmentData;
    block_sequence_ = sequence;
    if (!last && sequence < block_size_) return;  // more of this sub-block to come
  } else if (!last && sequence < block_size_) {
    return;  // out of order: ignored; the acknowledgement at the end of the sub-block says where to resume
  }
  // End of the sub-block (or the last segment): acknowledge what arrived in order.
  const bool complete = last && sequence == block_sequence_;
  const uint8_t response[8] = {kDownloadSubBlockResponse, block_sequence_, kMaxBlockSize, 0, 0, 0, 0, 0};
  block_size_ = kMaxBlockSize;
  block_sequence_ = 0;
  if (complete) state_ = SdoState::kDownloadBlockEnd;
  respond(response);
}

void SdoServer::end_block_download(const uint8_t* data) {
  const size_t unused = (data[0] >> 2) & 0x07;
  // Seven unused bytes only for an empty value (its one segment carries nothing).
  if (offset_ < unused || (unused == kSegmentData && offset_ != kSegmentData)) {
    abort(index_, sub_, SdoAbort::kTypeMismatch);
    return;
  }
  const size_t length = offset_ - unused;
  if (length > kBufferSize) {
    abort(index_, sub_, SdoAbort::kDataTooLong);
    return;
  }
  if (size_indicated_ && length != size_) {
    abort(index_, sub_, SdoAbort::kTypeMismatch);
    return;
  }
  if (block_crc_) {
    const uint16_t crc = static_cast<uint16_t>(data[1] | data[2] << 8);
    if (crc != crc16_ccitt(buffer_, length)) {
      abort(index_, sub_, SdoAbort::kCrc);
      return;
    }
  }
  state_ = SdoState::kIdle;
  if (const SdoAbort written = dictionary_.write(object_, buffer_, length); written != SdoAbort::kNone) {
    abort(index_, sub_, written);
    return;
  }
  const uint8_t response[8] = {kDownloadEndResponse, 0, 0, 0, 0, 0, 0, 0};
  respond(response);
}

// --- Upload --------------------------------------------------------------------------------------

void SdoServer::initiate_block_upload(const uint8_t* data) {
  if (!open_object(data, Direction::kUpload)) return;
  const uint8_t requested_block_size = data[4];
  const uint8_t switch_threshold = data[5];
  if (requested_block_size == 0 || requested_block_size > kMaxBlockSize) {
    abort(index_, sub_, SdoAbort::kInvalidBlockSize);
    return;
  }
  size_t length = 0;
  if (const SdoAbort read = load_upload(length); read != SdoAbort::kNone) {
    abort(index_, sub_, read);
    return;
  }
  // Protocol switch threshold: a client that allows it gets an object of at most `pst` bytes
  // by the normal upload (CiA-301 7.2.4.3.13); pst 0 (python-canopen) means block transfer always.
  if (switch_threshold != 0 && length <= switch_threshold) {
    const uint8_t normal[8] = {kInitiateUploadRequest, data[1], data[2], data[3], 0, 0, 0, 0};
    initiate_upload(normal);
    return;
  }
  size_ = length;
  offset_ = 0;
  block_crc_ = (data[0] & kCrcSupported) != 0;
  block_size_ = requested_block_size;
  block_sequence_ = 0;
  upload_crc_ = 0;
  state_ = SdoState::kUploadBlockStart;
  const uint8_t response[8] = {kUploadInitiateResponse,
                               data[1],
                               data[2],
                               data[3],
                               static_cast<uint8_t>(length),
                               static_cast<uint8_t>(length >> 8),
                               static_cast<uint8_t>(length >> 16),
                               static_cast<uint8_t>(length >> 24)};
  respond(response);
}

void SdoServer::upload_block_request(const uint8_t* data) {
  const uint8_t subcommand = data[0] & 0x03;
  if (state_ == SdoState::kUploadBlockStart && subcommand == kUploadStart) {
    send_upload_sub_block();
    return;
  }
  if (state_ == SdoState::kUploadBlockAck && subcommand == kUploadAck) {
    const uint8_t acknowledged = data[1];
    const uint8_t next_block_size = data[2];
    if (acknowledged > block_sequence_) {
      abort(index_, sub_, SdoAbort::kInvalidSequence);
      return;
    }
    if (next_block_size == 0 || next_block_size > kMaxBlockSize) {
      abort(index_, sub_, SdoAbort::kInvalidBlockSize);
      return;
    }
    // Segments after `acknowledged` are sent again in the next sub-block. The acknowledged
    // bytes are still in the window (it holds the whole sub-block just sent).
    size_t advanced = static_cast<size_t>(acknowledged) * kSegmentData;
    if (advanced > size_ - offset_) advanced = size_ - offset_;
    if (block_crc_) upload_crc_ = crc16_ccitt(window_data(offset_), advanced, upload_crc_);
    offset_ += advanced;
    block_size_ = next_block_size;
    const bool all_acknowledged = acknowledged == block_sequence_ && offset_ == size_;
    if (!all_acknowledged) {
      send_upload_sub_block();
      return;
    }
    const size_t in_last = size_ % kSegmentData == 0 && size_ > 0 ? kSegmentData : size_ % kSegmentData;
    const uint16_t crc = block_crc_ ? upload_crc_ : 0;
    const uint8_t end[8] = {static_cast<uint8_t>(kUploadEndRequest | ((kSegmentData - in_last) << 2)),
                            static_cast<uint8_t>(crc),
                            static_cast<uint8_t>(crc >> 8),
                            0,
                            0,
                            0,
                            0,
                            0};
    state_ = SdoState::kUploadBlockEnd;
    respond(end);
    return;
  }
  if (state_ == SdoState::kUploadBlockEnd && subcommand == kUploadEnd) {
    state_ = SdoState::kIdle;  // the client confirms: transfer done, nothing to answer
    return;
  }
  abort(index_, sub_, SdoAbort::kUnknownCommand);
}

void SdoServer::send_upload_sub_block() {
  // Segments from offset_ on, at most block_size_ of them; an empty object is one empty last segment.
  if (const SdoAbort read = cover(offset_, static_cast<size_t>(block_size_) * kSegmentData);
      read != SdoAbort::kNone) {
    abort(index_, sub_, read);
    return;
  }
  const uint8_t* bytes = window_data(offset_);
  uint8_t sequence = 0;
  size_t position = offset_;
  do {
    const size_t remaining = size_ - position;
    const size_t length = remaining < kSegmentData ? remaining : kSegmentData;
    ++sequence;
    const bool last = position + length == size_;
    uint8_t segment[8] = {static_cast<uint8_t>(sequence | (last ? kLastSegment : 0)), 0, 0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < length; ++i) segment[1 + i] = bytes[position - offset_ + i];
    position += length;
    respond(segment);
    if (last) break;
  } while (sequence < block_size_);
  block_sequence_ = sequence;
  state_ = SdoState::kUploadBlockAck;
}

}  // namespace motwin::canopen

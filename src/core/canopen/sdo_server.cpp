#include "core/canopen/sdo_server.h"

namespace motwin::canopen {
namespace {

// Client command specifiers (byte 0 bits 7..5).
constexpr uint8_t kCcsDownloadSegment = 0;
constexpr uint8_t kCcsInitiateDownload = 1;
constexpr uint8_t kCcsInitiateUpload = 2;
constexpr uint8_t kCcsUploadSegment = 3;
constexpr uint8_t kCcsAbort = 4;
constexpr uint8_t kCcsBlockUpload = 5;
constexpr uint8_t kCcsBlockDownload = 6;
constexpr uint8_t kToggleBit = 0x10;

}  // namespace

void SdoServer::on_request(const can::CanFrame& frame) {
  if (request_pending_) {
    ++dropped_requests_;
    return;
  }
  request_ = frame;
  request_pending_ = true;
}

void SdoServer::reset() {
  state_ = SdoState::kIdle;
  request_pending_ = false;
  idle_us_ = 0;
}

uint16_t SdoServer::multiplexer_index(const uint8_t* data) { return static_cast<uint16_t>(data[1] | data[2] << 8); }

void SdoServer::process(uint32_t elapsed_us) {
  if (request_pending_) {
    request_pending_ = false;
    idle_us_ = 0;
    handle(request_);
    return;
  }
  if (state_ == SdoState::kIdle) return;
  idle_us_ += elapsed_us;
  if (idle_us_ >= kTimeoutUs) abort(index_, sub_, SdoAbort::kTimeout);
}

void SdoServer::handle(const can::CanFrame& request) {
  if (request.rtr) return;  // RTR is not supported (manual 1.1); nothing to answer
  uint8_t data[8] = {};
  for (uint8_t i = 0; i < request.dlc && i < 8; ++i) data[i] = request.data[i];
  // Inside a block download sub-block every frame is a segment (seqno | last bit); only 0x80
  // (sequence number 0) cannot be one and is the client's abort.
  const bool block_segment = state_ == SdoState::kDownloadBlock && data[0] != 0x80;
  const uint8_t ccs = data[0] >> 5;
  if (!block_segment && ccs == kCcsAbort) {  // the client gives up: no answer
    state_ = SdoState::kIdle;
    return;
  }
  // SDO frames always carry 8 bytes (CiA-301 7.2.4.3); a shorter one cannot be parsed reliably.
  if (request.dlc != 8) {
    const bool in_transfer = state_ != SdoState::kIdle;
    abort(in_transfer ? index_ : 0, in_transfer ? sub_ : 0, SdoAbort::kUnknownCommand);
    return;
  }
  if (block_segment) {
    download_block_segment(data);
    return;
  }
  const uint8_t subcommand = data[0] & 0x03;  // block transfer: cs / ss
  switch (ccs) {
    case kCcsInitiateDownload: initiate_download(data); return;  // also ends a stale transfer
    case kCcsInitiateUpload: initiate_upload(data); return;
    case kCcsDownloadSegment:
      if (state_ == SdoState::kDownloadSegments) {
        download_segment(data);
        return;
      }
      break;
    case kCcsUploadSegment:
      if (state_ == SdoState::kUploadSegments) {
        upload_segment(data);
        return;
      }
      break;
    case kCcsBlockDownload:
      if ((data[0] & 0x01) == 0) {
        initiate_block_download(data);
        return;
      }
      if (state_ == SdoState::kDownloadBlockEnd) {
        end_block_download(data);
        return;
      }
      break;
    case kCcsBlockUpload:
      if (subcommand == 0) {
        initiate_block_upload(data);
        return;
      }
      if (state_ == SdoState::kUploadBlockStart || state_ == SdoState::kUploadBlockAck ||
          state_ == SdoState::kUploadBlockEnd) {
        upload_block_request(data);
        return;
      }
      break;
    default: break;  // 7: not defined
  }
  if (state_ == SdoState::kIdle) {
    abort(0, 0, SdoAbort::kUnknownCommand);
  } else {
    abort(index_, sub_, SdoAbort::kUnknownCommand);
  }
}

bool SdoServer::open_object(const uint8_t* data, Direction direction) {
  state_ = SdoState::kIdle;
  index_ = multiplexer_index(data);
  sub_ = data[3];
  if (const SdoAbort found = dictionary_.find(index_, sub_, object_); found != SdoAbort::kNone) {
    abort(index_, sub_, found);
    return false;
  }
  if (direction == Direction::kDownload && !writable(object_.info->access)) {
    abort(index_, sub_, SdoAbort::kReadOnly);
    return false;
  }
  return true;
}

void SdoServer::initiate_download(const uint8_t* data) {
  if (!open_object(data, Direction::kDownload)) return;
  const bool expedited = (data[0] & 0x02) != 0;
  const bool size_indicated = (data[0] & 0x01) != 0;
  const size_t object_size = dictionary_.size(object_);
  if (expedited) {
    size_t length = size_indicated ? 4u - ((data[0] >> 2) & 0x03) : 4u;
    // Size not indicated: the object's own size (CiA-301 allows it; CANopenNode does the same).
    if (!size_indicated && is_numeric(object_.info->type) && object_size < length) length = object_size;
    if (const SdoAbort written = dictionary_.write(object_, data + 4, length); written != SdoAbort::kNone) {
      abort(index_, sub_, written);
      return;
    }
    const uint8_t response[8] = {0x60, data[1], data[2], data[3], 0, 0, 0, 0};
    respond(response);
    return;
  }
  size_indicated_ = size_indicated;
  size_ = size_indicated ? static_cast<size_t>(data[4] | data[5] << 8 | data[6] << 16) |
                               static_cast<size_t>(data[7]) << 24
                         : 0;
  if (size_indicated && is_numeric(object_.info->type) && size_ != object_size) {
    abort(index_, sub_, size_ > object_size ? SdoAbort::kDataTooLong : SdoAbort::kDataTooShort);
    return;
  }
  if (size_ > kBufferSize) {
    abort(index_, sub_, SdoAbort::kDataTooLong);
    return;
  }
  offset_ = 0;
  toggle_ = 0;
  state_ = SdoState::kDownloadSegments;
  const uint8_t response[8] = {0x60, data[1], data[2], data[3], 0, 0, 0, 0};
  respond(response);
}

void SdoServer::download_segment(const uint8_t* data) {
  if ((data[0] & kToggleBit) != toggle_) {
    abort(index_, sub_, SdoAbort::kToggleBit);
    return;
  }
  const size_t length = 7u - ((data[0] >> 1) & 0x07);
  const bool last = (data[0] & 0x01) != 0;
  if (offset_ + length > kBufferSize || (size_indicated_ && offset_ + length > size_)) {
    abort(index_, sub_, size_indicated_ ? SdoAbort::kTypeMismatch : SdoAbort::kDataTooLong);
    return;
  }
  for (size_t i = 0; i < length; ++i) buffer_[offset_ + i] = data[1 + i];
  offset_ += length;
  const uint8_t response[8] = {static_cast<uint8_t>(0x20 | toggle_), 0, 0, 0, 0, 0, 0, 0};
  if (!last) {
    toggle_ ^= kToggleBit;
    respond(response);
    return;
  }
  state_ = SdoState::kIdle;
  if (size_indicated_ && offset_ != size_) {
    abort(index_, sub_, SdoAbort::kTypeMismatch);
    return;
  }
  if (const SdoAbort written = dictionary_.write(object_, buffer_, offset_); written != SdoAbort::kNone) {
    abort(index_, sub_, written);
    return;
  }
  respond(response);
}

void SdoServer::initiate_upload(const uint8_t* data) {
  if (!open_object(data, Direction::kUpload)) return;
  size_t length = 0;
  if (const SdoAbort read = load_upload(length); read != SdoAbort::kNone) {
    abort(index_, sub_, read);
    return;
  }
  if (length <= 4 && length > 0) {
    uint8_t response[8] = {static_cast<uint8_t>(0x43 | ((4 - length) << 2)), data[1], data[2], data[3], 0, 0, 0, 0};
    for (size_t i = 0; i < length; ++i) response[4 + i] = buffer_[i];
    respond(response);
    return;
  }
  // Segmented (an empty string too: size 0, then one last segment without data).
  size_ = length;
  offset_ = 0;
  toggle_ = 0;
  state_ = SdoState::kUploadSegments;
  const uint8_t response[8] = {0x41,
                               data[1],
                               data[2],
                               data[3],
                               static_cast<uint8_t>(length),
                               static_cast<uint8_t>(length >> 8),
                               static_cast<uint8_t>(length >> 16),
                               static_cast<uint8_t>(length >> 24)};
  respond(response);
}

void SdoServer::upload_segment(const uint8_t* data) {
  if ((data[0] & kToggleBit) != toggle_) {
    abort(index_, sub_, SdoAbort::kToggleBit);
    return;
  }
  const size_t remaining = size_ - offset_;
  const size_t length = remaining < 7 ? remaining : 7;
  if (const SdoAbort read = cover(offset_, length); read != SdoAbort::kNone) {
    abort(index_, sub_, read);
    return;
  }
  const bool last = offset_ + length == size_;
  uint8_t response[8] = {static_cast<uint8_t>(toggle_ | ((7 - length) << 1) | (last ? 1 : 0)), 0, 0, 0, 0, 0, 0, 0};
  const uint8_t* bytes = window_data(offset_);
  for (size_t i = 0; i < length; ++i) response[1 + i] = bytes[i];
  offset_ += length;
  toggle_ ^= kToggleBit;
  if (last) state_ = SdoState::kIdle;
  respond(response);
}

SdoAbort SdoServer::load_upload(size_t& total) {
  total = dictionary_.size(object_);
  window_start_ = 0;
  window_length_ = 0;
  streaming_ = total > kBufferSize;
  if (streaming_) {
    size_ = total;  // cover() clips to it
    return cover(0, kBufferSize);
  }
  size_t length = 0;
  const SdoAbort read = dictionary_.read(object_, buffer_, kBufferSize, length);
  if (read != SdoAbort::kNone) return read;
  total = length;
  window_length_ = length;
  return SdoAbort::kNone;
}

SdoAbort SdoServer::cover(size_t position, size_t length) {
  if (position + length > size_) length = size_ - position;
  if (position >= window_start_ && position + length <= window_start_ + window_length_) return SdoAbort::kNone;
  if (!streaming_) return SdoAbort::kGeneral;  // cannot happen: a buffered value is whole
  const size_t wanted = size_ - position < kBufferSize ? size_ - position : kBufferSize;
  size_t read_length = 0;
  const SdoAbort read = dictionary_.read_part(object_, position, buffer_, wanted, read_length);
  if (read != SdoAbort::kNone) return read;
  // A value that shrank under the transfer cannot deliver the announced size.
  if (read_length < length) return SdoAbort::kGeneral;
  window_start_ = position;
  window_length_ = read_length;
  return SdoAbort::kNone;
}

void SdoServer::abort(uint16_t index, uint8_t sub, SdoAbort abort_code) {
  state_ = SdoState::kIdle;
  const uint32_t c = code(abort_code);
  const uint8_t response[8] = {0x80,
                               static_cast<uint8_t>(index),
                               static_cast<uint8_t>(index >> 8),
                               sub,
                               static_cast<uint8_t>(c),
                               static_cast<uint8_t>(c >> 8),
                               static_cast<uint8_t>(c >> 16),
                               static_cast<uint8_t>(c >> 24)};
  respond(response);
}

void SdoServer::respond(const uint8_t (&data)[8]) {
  const can::CanFrame frame = can::make_frame(kSdoResponseCobIdBase + node_id_, data, 8);
  can_.transmit(frame);
}

}  // namespace motwin::canopen

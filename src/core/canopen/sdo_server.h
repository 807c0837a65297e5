// SDO server (CiA-301 7.2.4): expedited, segmented and block transfer in both directions, in the
// shape of CANopenNode's CO_SDOserver: a request is queued by on_request() and answered by the
// next process() call, which is also told how much time passed (the transfer timeout). The block
// transfer half lives in sdo_block.cpp.
//
// States (explicit, as CO_SDO_ST_*):
//   kIdle               waiting for an initiate request
//   kDownloadSegments   segmented download: waiting for the next download segment
//   kUploadSegments     segmented upload: waiting for the next upload segment request
//   kDownloadBlock      block download: receiving the segments of a sub-block
//   kDownloadBlockEnd   block download: all data received, waiting for the end request (CRC)
//   kUploadBlockStart   block upload: initiate answered, waiting for the start request (A3)
//   kUploadBlockAck     block upload: a sub-block sent, waiting for its acknowledgement (A2)
//   kUploadBlockEnd     block upload: end sent, waiting for the client's end response (A1)
// Every error answers with an abort frame and returns to kIdle:
//   request in kIdle that is not an initiate (segment, ccs 7)           05040001
//   segment with the wrong toggle bit                                   05030000
//   no request for kTimeoutUs in any transfer state                     05040000
//   block size 0 or above 127 (upload initiate, upload acknowledgement) 05040002
//   sequence number 0 or above the block size; ackseq above the sent   05040003
//   CRC of a block download different from the data                     05040004
//   object / sub-index missing, access, size, range, state              from the dictionary
//   segmented or block download whose bytes differ from the announced   06070010
#pragma once

#include <cstddef>
#include <cstdint>

#include "board/can_controller.h"
#include "core/canopen/object_dictionary.h"
#include "types/can_frame.h"

namespace motwin::canopen {

inline constexpr uint32_t kSdoRequestCobIdBase = 0x600;   // client -> server
inline constexpr uint32_t kSdoResponseCobIdBase = 0x580;  // server -> client

enum class SdoState : uint8_t {
  kIdle,
  kDownloadSegments,
  kUploadSegments,
  kDownloadBlock,
  kDownloadBlockEnd,
  kUploadBlockStart,
  kUploadBlockAck,
  kUploadBlockEnd,
};

// CRC-16 of CiA-301 block transfer: CCITT polynomial 0x1021, initial value 0, no reflection.
uint16_t crc16_ccitt(const uint8_t* data, size_t length, uint16_t crc = 0);

class SdoServer {
 public:
  // CANopenNode's default server timeout; python-canopen's client waits 0.3 s per response.
  static constexpr uint32_t kTimeoutUs = 1'000'000;
  // Largest value a segmented or block download carries, and the window through which longer
  // values stream on upload (ObjectDictionary::read_part). The TMCM-3216's longest object is a
  // short visible string; the room is for larger objects and whole sub-blocks (127 x 7 bytes).
  static constexpr size_t kBufferSize = 1024;
  // Segments per sub-block the server asks for in a block download (CiA-301 maximum).
  static constexpr uint8_t kMaxBlockSize = 127;

  SdoServer(ObjectDictionary& dictionary, board::CanController& can) : dictionary_(dictionary), can_(can) {}

  void set_node_id(uint8_t node_id) { node_id_ = node_id; }
  uint32_t request_cob_id() const { return kSdoRequestCobIdBase + node_id_; }

  // A frame received on 0x600 + node ID. Handled by the next process(); if one is already
  // waiting, the newer one is dropped (a client waits for each answer).
  void on_request(const can::CanFrame& frame);
  // Answers a pending request; aborts a transfer that timed out.
  void process(uint32_t elapsed_us);
  // Back to kIdle without a frame (NMT stopped, resets).
  void reset();

  SdoState state() const { return state_; }
  uint64_t dropped_requests() const { return dropped_requests_; }

 private:
  static uint16_t multiplexer_index(const uint8_t* data);
  void handle(const can::CanFrame& request);
  // Every initiation's start: the server goes idle, the request's multiplexer becomes the
  // transfer's object. False, after the abort, when the object does not exist or a download's is
  // not writable.
  enum class Direction : uint8_t { kUpload, kDownload };
  bool open_object(const uint8_t* data, Direction direction);
  void initiate_download(const uint8_t* data);
  void download_segment(const uint8_t* data);
  void initiate_upload(const uint8_t* data);
  void upload_segment(const uint8_t* data);
  // Block transfer (sdo_block.cpp). `data` is the request (8 bytes).
  void initiate_block_download(const uint8_t* data);
  void download_block_segment(const uint8_t* data);
  void end_block_download(const uint8_t* data);
  void initiate_block_upload(const uint8_t* data);
  void upload_block_request(const uint8_t* data);
  void send_upload_sub_block();
  // Upload of size_ bytes: buffer_ holds bytes [window_start_, window_start_ + window_length_).
  // Loads the value (whole, or its first window when it is longer than the buffer).
  SdoAbort load_upload(size_t& total);
  // Makes the window cover [position, position + length) (clipped to size_), reading from
  // `position` on when it does not; the bytes at `position` are then at window_data(position).
  SdoAbort cover(size_t position, size_t length);
  const uint8_t* window_data(size_t position) const { return buffer_ + (position - window_start_); }
  void abort(uint16_t index, uint8_t sub, SdoAbort code);
  void respond(const uint8_t (&data)[8]);

  ObjectDictionary& dictionary_;
  board::CanController& can_;
  uint8_t node_id_ = 1;

  SdoState state_ = SdoState::kIdle;
  bool request_pending_ = false;
  can::CanFrame request_{};
  uint64_t idle_us_ = 0;   // time since the last request of the current transfer
  uint64_t dropped_requests_ = 0;

  // The transfer in progress.
  ObjectRef object_{};
  uint16_t index_ = 0;
  uint8_t sub_ = 0;
  uint8_t toggle_ = 0;       // expected toggle bit (0 or 0x10)
  bool size_indicated_ = false;
  size_t size_ = 0;          // announced (download) or total (upload) size
  size_t offset_ = 0;        // bytes received or sent so far
  uint8_t buffer_[kBufferSize] = {};
  size_t window_start_ = 0;
  size_t window_length_ = 0;
  bool streaming_ = false;   // the upload is longer than buffer_ and read in windows
  uint16_t upload_crc_ = 0;  // block upload: CRC of the bytes acknowledged so far
  // Block transfer: whether both sides use the CRC, segments per sub-block, the last sequence
  // number received in order (download) or sent (upload).
  bool block_crc_ = false;
  uint8_t block_size_ = 0;
  uint8_t block_sequence_ = 0;
};

}  // namespace motwin::canopen

// SDO server (CiA-301 7.2.4): expedited and segmented transfer in both directions, in the shape
// of CANopenNode's CO_SDOserver: a request is queued by on_request() and answered by the next
// process() call, which is also told how much time passed (the transfer timeout). Block
// transfer is not implemented yet: its requests are aborted with 05040001, which python-canopen
// and CANopenNode clients take as "fall back to segmented" (notes/canopen.md).
//
// States (explicit, as CO_SDO_ST_*):
//   kIdle              waiting for an initiate request
//   kDownloadSegments  segmented download: waiting for the next download segment
//   kUploadSegments    segmented upload: waiting for the next upload segment request
// Every error answers with an abort frame and returns to kIdle:
//   request in kIdle that is not an initiate (segment, unknown ccs, block) 05040001
//   segment with the wrong toggle bit                                   05030000
//   no request for kTimeoutUs in a segment state                        05040000
//   object / sub-index missing, access, size, range, state              from the dictionary
//   segmented download whose bytes differ from the size it announced   06070010
#pragma once

#include <cstddef>
#include <cstdint>

#include "board/can_controller.h"
#include "core/can/can_frame.h"
#include "core/canopen/object_dictionary.h"

namespace motwin::canopen {

inline constexpr uint32_t kSdoRequestCobIdBase = 0x600;   // client -> server
inline constexpr uint32_t kSdoResponseCobIdBase = 0x580;  // server -> client

enum class SdoState : uint8_t { kIdle, kDownloadSegments, kUploadSegments };

class SdoServer {
 public:
  // CANopenNode's default server timeout; python-canopen's client waits 0.3 s per response.
  static constexpr uint32_t kTimeoutUs = 1'000'000;
  // Largest value a segmented transfer carries (the longest object is a visible string).
  static constexpr size_t kBufferSize = 64;

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
  void handle(const can::CanFrame& request);
  void initiate_download(const uint8_t* data);
  void download_segment(const uint8_t* data);
  void initiate_upload(const uint8_t* data);
  void upload_segment(const uint8_t* data);
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
};

}  // namespace motwin::canopen

// The virtual CAN bus on device-like endpoints (docs/canopen.md, "Bus options"):
//   SlcanPtyEndpoint   `--can slcan:LINK`: a Lawicel adapter on a pseudo-terminal, LINK a
//                      symbolic link to it (python-can interface='slcan', channel=LINK; slcand).
//                      One adapter, whoever has the pty open; its channel state (O/C) persists
//                      across clients, as on a USB dongle that stays plugged in.
//   SocketcanEndpoint  `--can socketcan:IFACE`: a raw CAN socket on a Linux interface (vcan0,
//                      can0): the bus's frames go out there and the interface's frames come in.
//                      Where the kernel has no AF_CAN (containers, this project's CI), open()
//                      fails with a message saying so.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "host/can_bus.h"
#include "host/eeprom_file.h"
#include "host/event_loop.h"
#include "host/pty_device.h"
#include "host/slcan_protocol.h"
#include "types/can_frame.h"
#include "types/result.h"

namespace motwin::host {

class SlcanPtyEndpoint final : public CanBusEndpoint {
 public:
  // Frames nobody reads pile up in the pty, then here; beyond this they are dropped, as a
  // dongle's buffer overflows.
  static constexpr size_t kMaxPendingOutputBytes = 256 * 1024;

  static Result<std::unique_ptr<SlcanPtyEndpoint>> open(EventLoop& loop, CanBus& bus, const std::string& link_path,
                                                        LogSink log = log_to_stderr);
  SlcanPtyEndpoint(const SlcanPtyEndpoint&) = delete;
  SlcanPtyEndpoint& operator=(const SlcanPtyEndpoint&) = delete;
  ~SlcanPtyEndpoint();

  const std::string& link_path() const { return port_->link_path(); }
  const std::string& device_path() const { return port_->device_path(); }
  const SlcanSession& session() const { return session_; }
  uint64_t dropped_frames() const { return dropped_frames_; }

  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override;

 private:
  SlcanPtyEndpoint(EventLoop& loop, CanBus& bus, const PtyDevice& device, std::string link_path, LogSink log);
  void on_data(const uint8_t* bytes, size_t length);
  void write(const std::string& text);

  CanBus& bus_;
  CanBus::EndpointId bus_id_ = 0;
  SlcanSession session_;
  std::vector<can::CanFrame> outgoing_;
  uint64_t dropped_frames_ = 0;
  std::unique_ptr<PtyPort> port_;
};

class SocketcanEndpoint final : public CanBusEndpoint {
 public:
  static Result<std::unique_ptr<SocketcanEndpoint>> open(EventLoop& loop, CanBus& bus, const std::string& interface,
                                                         LogSink log = log_to_stderr);
  SocketcanEndpoint(const SocketcanEndpoint&) = delete;
  SocketcanEndpoint& operator=(const SocketcanEndpoint&) = delete;
  ~SocketcanEndpoint();

  const std::string& interface_name() const { return interface_; }
  uint64_t dropped_frames() const { return dropped_frames_; }
  void on_frame(const can::CanFrame& frame, uint64_t timestamp_us) override;

 private:
  SocketcanEndpoint(EventLoop& loop, CanBus& bus, int fd, std::string interface, LogSink log);
  void read_some();

  EventLoop& loop_;
  CanBus& bus_;
  CanBus::EndpointId bus_id_ = 0;
  int fd_;
  std::string interface_;
  LogSink log_;
  uint64_t dropped_frames_ = 0;
};

}  // namespace motwin::host

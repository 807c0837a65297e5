#include "host/can_device_endpoints.h"

#include <cerrno>
#include <cstring>

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include "host/pty_device.h"

namespace motwin::host {
namespace {

constexpr size_t kPtyReadBudget = 4096;
constexpr size_t kMaxFramesPerRead = 64;

}  // namespace

// --- SLCAN on a pseudo-terminal -------------------------------------------------------------

Result<std::unique_ptr<SlcanPtyEndpoint>> SlcanPtyEndpoint::open(EventLoop& loop, CanBus& bus,
                                                                 const std::string& link_path, LogSink log) {
  const Result<PtyDevice> pty = open_pty_device(link_path);
  if (!pty) return Error{pty.error()};
  return std::unique_ptr<SlcanPtyEndpoint>(new SlcanPtyEndpoint(loop, bus, *pty, link_path, std::move(log)));
}

SlcanPtyEndpoint::SlcanPtyEndpoint(EventLoop& loop, CanBus& bus, const PtyDevice& device, std::string link_path,
                                   LogSink log)
    : bus_(bus), session_([this](const can::CanFrame& frame) { outgoing_.push_back(frame); }) {
  PtyPort::Handlers handlers;
  handlers.read_budget = [] { return size_t{kPtyReadBudget}; };
  handlers.on_data = [this](const uint8_t* bytes, size_t length) { on_data(bytes, length); };
  handlers.on_flush = [](bool) {};
  port_ = std::make_unique<PtyPort>(loop, device, std::move(link_path), kMaxPendingOutputBytes, std::move(log),
                                    std::move(handlers));
  bus_id_ = bus_.attach(*this);
}

SlcanPtyEndpoint::~SlcanPtyEndpoint() { bus_.detach(bus_id_); }

void SlcanPtyEndpoint::on_frame(const can::CanFrame& frame, uint64_t) {
  if (!session_.open()) return;
  write(format_slcan_frame(frame));
}

void SlcanPtyEndpoint::on_data(const uint8_t* bytes, size_t length) {
  // As over TCP: the acknowledgement goes out before the bus carries the frame, so a node's
  // answer always follows it.
  std::string reply;
  outgoing_.clear();
  session_.push(std::string_view(reinterpret_cast<const char*>(bytes), length), reply);
  write(reply);
  const std::vector<can::CanFrame> frames = std::move(outgoing_);
  outgoing_.clear();
  for (const can::CanFrame& frame : frames) bus_.send(bus_id_, frame);
}

void SlcanPtyEndpoint::write(const std::string& text) {
  if (text.empty()) return;
  if (!port_->write(reinterpret_cast<const uint8_t*>(text.data()), text.size())) ++dropped_frames_;
}

// --- SocketCAN ------------------------------------------------------------------------------

Result<std::unique_ptr<SocketcanEndpoint>> SocketcanEndpoint::open(EventLoop& loop, CanBus& bus,
                                                                   const std::string& interface, LogSink log) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    return Error{"socketcan: bad interface name \"" + interface + "\""};
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    return Error{"socketcan:" + interface + ": cannot open a CAN socket (" + std::strerror(errno) +
                 "): this kernel or container has no SocketCAN; use --can socketcand:... or slcan:... instead"};
  }
  ifreq request{};
  std::memcpy(request.ifr_name, interface.c_str(), interface.size() + 1);
  if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
    Error error{"socketcan:" + interface + ": no such CAN interface (" + std::strerror(errno) +
                "; create one with: ip link add dev " + interface + " type vcan && ip link set up " + interface + ")"};
    ::close(fd);
    return error;
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    Error error{"socketcan:" + interface + ": cannot bind (" + std::strerror(errno) + ")"};
    ::close(fd);
    return error;
  }
  return std::unique_ptr<SocketcanEndpoint>(new SocketcanEndpoint(loop, bus, fd, interface, std::move(log)));
}

SocketcanEndpoint::SocketcanEndpoint(EventLoop& loop, CanBus& bus, int fd, std::string interface, LogSink log)
    : loop_(loop), bus_(bus), fd_(fd), interface_(std::move(interface)), log_(std::move(log)) {
  bus_id_ = bus_.attach(*this);
  loop_.watch(fd_, POLLIN, [this](short) { read_some(); });
}

SocketcanEndpoint::~SocketcanEndpoint() {
  bus_.detach(bus_id_);
  loop_.unwatch(fd_);
  ::close(fd_);
}

void SocketcanEndpoint::on_frame(const can::CanFrame& frame, uint64_t) {
  can_frame out{};
  out.can_id = frame.id | (frame.extended ? CAN_EFF_FLAG : 0u) | (frame.rtr ? CAN_RTR_FLAG : 0u);
  out.len = frame.dlc > can::kMaxDataLength ? can::kMaxDataLength : frame.dlc;
  if (!frame.rtr) std::memcpy(out.data, frame.data, out.len);
  // The kernel queue is full (nobody acknowledges on a real bus): the frame is lost, counted.
  if (::send(fd_, &out, sizeof(out), MSG_DONTWAIT) != static_cast<ssize_t>(sizeof(out))) ++dropped_frames_;
}

void SocketcanEndpoint::read_some() {
  for (size_t i = 0; i < kMaxFramesPerRead; ++i) {
    can_frame in{};
    const ssize_t n = ::recv(fd_, &in, sizeof(in), MSG_DONTWAIT);
    if (n != static_cast<ssize_t>(sizeof(in))) return;
    if ((in.can_id & CAN_ERR_FLAG) != 0) continue;
    can::CanFrame frame;
    frame.extended = (in.can_id & CAN_EFF_FLAG) != 0;
    frame.rtr = (in.can_id & CAN_RTR_FLAG) != 0;
    frame.id = in.can_id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    frame.dlc = in.len > can::kMaxDataLength ? can::kMaxDataLength : in.len;
    if (!frame.rtr) std::memcpy(frame.data, in.data, frame.dlc);
    bus_.send(bus_id_, frame);
  }
}

}  // namespace motwin::host

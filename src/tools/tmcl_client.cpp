#include "tools/tmcl_client.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "core/tmcl/status.h"
#include "tools/fd_io.h"
#include "tools/tmcl_mnemonics.h"

namespace motwin::tools {
namespace {

using tmcl::Frame;
using tmcl::Instruction;
using tmcl::kFrameLength;

struct HostAndPort {
  std::string host;
  std::string port;
};

Result<HostAndPort> split_host_and_port(std::string_view text) {
  const auto invalid = [&] {
    return Error{fmt::format("invalid TCP address '{}': expected HOST:PORT, for example 127.0.0.1:5000", text)};
  };
  const size_t colon = text.rfind(':');
  if (colon == std::string_view::npos || colon == 0 || colon + 1 == text.size()) return invalid();
  std::string_view host = text.substr(0, colon);
  const std::string_view port = text.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const std::optional<int64_t> port_number = parse_integer(port);
  if (!port_number || *port_number < 1 || *port_number > 65535 || port.front() == '-' || port.front() == '+') {
    return invalid();
  }
  return HostAndPort{std::string(host), std::string(port)};
}

// Non-blocking connect so that an unreachable address fails within `timeout`.
Result<UniqueFd> connect_with_timeout(const addrinfo& address, std::chrono::milliseconds timeout) {
  UniqueFd fd(::socket(address.ai_family, address.ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, address.ai_protocol));
  if (!fd.valid()) return Error{std::strerror(errno)};
  if (::connect(fd.get(), address.ai_addr, address.ai_addrlen) != 0) {
    if (errno != EINPROGRESS) return Error{std::strerror(errno)};
    pollfd poll_entry{fd.get(), POLLOUT, 0};
    int ready;
    do {
      ready = ::poll(&poll_entry, 1, static_cast<int>(timeout.count()));
    } while (ready < 0 && errno == EINTR);
    if (ready == 0) return Error{fmt::format("no answer within {} ms", timeout.count())};
    int socket_error = 0;
    socklen_t length = sizeof socket_error;
    if (ready < 0 || ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &socket_error, &length) != 0) {
      return Error{std::strerror(errno)};
    }
    if (socket_error != 0) return Error{std::strerror(socket_error)};
  }
  const int flags = ::fcntl(fd.get(), F_GETFL);
  ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK);
  // 9-byte requests must leave at once, not wait for Nagle's algorithm.
  const int enable = 1;
  ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &enable, sizeof enable);
  return fd;
}

}  // namespace

std::string hex_bytes(const uint8_t* bytes, size_t length) {
  std::string out;
  for (size_t i = 0; i < length; ++i) {
    if (i > 0) out += ' ';
    out += fmt::format("{:02X}", bytes[i]);
  }
  return out;
}

ReplyKind expected_reply_kind(const Instruction& request) {
  if (request.command == tmcl::command::kGetFirmwareVersion && request.type == 0) return ReplyKind::kVersionString;
  if (request.command == tmcl::command::kRestoreFactoryDefaults) return ReplyKind::kNone;
  return ReplyKind::kNormal;
}

Result<TmclReply> decode_reply(const Frame& bytes, const Instruction& request) {
  TmclReply reply;
  reply.kind = expected_reply_kind(request);
  reply.host_address = bytes[0];
  if (reply.kind == ReplyKind::kVersionString) {
    reply.command = request.command;
    for (size_t i = 1; i < kFrameLength; ++i) {
      const char c = static_cast<char>(bytes[i]);
      if (c < 0x20 || c > 0x7E) {
        return Error{fmt::format("version reply is not 8 printable characters: {}", hex_bytes(bytes.data(), kFrameLength))};
      }
      reply.version_string += c;
    }
    return reply;
  }
  const uint8_t expected_checksum = tmcl::checksum(bytes.data(), kFrameLength - 1);
  if (bytes[kFrameLength - 1] != expected_checksum) {
    return Error{fmt::format("reply checksum error: got 0x{:02X}, expected 0x{:02X} (reply {})", bytes[kFrameLength - 1],
                             expected_checksum, hex_bytes(bytes.data(), kFrameLength))};
  }
  reply.module_address = bytes[1];
  reply.status = bytes[2];
  reply.command = bytes[3];
  // Replies keep the value where requests have it (bytes 4..7, big-endian).
  reply.value = tmcl::decode_instruction(bytes).value;
  const bool is_checksum_error_reply = reply.status == tmcl::to_byte(tmcl::Status::kChecksumError);
  // 134 (type 0) answers with the stored instruction's opcode in the command byte
  // (docs/assembler.md, "Reading program memory back").
  const bool carries_stored_opcode = request.command == tmcl::command::kReadProgramMemory &&
                                     reply.status == tmcl::to_byte(tmcl::Status::kOk);
  if (!is_checksum_error_reply && !carries_stored_opcode && reply.command != request.command) {
    return Error{fmt::format("reply is for command {}, not for the request's command {} (reply {})", reply.command,
                             request.command, hex_bytes(bytes.data(), kFrameLength))};
  }
  return reply;
}

Result<UniqueFd> connect_tcp_socket(std::string_view host_and_port, std::chrono::milliseconds connect_timeout) {
  Result<HostAndPort> target = split_host_and_port(host_and_port);
  if (!target) return Error{target.error()};
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* addresses = nullptr;
  if (const int rc = ::getaddrinfo(target->host.c_str(), target->port.c_str(), &hints, &addresses); rc != 0) {
    return Error{fmt::format("cannot resolve '{}': {}", target->host, ::gai_strerror(rc))};
  }
  std::string last_error = "no address";
  UniqueFd connected;
  for (const addrinfo* address = addresses; address != nullptr; address = address->ai_next) {
    Result<UniqueFd> fd = connect_with_timeout(*address, connect_timeout);
    if (fd) {
      connected = std::move(fd.value());
      break;
    }
    last_error = fd.error();
  }
  ::freeaddrinfo(addresses);
  if (!connected.valid()) return Error{fmt::format("cannot connect to {}: {}", host_and_port, last_error)};
  return connected;
}

Result<TmclClient> TmclClient::connect_tcp(std::string_view host_and_port, std::chrono::milliseconds connect_timeout) {
  Result<UniqueFd> connected = connect_tcp_socket(host_and_port, connect_timeout);
  if (!connected) return Error{connected.error()};
  return TmclClient(std::move(connected.value()), true, fmt::format("tcp {}", host_and_port));
}

Result<TmclClient> TmclClient::open_serial(const std::string& device_path) {
  UniqueFd fd(::open(device_path.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC));
  if (!fd.valid()) return Error{fmt::format("cannot open serial device {}: {}", device_path, std::strerror(errno))};
  termios settings{};
  if (::tcgetattr(fd.get(), &settings) != 0) {
    return Error{fmt::format("{} is not a serial device: {}", device_path, std::strerror(errno))};
  }
  ::cfmakeraw(&settings);
  ::cfsetispeed(&settings, B115200);
  ::cfsetospeed(&settings, B115200);
  settings.c_cflag |= CLOCAL | CREAD;
  // poll() does the waiting; read() returns whatever has arrived.
  settings.c_cc[VMIN] = 0;
  settings.c_cc[VTIME] = 0;
  if (::tcsetattr(fd.get(), TCSANOW, &settings) != 0) {
    return Error{fmt::format("cannot configure serial device {}: {}", device_path, std::strerror(errno))};
  }
  ::tcflush(fd.get(), TCIOFLUSH);
  return TmclClient(std::move(fd), false, fmt::format("serial {}", device_path));
}

void TmclClient::discard_stale_input() {
  if (!is_socket_) ::tcflush(fd_.get(), TCIFLUSH);
  discard_readable_bytes(fd_.get());
  stale_input_possible_ = false;
}

Result<Frame> TmclClient::exchange(const Frame& request_bytes, size_t reply_length) {
  if (stale_input_possible_) discard_stale_input();
  const IoResult written = write_all(fd_.get(), request_bytes.data(), kFrameLength, is_socket_);
  if (written.status == IoStatus::kClosed) return Error{fmt::format("{}: connection closed by the module", peer_name_)};
  if (written.status != IoStatus::kOk) {
    return Error{fmt::format("{}: cannot send: {}", peer_name_, std::strerror(written.error_number))};
  }
  Frame reply{};
  if (reply_length == 0) return reply;
  const IoResult received = read_exact(fd_.get(), reply.data(), reply_length, SteadyClock::now() + reply_timeout_);
  switch (received.status) {
    case IoStatus::kOk:
      return reply;
    case IoStatus::kTimeout: {
      stale_input_possible_ = true;
      std::string message = fmt::format("no reply from {} within {} ms", peer_name_, reply_timeout_.count());
      if (received.transferred > 0) {
        message += fmt::format(" (got {} of {} bytes: {})", received.transferred, reply_length,
                               hex_bytes(reply.data(), received.transferred));
      }
      return Error{message};
    }
    case IoStatus::kClosed:
      return Error{fmt::format("{}: connection closed by the module before its reply was complete ({} of {} bytes)",
                               peer_name_, received.transferred, reply_length)};
    case IoStatus::kError:
      break;
  }
  stale_input_possible_ = true;
  return Error{fmt::format("{}: cannot receive: {}", peer_name_, std::strerror(received.error_number))};
}

Result<TmclReply> TmclClient::request(const Instruction& instruction, uint8_t module_address) {
  const ReplyKind kind = expected_reply_kind(instruction);
  Result<Frame> bytes = exchange(tmcl::encode_request(module_address, instruction),
                                 kind == ReplyKind::kNone ? 0 : kFrameLength);
  if (!bytes) return Error{bytes.error()};
  if (kind == ReplyKind::kNone) {
    TmclReply reply;
    reply.kind = kind;
    reply.command = instruction.command;
    return reply;
  }
  Result<TmclReply> reply = decode_reply(bytes.value(), instruction);
  if (!reply) stale_input_possible_ = true;
  return reply;
}

}  // namespace motwin::tools

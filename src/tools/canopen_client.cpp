#include "tools/canopen_client.h"

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "host/socketcand_protocol.h"

namespace motwin::tools {
namespace {

int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Digits only, at most `max_digits` of them (so the value fits); nullopt otherwise.
std::optional<uint64_t> parse_digits(std::string_view digits, size_t max_digits) {
  uint64_t value = 0;
  const char* end = digits.data() + digits.size();
  if (digits.empty() || digits.size() > max_digits) return std::nullopt;
  const auto [stop, status] = std::from_chars(digits.data(), end, value);
  if (status != std::errc{} || stop != end) return std::nullopt;
  return value;
}

// "SEC.USEC" of a socketcand frame element into µs; 0 when malformed.
uint64_t parse_timestamp_us(std::string_view text) {
  const size_t dot = text.find('.');
  std::string fraction = dot == std::string_view::npos ? std::string() : std::string(text.substr(dot + 1));
  fraction.resize(6, '0');
  const std::optional<uint64_t> seconds = parse_digits(text.substr(0, dot), 12);
  const std::optional<uint64_t> microseconds = parse_digits(fraction, 6);
  if (!seconds || !microseconds) return 0;
  return *seconds * 1'000'000u + *microseconds;
}

std::optional<ReceivedFrame> parse_frame_element(const std::string& element) {
  const std::vector<std::string_view> words = host::socketcand_words(element);
  const Result<can::CanFrame> frame = host::parse_socketcand_frame(words);
  if (!frame) return std::nullopt;
  return ReceivedFrame{*frame, parse_timestamp_us(words[2])};
}

}  // namespace

Result<std::unique_ptr<SocketcandClient>> SocketcandClient::connect(const std::string& host, uint16_t port,
                                                                    int timeout_ms, const std::string& channel) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* addresses = nullptr;
  if (const int status = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &addresses); status != 0) {
    return Error{"cannot resolve " + host + ": " + ::gai_strerror(status)};
  }
  int fd = -1;
  int last_errno = 0;
  for (const addrinfo* a = addresses; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      last_errno = errno;
      continue;
    }
    if (::connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
      last_errno = errno;
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(addresses);
  if (fd < 0) return Error{"cannot connect to " + host + ":" + std::to_string(port) + ": " + std::strerror(last_errno)};
  const int on = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
  std::unique_ptr<SocketcandClient> client(new SocketcandClient(fd));
  const auto greeted = [&](const char* what) {
    const std::optional<std::string> element = client->element(timeout_ms);
    const std::vector<std::string_view> words = element ? host::socketcand_words(*element) : std::vector<std::string_view>{};
    return words.size() == 1 && words[0] == what;
  };
  const auto no_answer = [](const char* what) {
    return Error{std::string("no < ") + what + " > from the socketcand server"};
  };
  if (!greeted("hi")) return no_answer("hi");
  const std::string open = "< open " + channel + " >";
  if (::send(fd, open.data(), open.size(), MSG_NOSIGNAL) < 0 || !greeted("ok")) return no_answer("ok");
  const std::string raw = "< rawmode >";
  if (::send(fd, raw.data(), raw.size(), MSG_NOSIGNAL) < 0 || !greeted("ok")) return no_answer("ok");
  return client;
}

SocketcandClient::~SocketcandClient() { ::close(fd_); }

Result<void> SocketcandClient::send(const can::CanFrame& frame) { return send(std::span<const can::CanFrame>(&frame, 1)); }

Result<void> SocketcandClient::send(std::span<const can::CanFrame> frames) {
  std::string text;
  for (const can::CanFrame& frame : frames) text += host::format_socketcand_send(frame);
  if (::send(fd_, text.data(), text.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(text.size())) {
    return Error{"cannot send to the socketcand server"};
  }
  return {};
}

std::optional<std::string> SocketcandClient::element(int timeout_ms) {
  const int64_t deadline = now_ms() + timeout_ms;
  for (;;) {
    const size_t start = buffer_.find('<');
    const size_t end = start == std::string::npos ? std::string::npos : buffer_.find('>', start);
    if (end != std::string::npos) {
      std::string inner = buffer_.substr(start + 1, end - start - 1);
      buffer_.erase(0, end + 1);
      return inner;
    }
    const int64_t remaining = deadline - now_ms();
    if (remaining <= 0) return std::nullopt;
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(remaining)) <= 0) continue;
    char chunk[4096];
    const ssize_t n = ::recv(fd_, chunk, sizeof(chunk), 0);
    if (n <= 0) {
      closed_ = true;
      return std::nullopt;
    }
    buffer_.append(chunk, static_cast<size_t>(n));
  }
}

std::optional<ReceivedFrame> SocketcandClient::receive_stamped(int timeout_ms) {
  const int64_t deadline = now_ms() + timeout_ms;
  for (;;) {
    const int64_t remaining = deadline - now_ms();
    if (remaining < 0) return std::nullopt;
    const std::optional<std::string> next = element(static_cast<int>(remaining));
    if (!next) return std::nullopt;
    if (std::optional<ReceivedFrame> frame = parse_frame_element(*next)) return frame;
  }
}

std::optional<can::CanFrame> SocketcandClient::receive(int timeout_ms) {
  const std::optional<ReceivedFrame> received = receive_stamped(timeout_ms);
  if (!received) return std::nullopt;
  return received->frame;
}

namespace {

// Sends `request` to 0x600 + node and waits for the next frame on 0x580 + node.
std::optional<can::CanFrame> exchange(SocketcandClient& bus, uint8_t node, const uint8_t (&request)[8], int timeout_ms,
                                      SdoResult& result) {
  if (const Result<void> sent = bus.send(can::make_frame(0x600u + node, request, 8)); !sent) {
    result.error = sent.error();
    return std::nullopt;
  }
  const int64_t deadline = now_ms() + timeout_ms;
  for (;;) {
    const int64_t remaining = deadline - now_ms();
    const std::optional<can::CanFrame> frame = remaining > 0 ? bus.receive(static_cast<int>(remaining)) : std::nullopt;
    if (!frame) {
      result.error = "no SDO response from node " + std::to_string(node) + " within " + std::to_string(timeout_ms) + " ms";
      return std::nullopt;
    }
    if (frame->id != 0x580u + node || frame->extended) continue;
    if (frame->dlc != 8) {
      result.error = "SDO response with DLC " + std::to_string(frame->dlc);
      return std::nullopt;
    }
    if (frame->data[0] == 0x80) {
      result.abort_code = static_cast<uint32_t>(frame->data[4] | frame->data[5] << 8 | frame->data[6] << 16) |
                          static_cast<uint32_t>(frame->data[7]) << 24;
      return std::nullopt;
    }
    return frame;
  }
}

}  // namespace

SdoResult sdo_upload(SocketcandClient& bus, uint8_t node, uint16_t index, uint8_t sub, int timeout_ms) {
  SdoResult result;
  const uint8_t lo = static_cast<uint8_t>(index), hi = static_cast<uint8_t>(index >> 8);
  std::optional<can::CanFrame> r = exchange(bus, node, {0x40, lo, hi, sub, 0, 0, 0, 0}, timeout_ms, result);
  if (!r) return result;
  const uint8_t header = r->data[0];
  if ((header & 0xE0) != 0x40) {
    result.error = "unexpected initiate upload response";
    return result;
  }
  if (header & 0x02) {  // expedited
    const size_t n = (header & 0x01) ? 4u - ((header >> 2) & 3u) : 4u;
    result.data.assign(r->data + 4, r->data + 4 + n);
    result.ok = true;
    return result;
  }
  uint8_t toggle = 0;
  for (int segments = 0; segments < 1 << 16; ++segments) {
    const uint8_t request[8] = {static_cast<uint8_t>(0x60 | toggle), 0, 0, 0, 0, 0, 0, 0};
    r = exchange(bus, node, request, timeout_ms, result);
    if (!r) return result;
    if ((r->data[0] & 0xE0) != 0x00 || (r->data[0] & 0x10) != toggle) {
      result.error = "unexpected upload segment";
      return result;
    }
    const size_t n = 7u - ((r->data[0] >> 1) & 7u);
    result.data.insert(result.data.end(), r->data + 1, r->data + 1 + n);
    if (r->data[0] & 0x01) {
      result.ok = true;
      return result;
    }
    toggle ^= 0x10;
  }
  result.error = "segmented upload too long";
  return result;
}

SdoResult sdo_download(SocketcandClient& bus, uint8_t node, uint16_t index, uint8_t sub,
                       const std::vector<uint8_t>& data, int timeout_ms) {
  SdoResult result;
  const uint8_t lo = static_cast<uint8_t>(index), hi = static_cast<uint8_t>(index >> 8);
  if (data.size() <= 4 && !data.empty()) {
    uint8_t request[8] = {static_cast<uint8_t>(0x23 | ((4 - data.size()) << 2)), lo, hi, sub, 0, 0, 0, 0};
    for (size_t i = 0; i < data.size(); ++i) request[4 + i] = data[i];
    if (exchange(bus, node, request, timeout_ms, result)) result.ok = true;
    return result;
  }
  const uint32_t size = static_cast<uint32_t>(data.size());
  const uint8_t initiate[8] = {0x21, lo, hi, sub, static_cast<uint8_t>(size), static_cast<uint8_t>(size >> 8),
                               static_cast<uint8_t>(size >> 16), static_cast<uint8_t>(size >> 24)};
  if (!exchange(bus, node, initiate, timeout_ms, result)) return result;
  uint8_t toggle = 0;
  size_t offset = 0;
  do {
    const size_t n = data.size() - offset < 7 ? data.size() - offset : 7;
    const bool last = offset + n == data.size();
    uint8_t request[8] = {static_cast<uint8_t>(toggle | ((7 - n) << 1) | (last ? 1 : 0)), 0, 0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < n; ++i) request[1 + i] = data[offset + i];
    if (!exchange(bus, node, request, timeout_ms, result)) return result;
    offset += n;
    toggle ^= 0x10;
  } while (offset < data.size());
  result.ok = true;
  return result;
}

}  // namespace motwin::tools

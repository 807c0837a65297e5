#include "host/socketcand_client.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <unistd.h>

namespace motwin::host {
namespace {

constexpr size_t kReadChunkBytes = 4096;
// Reads per loop event: a busy remote bus cannot starve the rest of the loop.
constexpr size_t kMaxReadsPerEvent = 16;

}  // namespace

// --- The protocol --------------------------------------------------------------------------

void SocketcandClientSession::push(std::string_view bytes) {
  elements_.clear();
  parser_.push(bytes, elements_);
  for (const std::string& element : elements_) {
    if (state_ == State::kFailed) return;
    handle(element);
  }
}

bool SocketcandClientSession::send(const can::CanFrame& frame) {
  if (state_ != State::kJoined || frame.rtr) return false;
  io_.write(format_socketcand_send(frame));
  return true;
}

void SocketcandClientSession::handle(const std::string& element) {
  const std::vector<std::string_view> words = socketcand_words(element);
  const std::string_view command = words.empty() ? std::string_view{} : words[0];
  const bool ok = command == "ok" && words.size() == 1;
  switch (state_) {
    case State::kAwaitHi:
      if (command != "hi" || words.size() != 1) return fail("expected < hi >, got <" + element + ">");
      state_ = State::kAwaitOpenOk;
      io_.write("< open " + channel_ + " >");
      return;
    case State::kAwaitOpenOk:
      if (!ok) return fail("< open " + channel_ + " > answered with <" + element + ">");
      state_ = State::kAwaitRawModeOk;
      io_.write("< rawmode >");
      return;
    case State::kAwaitRawModeOk:
      if (!ok) return fail("< rawmode > answered with <" + element + ">");
      state_ = State::kJoined;
      io_.handshake_done();
      return;
    case State::kJoined:
      if (command == "frame") {
        if (const Result<can::CanFrame> frame = parse_socketcand_frame(words); frame) {
          io_.frame_from_server(*frame);
          return;
        }
      }
      ++ignored_;
      return;
    case State::kFailed:
      return;
  }
}

void SocketcandClientSession::fail(const std::string& reason) {
  state_ = State::kFailed;
  io_.failed(reason);
}

// --- The connection ------------------------------------------------------------------------

Result<std::unique_ptr<SocketcandClientEndpoint>> SocketcandClientEndpoint::open(EventLoop& loop, CanBus& bus,
                                                                 const SocketcandClientSpec& spec, LogSink log) {
  const std::string where = (spec.server.host.find(':') != std::string::npos ? "[" + spec.server.host + "]"
                                                                              : spec.server.host) +
                            ":" + std::to_string(spec.server.port) + " " + spec.channel;
  const std::string context = "cannot join the socketcand bus at " + where + ": ";
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* addresses = nullptr;
  const std::string port_text = std::to_string(spec.server.port);
  if (const int status = ::getaddrinfo(spec.server.host.c_str(), port_text.c_str(), &hints, &addresses);
      status != 0) {
    return Error{context + ::gai_strerror(status)};
  }
  sockaddr_storage address{};
  const socklen_t address_length = static_cast<socklen_t>(std::min<size_t>(addresses->ai_addrlen, sizeof(address)));
  std::memcpy(&address, addresses->ai_addr, address_length);
  ::freeaddrinfo(addresses);

  std::unique_ptr<SocketcandClientEndpoint> client(
      new SocketcandClientEndpoint(loop, bus, address, address_length, spec.channel, std::move(log)));
  client->connect_now();
  const uint64_t deadline_us = monotonic_now_us() + kJoinTimeoutUs;
  while (!client->joined() && client->start_failure_.empty()) {
    const uint64_t now_us = monotonic_now_us();
    if (now_us >= deadline_us) {
      return Error{context + "no answer within " + std::to_string(kJoinTimeoutUs / 1'000'000) + " s"};
    }
    loop.poll_once(deadline_us - now_us);
  }
  if (!client->start_failure_.empty()) return Error{context + client->start_failure_};
  client->starting_ = false;
  return client;
}

SocketcandClientEndpoint::SocketcandClientEndpoint(EventLoop& loop, CanBus& bus, sockaddr_storage address, socklen_t address_length,
                                   std::string channel, LogSink log)
    : loop_(loop),
      bus_(bus),
      address_(address),
      address_length_(address_length),
      channel_(std::move(channel)),
      log_(std::move(log)) {
  bus_id_ = bus_.attach(*this);
}

SocketcandClientEndpoint::~SocketcandClientEndpoint() {
  bus_.detach(bus_id_);
  if (retry_timer_ != 0) loop_.cancel_timer(retry_timer_);
  if (fd_ >= 0) {
    loop_.unwatch(fd_);
    ::close(fd_);
  }
}

std::string SocketcandClientEndpoint::where() const { return format_socket_address(address_) + " " + channel_; }

void SocketcandClientEndpoint::connect_now() {
  SocketcandClientSession::Io& io = *this;
  session_ = std::make_unique<SocketcandClientSession>(io, channel_);
  output_.clear();
  fd_ = ::socket(address_.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    const std::string reason = std::string("cannot open a socket: ") + std::strerror(errno);
    fd_ = -1;
    return lose(reason);
  }
  const int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
  loop_.watch(fd_, POLLOUT, [this](short revents) { on_events(revents); });
  connecting_ = true;
  if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address_), address_length_) == 0) {
    connecting_ = false;
    loop_.set_events(fd_, POLLIN);
  } else if (errno != EINPROGRESS) {
    lose(std::strerror(errno));
  }
}

void SocketcandClientEndpoint::on_events(short revents) {
  if (connecting_) {
    int error = 0;
    socklen_t length = sizeof(error);
    if (::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &length) != 0) error = errno;
    if (error != 0) return lose(std::strerror(error));
    if ((revents & (POLLOUT | POLLIN)) == 0) return lose("the connection failed");
    connecting_ = false;
    loop_.set_events(fd_, POLLIN);
  }
  if ((revents & (POLLIN | POLLHUP | POLLERR)) != 0) read_some();
  if (fd_ >= 0 && (revents & POLLOUT) != 0) flush();
}

void SocketcandClientEndpoint::read_some() {
  char chunk[kReadChunkBytes];
  for (size_t i = 0; i < kMaxReadsPerEvent && fd_ >= 0; ++i) {
    const ssize_t n = ::recv(fd_, chunk, sizeof(chunk), MSG_DONTWAIT);
    if (n > 0) {
      session_->push(std::string_view(chunk, static_cast<size_t>(n)));
      continue;
    }
    if (n == 0) return lose("the server closed the connection");
    if (errno == EAGAIN || errno == EWOULDBLOCK) return;
    if (errno == EINTR) continue;
    return lose(std::strerror(errno));
  }
}

void SocketcandClientEndpoint::flush() {
  if (fd_ < 0 || connecting_) return;
  std::string error;
  if (output_.send_to(fd_, &error) == SocketOutput::Sent::kFailed) return lose(error);
  loop_.set_events(fd_, output_.empty() ? POLLIN : static_cast<short>(POLLIN | POLLOUT));
}

void SocketcandClientEndpoint::lose(const std::string& reason) {
  const bool was_joined = joined();
  if (fd_ >= 0) {
    loop_.unwatch(fd_);
    ::close(fd_);
  }
  fd_ = -1;
  connecting_ = false;
  output_.clear();
  if (starting_) {
    start_failure_ = reason;
    return;
  }
  if (was_joined) {
    log_("motwin: socketcand-client " + where() + ": connection lost (" + reason + "); reconnecting, frames are " +
         "dropped until then");
  }
  if (retry_timer_ != 0) return;
  retry_timer_ = loop_.add_timer_after(retry_delay_us_, [this] {
    retry_timer_ = 0;
    connect_now();
  });
  retry_delay_us_ = std::min(retry_delay_us_ * 2, kMaxRetryUs);
}

void SocketcandClientEndpoint::write(const std::string& element) {
  if (fd_ < 0) return;
  output_.append(element);
  flush();
}

void SocketcandClientEndpoint::handshake_done() {
  ++connections_;
  retry_delay_us_ = kFirstRetryUs;
  if (!starting_) log_("motwin: socketcand-client " + where() + ": joined the bus again");
}

void SocketcandClientEndpoint::failed(const std::string& reason) { lose("the server answered " + reason); }

void SocketcandClientEndpoint::frame_from_server(const can::CanFrame& frame) { bus_.send(bus_id_, frame); }

void SocketcandClientEndpoint::on_frame(const can::CanFrame& frame, uint64_t) {
  if (!joined() || output_.pending() > kMaxPendingOutputBytes || !session_->send(frame)) {
    ++dropped_frames_;
  }
}

}  // namespace motwin::host

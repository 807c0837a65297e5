#include "host/pty_device.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <termios.h>
#include <unistd.h>

namespace motwin::host {
namespace {

std::string read_link(const std::string& path) {
  char target[PATH_MAX];
  const ssize_t n = ::readlink(path.c_str(), target, sizeof(target) - 1);
  return n < 0 ? std::string() : std::string(target, static_cast<size_t>(n));
}

// Points `link_path` at `device_path`, or says why it cannot be (re)placed.
Result<void> place_link(const std::string& link_path, const std::string& device_path) {
  struct stat existing {};
  if (::lstat(link_path.c_str(), &existing) == 0) {
    if (!S_ISLNK(existing.st_mode)) return Error{link_path + " exists and is not a symbolic link; not replacing it"};
    const std::string target = read_link(link_path);
    struct stat target_info {};
    const bool stale = ::stat(link_path.c_str(), &target_info) != 0;
    if (!stale && target.rfind("/dev/pts/", 0) != 0) {
      return Error{link_path + " is a symbolic link to " + target + ", not to a pseudo-terminal; not replacing it"};
    }
  } else if (errno != ENOENT) {
    return Error{"cannot inspect " + link_path + ": " + std::strerror(errno)};
  }
  // Create beside it and rename over it, so the link is never missing or half made.
  const std::string temporary = link_path + ".motwin-" + std::to_string(::getpid());
  ::unlink(temporary.c_str());
  if (::symlink(device_path.c_str(), temporary.c_str()) != 0) {
    return Error{"cannot create symbolic link " + link_path + ": " + std::strerror(errno)};
  }
  if (::rename(temporary.c_str(), link_path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    return Error{"cannot create symbolic link " + link_path + ": " + std::strerror(error)};
  }
  return {};
}

// The link's absolute path with its directory resolved ("./x" and "/tmp/../tmp/x" are one link).
std::string absolute_link_path(const std::string& link_path) {
  std::error_code ignored;
  const std::filesystem::path absolute = std::filesystem::absolute(link_path, ignored);
  const std::filesystem::path directory = std::filesystem::weakly_canonical(absolute.parent_path(), ignored);
  return (directory / absolute.filename()).string();
}

// FNV-1a: a long path still gets a short, stable socket name.
uint64_t fnv1a(const std::string& text) {
  uint64_t hash = 14695981039346656037ull;
  for (const char c : text) hash = (hash ^ static_cast<uint8_t>(c)) * 1099511628211ull;
  return hash;
}

}  // namespace

Result<int> claim_pty_link(const std::string& link_path) {
  const std::string absolute = absolute_link_path(link_path);
  std::string name = "motwin-pty-link:" + absolute;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (name.size() + 1 > sizeof(address.sun_path)) {
    char hashed[32];
    std::snprintf(hashed, sizeof hashed, "%016llx", static_cast<unsigned long long>(fnv1a(absolute)));
    name = "motwin-pty-link#" + std::string(hashed);
  }
  // sun_path[0] = 0: the abstract namespace.
  std::memcpy(address.sun_path + 1, name.data(), name.size());
  const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + name.size());
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return Error{"cannot claim " + link_path + ": " + std::strerror(errno)};
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), length) != 0) {
    const int error = errno;
    ::close(fd);
    if (error == EADDRINUSE) {
      return Error{link_path + " is the serial port of a running motwin; not taking it over (stop that one or "
                   "choose another path)"};
    }
    return Error{"cannot claim " + link_path + ": " + std::strerror(error)};
  }
  return fd;
}

Result<PtyDevice> open_pty_device(const std::string& link_path) {
  int claim_fd = -1;
  auto fail = [&claim_fd](const std::string& what, int master_fd, int slave_fd) {
    if (slave_fd >= 0) ::close(slave_fd);
    if (master_fd >= 0) ::close(master_fd);
    if (claim_fd >= 0) ::close(claim_fd);
    return Error{what};
  };
  if (link_path.empty()) return fail("the pseudo-terminal link path is empty", -1, -1);
  Result<int> claim = claim_pty_link(link_path);
  if (!claim) return fail(claim.error(), -1, -1);
  claim_fd = *claim;
  const int master_fd = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_fd < 0) return fail("cannot create a pseudo-terminal: " + std::string(std::strerror(errno)), -1, -1);
  char device[PATH_MAX];
  if (::grantpt(master_fd) != 0 || ::unlockpt(master_fd) != 0 || ::ptsname_r(master_fd, device, sizeof(device)) != 0) {
    return fail("cannot set up a pseudo-terminal: " + std::string(std::strerror(errno)), master_fd, -1);
  }
  const int slave_fd = ::open(device, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave_fd < 0) {
    return fail("cannot open " + std::string(device) + ": " + std::strerror(errno), master_fd, -1);
  }
  termios settings{};
  if (::tcgetattr(slave_fd, &settings) == 0) {
    ::cfmakeraw(&settings);  // no echo, no line editing, no CR/LF translation: bytes pass as they are
    ::cfsetispeed(&settings, B115200);
    ::cfsetospeed(&settings, B115200);
    ::tcsetattr(slave_fd, TCSANOW, &settings);
  }
  // Packet mode: each read starts with a status byte, which reports when a client flushes its
  // input (pyserial does on open): the moment to drop replies nobody will read.
  const int packet_mode = 1;
  if (::ioctl(master_fd, TIOCPKT, &packet_mode) != 0) {
    return fail("cannot set packet mode on the pseudo-terminal: " + std::string(std::strerror(errno)), master_fd,
                slave_fd);
  }
  const int flags = ::fcntl(master_fd, F_GETFL);
  if (flags < 0 || ::fcntl(master_fd, F_SETFL, flags | O_NONBLOCK) != 0) {
    return fail("cannot make the pseudo-terminal non-blocking: " + std::string(std::strerror(errno)), master_fd,
                slave_fd);
  }
  if (Result<void> linked = place_link(link_path, device); !linked) return fail(linked.error(), master_fd, slave_fd);
  return PtyDevice{master_fd, slave_fd, claim_fd, device};
}

void remove_pty_link(const std::string& link_path, const std::string& device_path) {
  if (read_link(link_path) == device_path) ::unlink(link_path.c_str());
}


}  // namespace motwin::host

namespace motwin::host {
namespace {

constexpr size_t kPtyReadChunkBytes = 4096;
// A hangup should not happen while we hold the slave open; if it does, poll() would report it
// continuously, so reading pauses this long instead of spinning.
constexpr uint64_t kHangupRetryUs = 100'000;

}  // namespace

PtyPort::PtyPort(EventLoop& loop, const PtyDevice& device, std::string link_path, size_t max_pending_output_bytes,
                 LogSink log, Handlers handlers)
    : loop_(loop),
      master_fd_(device.master_fd),
      slave_fd_(device.slave_fd),
      link_claim_fd_(device.link_claim_fd),
      link_path_(std::move(link_path)),
      device_path_(device.device_path),
      max_pending_output_bytes_(max_pending_output_bytes),
      log_(std::move(log)),
      handlers_(std::move(handlers)) {
  loop_.watch(master_fd_, POLLIN, [this](short revents) { on_events(revents); });
}

PtyPort::~PtyPort() {
  loop_.unwatch(master_fd_);
  // Only our own link: another instance may have taken the name over since.
  remove_pty_link(link_path_, device_path_);
  ::close(slave_fd_);
  ::close(master_fd_);
  if (link_claim_fd_ >= 0) ::close(link_claim_fd_);  // after the link is gone
}

void PtyPort::on_events(short revents) {
  // Reading first: a flush reported in the status byte must discard stale output before it is
  // written into the freshly flushed pty.
  if ((revents & (POLLIN | POLLPRI)) != 0) {
    read_some();
    if ((revents & POLLOUT) != 0) flush();
  } else if ((revents & POLLOUT) != 0) {
    flush();
  } else if ((revents & (POLLHUP | POLLERR)) != 0 && !input_suspended_) {
    log_("motwin: pseudo-terminal " + device_path_ + " hung up; pausing input");
    input_suspended_ = true;
    update_events();
    loop_.add_timer_after(kHangupRetryUs, [this] {
      input_suspended_ = false;
      update_events();
    });
  }
}

void PtyPort::read_some() {
  const size_t room = handlers_.read_budget();
  if (room == 0) return;
  uint8_t buffer[kPtyReadChunkBytes + 1];
  ssize_t n = 0;
  do {
    n = ::read(master_fd_, buffer, 1 + std::min(kPtyReadChunkBytes, room));
  } while (n < 0 && errno == EINTR);
  if (n <= 0) {
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) on_events(POLLHUP);
    return;
  }
  const uint8_t status = buffer[0];
  if (status != TIOCPKT_DATA) {
    // A status packet carries no data. A client that flushed its input (pyserial on open) wants
    // nothing old: drop our output, including the tail of what the pty took only in part.
    if ((status & TIOCPKT_FLUSHREAD) != 0) {
      discard_written_output();
      output_.clear();
      reported_dropped_output_ = false;
    }
    handlers_.on_flush((status & TIOCPKT_FLUSHWRITE) != 0);
    update_events();
    return;
  }
  handlers_.on_data(buffer + 1, static_cast<size_t>(n - 1));
  update_events();
}

void PtyPort::discard_written_output() {
  // The kernel empties the client's input queue and wakes us as a writer before we read the
  // flush status: output written in between landed in the flushed queue (seen on a loaded
  // machine: a pty full of old frames, the last one cut short, so that the client's first
  // answer after the flush ran into it and was lost). It is old too: flush it again from our
  // side, with packet mode off so that this flush is not reported back to us as the client's.
  int off = 0;
  int on = 1;
  ::ioctl(master_fd_, TIOCPKT, &off);
  ::tcflush(slave_fd_, TCIFLUSH);
  ::ioctl(master_fd_, TIOCPKT, &on);
}

bool PtyPort::write(const uint8_t* bytes, size_t length) {
  if (output_.size() + length > max_pending_output_bytes_) {
    if (!reported_dropped_output_) {
      log_("motwin: nobody reads " + link_path_ + "; dropping output until someone does");
      reported_dropped_output_ = true;
    }
    return false;
  }
  output_.insert(output_.end(), bytes, bytes + length);
  flush();
  return true;
}

void PtyPort::flush() {
  size_t sent = 0;
  while (sent < output_.size()) {
    const ssize_t n = ::write(master_fd_, output_.data() + sent, output_.size() - sent);
    if (n > 0) {
      sent += static_cast<size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      break;  // the pty is full: the rest goes on POLLOUT
    } else {
      sent = output_.size();  // the pty refuses data (EIO): lost, as on a dead line
    }
  }
  output_.erase(output_.begin(), output_.begin() + static_cast<std::ptrdiff_t>(sent));
  if (output_.empty()) reported_dropped_output_ = false;
  update_events();
}

void PtyPort::update_events() {
  short events = 0;
  if (!input_suspended_ && handlers_.read_budget() > 0) events |= POLLIN;
  if (!output_.empty()) events |= POLLOUT;
  loop_.set_events(master_fd_, events);
}

}  // namespace motwin::host

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "host/pty_endpoint.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using testing::Bytes;
using testing::reply;
using testing::request;
using testing::slice;

constexpr uint8_t kGap = 6, kSap = 5, kSgp = 9;

// What a serial-port client does: open the device, read and write raw bytes.
class SerialTestClient {
 public:
  explicit SerialTestClient(const std::string& path) { fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC); }
  SerialTestClient(const SerialTestClient&) = delete;
  SerialTestClient& operator=(const SerialTestClient&) = delete;
  ~SerialTestClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool is_open() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  void send(const Bytes& bytes) const { ASSERT_EQ(::write(fd_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size())); }
  bool has(size_t count) {
    uint8_t buffer[256];
    const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
    if (n > 0) received_.insert(received_.end(), buffer, buffer + n);
    return received_.size() >= count;
  }
  Bytes take() {
    Bytes out;
    out.swap(received_);
    return out;
  }
  const Bytes& received() const { return received_; }

 private:
  int fd_ = -1;
  Bytes received_;
};

class PtyEndpointTest : public ::testing::Test {
 protected:
  std::string link() const { return (scratch_.path() / "tmcm1636").string(); }

  void open_endpoint(LineEcho echo = LineEcho::kNone) {
    Result<std::unique_ptr<TmclPtyEndpoint>> opened = TmclPtyEndpoint::open(
        rig_.runtime->loop(), rig_.runtime->service(), link(), [](const std::string&) {}, echo);
    ASSERT_TRUE(opened) << opened.error();
    endpoint_ = std::move(*opened);
  }
  Bytes exchange(SerialTestClient& client, const Bytes& frame) {
    client.send(frame);
    EXPECT_TRUE(testing::pump_until([this] { rig_.step(); }, [&] { return client.has(9); }));
    return client.take();
  }

  testing::ScratchDirectory scratch_;
  testing::ModuleOnRuntime rig_;
  std::unique_ptr<TmclPtyEndpoint> endpoint_;
};

TEST_F(PtyEndpointTest, the_link_points_to_a_raw_pseudo_terminal_that_answers_tmcl) {
  open_endpoint();
  EXPECT_EQ(std::filesystem::read_symlink(link()).string(), endpoint_->device_path());
  EXPECT_EQ(endpoint_->device_path().rfind("/dev/pts/", 0), 0u);
  SerialTestClient client(link());
  ASSERT_TRUE(client.is_open());
  termios settings{};
  ASSERT_EQ(::tcgetattr(client.fd(), &settings), 0);
  EXPECT_EQ(settings.c_lflag & (ECHO | ICANON), 0u);  // raw: no echo of our replies back to us
  EXPECT_EQ(exchange(client, request(kGap, 43, 0, 0)), (Bytes{0x02, 0x01, 0x64, 0x06, 0x00, 0x00, 0x0F, 0xA0, 0x1C}));
}

TEST_F(PtyEndpointTest, clients_may_open_and_close_the_device_repeatedly) {
  open_endpoint();
  for (int round = 0; round < 5; ++round) {
    SCOPED_TRACE(round);
    SerialTestClient client(link());
    ASSERT_TRUE(client.is_open());
    EXPECT_EQ(exchange(client, request(kSap, 43, 0, 1000 + round)), reply(100, kSap, 1000 + round));
  }
  // Nobody has the device open: the master must be quiet, not hung up (no busy loop).
  EXPECT_EQ(rig_.runtime->loop().poll_once(0), 0u);
  SerialTestClient last(link());
  EXPECT_EQ(exchange(last, request(kGap, 43, 0, 0)), reply(100, kGap, 1004));
}

// The RS485 transceiver's echo, as Zephyr's TMCM RS485 bus driver uses it: it writes one byte and
// waits for that byte to come back before it writes the next; after the ninth echo it reads the
// reply. Nothing but the echo may come back before the ninth byte.
TEST_F(PtyEndpointTest, with_the_echo_each_byte_comes_back_before_the_next_is_sent_then_the_reply) {
  open_endpoint(LineEcho::kTransceiver);
  EXPECT_EQ(endpoint_->echo(), LineEcho::kTransceiver);
  SerialTestClient client(link());
  ASSERT_TRUE(client.is_open());
  for (int32_t value : {2000, 3200}) {
    SCOPED_TRACE(value);
    const Bytes frame = request(kSap, 43, 0, value);
    for (size_t i = 0; i < frame.size(); ++i) {
      client.send(Bytes{frame[i]});
      ASSERT_TRUE(testing::pump_until([this] { rig_.step(); }, [&] { return client.has(i + 1); }));
      if (i + 1 < frame.size()) {
        EXPECT_EQ(client.received(), slice(frame, 0, i + 1)) << "after byte " << i;
      }
    }
    ASSERT_TRUE(testing::pump_until([this] { rig_.step(); }, [&] { return client.has(18); }));
    Bytes expected = frame;
    const Bytes answer = reply(100, kSap, value);
    expected.insert(expected.end(), answer.begin(), answer.end());
    EXPECT_EQ(client.take(), expected);
  }
}

// A pty passes a client's bytes on to the master asynchronously (a kernel worker), and the loop
// sees a pause of the line only where one of its polls found the master quiet. On a loaded
// machine the bytes may reach the master well after the client wrote them, so the tests below
// wait for the kernel and for the endpoint's reads, not for the wall clock.

// Bytes this process has read so far (rchar of /proc/self/io), less its reads of that file: the
// endpoint's reads of the pty master while the client only writes.
uint64_t bytes_read_by_this_process() {
  static uint64_t read_from_proc_self_io = 0;  // rchar counts these reads too
  char text[4096];
  const int fd = ::open("/proc/self/io", O_RDONLY | O_CLOEXEC);
  const ssize_t n = fd < 0 ? -1 : ::read(fd, text, sizeof(text) - 1);
  if (fd >= 0) ::close(fd);
  if (n <= 0) {
    ADD_FAILURE() << "cannot read /proc/self/io";
    return 0;
  }
  text[n] = '\0';
  const char* rchar = std::strstr(text, "rchar:");
  EXPECT_NE(rchar, nullptr) << text;
  // The text shows rchar as it was before this read.
  const uint64_t value = rchar == nullptr ? 0 : std::strtoull(rchar + 6, nullptr, 10) - read_from_proc_self_io;
  read_from_proc_self_io += static_cast<uint64_t>(n);
  return value;
}

// Bytes waiting at the pty master for the endpoint to read: the master is the one descriptor of
// this process that is open on /dev/ptmx.
int bytes_waiting_at_the_master() {
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code error;
    if (std::filesystem::read_symlink(entry.path(), error) != "/dev/ptmx") continue;
    int waiting = 0;
    EXPECT_EQ(::ioctl(std::stoi(entry.path().filename().string()), FIONREAD, &waiting), 0);
    return waiting;
  }
  ADD_FAILURE() << "no descriptor on /dev/ptmx";
  return 0;
}

TEST_F(PtyEndpointTest, a_pause_resynchronises_after_a_half_frame) {
  open_endpoint();
  SerialTestClient client(link());
  const uint64_t read_before = bytes_read_by_this_process();
  client.send(slice(request(kGap, 43, 0, 0), 0, 4));
  ASSERT_TRUE(
      testing::pump_until([this] { rig_.step(); }, [&] { return bytes_read_by_this_process() >= read_before + 4; }));
  // Longer than the 5 ms resync gap, measured by the loop's clock from when it read the half:
  // until a loop iteration (its poll) starts 20 ms later.
  const uint64_t start = monotonic_now_us();
  uint64_t step_start = start;
  while (step_start - start < 20'000) {
    step_start = monotonic_now_us();
    rig_.step();
  }
  EXPECT_EQ(exchange(client, request(kGap, 43, 0, 0)), reply(100, kGap, 4000));
}

TEST_F(PtyEndpointTest, a_stall_of_the_server_is_no_pause_of_the_line) {
  open_endpoint();
  SerialTestClient client(link());
  const Bytes frame = request(kGap, 43, 0, 0);
  const uint64_t read_before = bytes_read_by_this_process();
  client.send(slice(frame, 0, 4));
  // The first half is read, and the loop stops right after (it sees no quiet line after it).
  ASSERT_TRUE(
      testing::pump_until([this] { rig_.step(); }, [&] { return bytes_read_by_this_process() >= read_before + 4; }));
  // The rest follows at once, but the server does not run for 20 ms (a loaded machine): the
  // bytes wait in the pty, and the line itself never paused.
  client.send(slice(frame, 4, 9));
  ASSERT_TRUE(testing::pump_until([] { ::usleep(100); }, [] { return bytes_waiting_at_the_master() >= 5; }));
  ::usleep(20'000);
  EXPECT_EQ(exchange(client, {}), reply(100, kGap, 4000));
}

TEST_F(PtyEndpointTest, a_client_that_flushes_on_open_never_gets_an_old_clients_replies) {
  open_endpoint();
  {
    // Sends 3000 requests and never reads a reply: far more than the pty holds.
    SerialTestClient flooder(link());
    Bytes flood;
    for (int i = 0; i < 3000; ++i) {
      const Bytes frame = request(kSgp, 20, 2, 5);
      flood.insert(flood.end(), frame.begin(), frame.end());
    }
    size_t written = 0;
    ASSERT_TRUE(testing::pump_until([this] { rig_.step(); }, [&] {
      const ssize_t n = ::write(flooder.fd(), flood.data() + written, flood.size() - written);
      if (n > 0) written += static_cast<size_t>(n);
      return written == flood.size() && rig_.runtime->service().served_request_count() == 3000;
    }));
  }
  // What pyserial does on open: discard whatever input is waiting.
  SerialTestClient client(link());
  ASSERT_EQ(::tcflush(client.fd(), TCIFLUSH), 0);
  EXPECT_EQ(exchange(client, request(kGap, 43, 0, 0)), reply(100, kGap, 4000));
  for (int i = 0; i < 20; ++i) rig_.step();
  EXPECT_FALSE(client.has(1));  // nothing stale behind it
}

TEST_F(PtyEndpointTest, a_stale_link_is_replaced_and_removed_at_shutdown) {
  std::filesystem::create_symlink("/dev/pts/999999", link());
  open_endpoint();
  EXPECT_EQ(std::filesystem::read_symlink(link()).string(), endpoint_->device_path());
  endpoint_.reset();
  EXPECT_FALSE(std::filesystem::is_symlink(link()));
}

TEST_F(PtyEndpointTest, a_regular_file_or_a_link_to_something_else_is_not_replaced) {
  std::ofstream(link()) << "precious";
  Result<std::unique_ptr<TmclPtyEndpoint>> opened =
      TmclPtyEndpoint::open(rig_.runtime->loop(), rig_.runtime->service(), link());
  EXPECT_FALSE(opened);
  EXPECT_EQ(opened.error(), link() + " exists and is not a symbolic link; not replacing it");
  std::filesystem::remove(link());

  const std::string target = (scratch_.path() / "real-device").string();
  std::ofstream(target) << "x";
  std::filesystem::create_symlink(target, link());
  opened = TmclPtyEndpoint::open(rig_.runtime->loop(), rig_.runtime->service(), link());
  EXPECT_FALSE(opened);
  EXPECT_EQ(opened.error(),
            link() + " is a symbolic link to " + target + ", not to a pseudo-terminal; not replacing it");
  EXPECT_EQ(std::filesystem::read_symlink(link()).string(), target);
}

// A live server's link is never taken over (a killed one's is: a_stale_link_is_replaced...): the
// claim is the name, however it is spelled, and it ends with its owner.
TEST_F(PtyEndpointTest, a_link_a_live_endpoint_owns_is_refused_and_free_again_once_it_closes) {
  open_endpoint();
  const std::string device = endpoint_->device_path();
  const std::string other_spelling = (scratch_.path() / "." / "tmcm1636").string();
  Result<std::unique_ptr<TmclPtyEndpoint>> second =
      TmclPtyEndpoint::open(rig_.runtime->loop(), rig_.runtime->service(), other_spelling);
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error(), other_spelling + " is the serial port of a running motwin; not taking it over (stop that "
                                             "one or choose another path)");
  EXPECT_EQ(std::filesystem::read_symlink(link()).string(), device) << "the owner's link is untouched";
  endpoint_.reset();
  Result<std::unique_ptr<TmclPtyEndpoint>> after =
      TmclPtyEndpoint::open(rig_.runtime->loop(), rig_.runtime->service(), link());
  ASSERT_TRUE(after) << after.error();
}

TEST_F(PtyEndpointTest, a_link_in_a_missing_directory_is_an_error) {
  Result<std::unique_ptr<TmclPtyEndpoint>> opened =
      TmclPtyEndpoint::open(rig_.runtime->loop(), rig_.runtime->service(), (scratch_.path() / "no" / "tty").string());
  EXPECT_FALSE(opened);
  EXPECT_NE(opened.error().find("No such file or directory"), std::string::npos) << opened.error();
}

}  // namespace
}  // namespace motwin::host

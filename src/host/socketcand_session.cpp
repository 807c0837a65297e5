#include "host/socketcand_session.h"

#include <optional>

namespace motwin::host {

void SocketcandSession::start() { io_.write("< hi >"); }

void SocketcandSession::push(std::string_view bytes) {
  elements_.clear();
  parser_.push(bytes, elements_);
  for (const std::string& element : elements_) {
    if (io_.closing()) return;
    handle(element);
  }
}

void SocketcandSession::frame_from_bus(const can::CanFrame& frame, uint64_t timestamp_us) {
  if (io_.closing() || mode_ != Mode::kRaw) return;
  io_.write(format_socketcand_frame(frame, timestamp_us));
}

void SocketcandSession::handle(const std::string& element) {
  const std::vector<std::string_view> words = socketcand_words(element);
  const std::string_view command = words.empty() ? std::string_view{} : words[0];
  switch (mode_) {
    case Mode::kAwaitOpen:
      if (command == "open" && words.size() == 2) {
        mode_ = Mode::kBcm;
        io_.write("< ok >");
      } else {
        error("expected open");
      }
      return;
    case Mode::kBcm:
    case Mode::kRaw:
      if (command == "send") {
        const Result<can::CanFrame> frame = parse_socketcand_send(words);
        if (!frame) {
          error(frame.error());
          return;
        }
        io_.send_to_bus(*frame);
      } else if (command == "rawmode" && words.size() == 1) {
        const bool entering = mode_ != Mode::kRaw;
        mode_ = Mode::kRaw;
        io_.write("< ok >");
        if (entering) io_.raw_mode_entered();
      } else if (command == "bcmmode" && words.size() == 1) {
        mode_ = Mode::kBcm;
        io_.write(" < ok >");
      } else if (command == "echo" && words.size() == 1) {
        io_.write(" < echo >");
      } else {
        error("unknown command");
      }
      return;
  }
}

void SocketcandSession::error(const std::string& text) { io_.write(" < error " + text + " >"); }

}  // namespace motwin::host

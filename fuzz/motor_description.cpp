// Motor description files (src/sim/modules/tmcm1636/motor_description.*): any JSON text.
//
// Invariants: a description that loads is written back by motor_description_json() as text that
// loads again and is written back identically (a fixed point after one round); a simulated
// board built on it runs 20 ms of control ticks at zero drive with finite readings. Text that
// does not load names the source in its error.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_support.h"
#include "sim/modules/tmcm1636/motor_description.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_board.h"
#include "sim/modules/tmcm1636/tmcm1636_sim_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motwin;
  if (size > 16 * 1024) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const Result<sim::MotorDescription> loaded = sim::parse_motor_description(text, "fuzz.json");
  if (!loaded) {
    FUZZ_CHECK(loaded.error().rfind("fuzz.json", 0) == 0, "error without its source: %s", loaded.error().c_str());
    return 0;
  }
  const std::string json = sim::motor_description_json(*loaded);
  const Result<sim::MotorDescription> again = sim::parse_motor_description(json, "written.json");
  FUZZ_CHECK(again.ok(), "the written description does not load: %s\n%s", again.error().c_str(), json.c_str());
  FUZZ_CHECK(sim::motor_description_json(*again) == json, "writing the description is not stable:\n%s",
             json.c_str());

  sim::Tmcm1636SimIo io;
  sim::Tmcm1636SimBoard board(io, *loaded);
  for (int tick = 0; tick < 400; ++tick) {
    board.before_tick();
    board.after_tick(50e-6);
  }
  for (const char* signal : {"SPEED_RPM", "POSITION_REV", "VBUS", "IQ_A"}) {
    const auto value = board.read_signal(signal);
    FUZZ_CHECK(value && std::isfinite(*value), "%s is %g after 20 ms at zero drive\n%s", signal, value ? *value : 0.0,
               json.c_str());
  }
  return 0;
}

// The TMCM-142's simulated board (src/sim/modules/tmcm142/tmcm142_sim_board.*) with its files: a stepper motor
// description (src/sim/stepper_motor_selection.*: any JSON text) and a scenario file against
// the board's signal table (src/sim/scenario.*), run under the TMCM-142 firmware.
//
// Input: byte 0 picks the motion the firmware runs (rotate either way, a position move, a
// reference search, none) and whether the motor JSON is used (else the ideal motor); then the
// motor JSON up to the first NUL byte; then the scenario text.
//
// Invariants:
// - a motor description that loads keeps the parser's promises: every real-valued field finite
//   and positive (detent, friction and viscous friction may be 0), full steps a multiple of 4
//   from 4 to 4000, a rotor the plant integrates stably (StepperPlant::step_number); text that
//   does not load names the source in its error;
// - a scenario that parses gives events sorted by time (file order among equal times), each on a
//   signal of the TMCM-142 table in its canonical spelling with a value it accepts, a time
//   within bounds and a line inside the text; errors name the source and line;
// - firmware and board until 20 ms after the last event (20 to 100 ms) with the events applied as
//   their times come (and all of them at the end): every reading finite (position, speed, coil
//   currents, torque; the ideal motor's speed from its position change, SPEED_RPM with the
//   range checks), the encoder count the firmware sees as the sensors compute it from the rotor
//   position (unless the encoder is faulty or an input changed in that tick), every writable
//   axis parameter inside its row's range (every 10 ms and at the end).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "board/ram_non_volatile_memory.h"
#include "core/modules/tmcm142/tmcm142.h"
#include "core/tmcl/instruction.h"
#include "fuzz_support.h"
#include "scenario_checks.h"
#include "sim/scenario.h"
#include "sim/stepper_motor_selection.h"
#include "sim/modules/tmcm142/tmcm142_sim_board.h"
#include "sim/modules/tmcm142/tmcm142_sim_io.h"

namespace {

using namespace motwin;
using Tmcm142 = modules::tmcm142::Tmcm142;
using Tmcm142Nvm = board::RamNonVolatileMemory<Tmcm142::kNvmLayout.total_size>;

void check_motor(const Result<sim::StepperMotorDescription>& loaded) {
  if (!loaded) {
    FUZZ_CHECK(loaded.error().rfind("fuzz-motor.json: ", 0) == 0, "error without its source: %s",
               loaded.error().c_str());
    return;
  }
  const sim::StepperMotorDescription& m = *loaded;
  for (double value : {m.resistance_ohm, m.inductance_h, m.torque_constant_nm_per_a, m.rotor_inertia_kg_m2,
                       m.rated_current_a}) {
    FUZZ_CHECK(std::isfinite(value) && value > 0.0, "a loaded motor with %g where a positive number belongs", value);
  }
  for (double value : {m.detent_torque_nm, m.friction_torque_nm, m.viscous_friction_nm_s}) {
    FUZZ_CHECK(std::isfinite(value) && value >= 0.0, "a loaded motor with %g where a number >= 0 belongs", value);
  }
  FUZZ_CHECK(m.full_steps_per_revolution >= 4 && m.full_steps_per_revolution <= 4000 &&
                 m.full_steps_per_revolution % 4 == 0,
             "full steps per revolution %d", m.full_steps_per_revolution);
  // The parser refuses motors whose explicit rotor integration would diverge.
  const double sub_step_s = modules::tmcm142::kControlTickS / sim::StepperPlant::kFinestSubSteps;
  FUZZ_CHECK(sim::StepperPlant::step_number(m, sub_step_s) <= sim::StepperPlant::kStableStepNumber,
             "a loaded motor the plant cannot integrate stably: step number %g",
             sim::StepperPlant::step_number(m, sub_step_s));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 32 * 1024) return 0;
  const uint8_t control = data[0];
  const std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  const size_t nul = rest.find('\0');
  const std::string_view json = rest.substr(0, nul);
  const std::string_view scenario = nul == std::string_view::npos ? std::string_view() : rest.substr(nul + 1);

  const Result<sim::StepperMotorDescription> motor = sim::parse_stepper_motor_description(json, "fuzz-motor.json");
  check_motor(motor);
  const Result<std::vector<sim::ScenarioEvent>> parsed =
      sim::parse_scenario(scenario, "fuzz.scn", sim::Tmcm142SimBoard::signal_table());
  if (!parsed.ok()) {
    FUZZ_CHECK(parsed.error().rfind("fuzz.scn:", 0) == 0, "error without its source: %s", parsed.error().c_str());
  }
  std::vector<sim::ScenarioEvent> events = parsed.ok() ? *parsed : std::vector<sim::ScenarioEvent>{};
  fuzz::check_scenario_events(events, scenario, sim::Tmcm142SimBoard::signal_table());
  if (std::getenv("MOTWIN_FUZZ_TRACE") != nullptr) {  // for reading a saved input
    std::fprintf(stderr, "motor: %s; scenario: %zu events %s\n", motor ? motor->name.c_str() : motor.error().c_str(),
                 events.size(), parsed.error().c_str());
  }
  const size_t event_count = events.size();
  // The run lasts until 20 ms after the last event (at least 20 ms, at most 100 ms): every event
  // of the first 100 ms is applied on time and has 20 ms of firmware after it, and an input
  // without events costs a fifth of the 100 ms (fuzz/README.md, Decisions).
  constexpr uint64_t kShortestRunUs = 20'000;
  constexpr uint64_t kLongestRunUs = 100'000;
  const uint64_t last_event_us = events.empty() ? 0 : events.back().time_us;
  const uint64_t run_us = std::min(std::min(last_event_us, kLongestRunUs) + kShortestRunUs, kLongestRunUs);

  // As Tmcm142VirtualModule::make and run_ticks wire them.
  auto io = std::make_unique<sim::Tmcm142SimIo>();
  const bool physical = (control & 1) != 0 && motor.ok();
  auto board = physical ? std::make_unique<sim::Tmcm142SimBoard>(*io, *motor)
                        : std::make_unique<sim::Tmcm142SimBoard>(*io);
  auto nvm = std::make_unique<Tmcm142Nvm>();
  Tmcm142::format_factory_image(nvm->mutable_data(), nvm->size());
  sim::ScenarioPlayer player(std::move(events), *board);
  player.apply_due(0);  // time-0 events are the initial inputs
  board->before_tick();
  auto module = std::make_unique<Tmcm142>(*nvm, board->power_stage(), *io);
  module->engine().power_up();

  const int32_t amount = static_cast<int32_t>((control >> 4) + 1) * 5000;
  const auto execute = [&](uint8_t command, uint8_t type, int32_t value) {
    module->engine().execute(tmcl::Instruction{command, type, 0, value}, tmcl::Origin::kHost);
  };
  switch ((control >> 1) & 7) {
    case 0: execute(tmcl::command::kRor, 0, amount * 20); break;
    case 1: execute(tmcl::command::kRol, 0, amount * 20); break;
    case 2: execute(tmcl::command::kMvp, 0, amount); break;
    case 3: execute(tmcl::command::kMvp, 0, -amount); break;
    case 4: execute(tmcl::command::kRfs, 0, 0); break;
    case 5:
      execute(tmcl::command::kSap, 193, (control >> 4) & 7);  // another reference search mode
      execute(tmcl::command::kRfs, 0, 0);
      break;
    default: break;  // standing still, powered
  }

  const auto ticks = static_cast<uint32_t>(run_us / modules::tmcm142::kControlTickUs);
  // Only an input (a scenario event) sets ENCODER_FAULT: read again when inputs changed.
  bool encoder_fault = board->read_signal("ENCODER_FAULT") != 0.0;
  double previous_position_rev = board->rotor_revolutions();
  for (uint32_t tick = 0; tick < ticks; ++tick) {
    const uint64_t now_us = uint64_t{tick} * modules::tmcm142::kControlTickUs;
    io->set_sim_time_us(now_us);
    const bool inputs_changed = player.apply_due(now_us) != 0;
    if (inputs_changed) encoder_fault = board->read_signal("ENCODER_FAULT") != 0.0;
    board->before_tick();
    if (!inputs_changed && !encoder_fault) {
      // The count the firmware sees is the one the sensors compute from the rotor position.
      const int32_t expected = board->sensors().encoder_count_at(board->rotor_revolutions());
      FUZZ_CHECK(board->power_stage().feedback.encoder_count == expected, "encoder count %d, rotor says %d at tick %u",
                 board->power_stage().feedback.encoder_count, expected, tick);
    }
    module->tick();
    board->after_tick(modules::tmcm142::kControlTickS);
    // The readings POSITION_REV, SPEED_RPM, COIL_A_A, COIL_B_A and TORQUE_NM, from the accessors
    // read_signal() answers them with (looking five names up per tick cost three quarters of
    // each input's time). The ideal motor's speed has no accessor: it is its tick's whole-number
    // electrical angle step over the tick (IdealStepper::advance), the same as the position's
    // change over the tick, which is checked every tick; SPEED_RPM itself with the ranges.
    const sim::StepperPlant* plant = board->plant();
    const double position_rev = board->rotor_revolutions();
    const double readings[] = {
        position_rev,
        plant ? plant->velocity_rps() : (position_rev - previous_position_rev) / modules::tmcm142::kControlTickS,
        plant ? plant->coil_a_current_a() : 0.0,
        plant ? plant->coil_b_current_a() : 0.0,
        plant ? plant->motor_torque_nm() : 0.0};
    static constexpr const char* kReadingNames[] = {"POSITION_REV", "the speed", "COIL_A_A", "COIL_B_A", "TORQUE_NM"};
    for (size_t i = 0; i < std::size(readings); ++i) {
      FUZZ_CHECK(std::isfinite(readings[i]), "%s is %g after tick %u", kReadingNames[i], readings[i], tick);
    }
    previous_position_rev = position_rev;
    if (tick % 200 == 199 || tick + 1 == ticks) {
      fuzz::check_axis_parameter_ranges(*module, "while running");
      const double speed_rpm = board->read_signal("SPEED_RPM").value_or(0.0);
      FUZZ_CHECK(std::isfinite(speed_rpm), "SPEED_RPM is %g after tick %u", speed_rpm, tick);
    }
  }
  const size_t applied_on_time = player.applied_count();
  const size_t applied_late = player.apply_due(UINT64_MAX);
  FUZZ_CHECK(applied_on_time + applied_late == event_count && player.finished(), "not every event was applied");
  board->before_tick();
  module->tick();
  fuzz::check_axis_parameter_ranges(*module, "after the scenario");
  return 0;
}

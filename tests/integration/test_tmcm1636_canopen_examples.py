#!/usr/bin/python3
"""Trinamic's TMCM-1636 CANopen example scripts (PyTrinamic) replayed in raw frames over the
socketcand server against `motwin serve --module tmcm-1636 --firmware canopen --motor
qbl4208-61-04-013`, the reference motor: the current example
examples/modules/TMCM1636/CANopen/PV/pv_position_moves_using_pdo.py (PyTrinamic 16bde95) and the
legacy ones of examples/modules/TMCM_1636/CANopen/ (encoder_pp, encoder_pv, hall_pv, openloop_pv,
encoder_hm, encoder_csp, encoder_csv, encoder_cst_mode.py, their last text, d6ece13 = c16d6f7^,
before PyTrinamic removed them). Each sends what the script sends through python-canopen 1.2.1 (the
version the scripts were tested with; its canopen/pdo/base.py, profiles/p402.py, sdo/client.py
make the traffic): SDO by name resolved with Trinamic's EDS, the 44 PDO-configuration uploads of
pdo.read(), BaseNode402's state changes by RPDO 1, each confirmed by a TPDO within 0.4 s. Each
test asserts the outcome its script waits for, with values.

Where the scripts sleep, the replay waits the same simulated time (the bus time stamped on the
socketcand frames, canopen_harness.CanopenClient.wait_sim); the scripts' loops without a timeout
get a bound in simulated time. The servers run 10 times as fast as the wall clock (the homing
replay, which reads a state right after starting the search, twice as fast). Sizes and signs of
the objects come from Trinamic's EDS (tests/data), as python-canopen takes them from there.
"""

import configparser
import contextlib
import os
import statistics
import struct
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import motwin_harness as mh  # noqa: E402
from canopen_harness import (  # noqa: E402
    NMT_PREOP, NMT_START, CanopenClient, TestFailure, check, check_equal, run_can_tests,
)
from motwin_harness import FRAME_TIMEOUT, TempDir  # noqa: E402

NODE = 1  # the scripts' node ID (hard-coded in PyTrinamic's addDs402Node)
SPEED = "10"
# The homing replay reads 6041 right after the frame that starts the search, which takes about
# 4.7 s of simulated time on this bench: at twice the wall clock a stall of two seconds between
# the two requests is needed to miss it.
HOMING_SPEED = "2"
REFERENCE_MOTOR = ["--motor", "qbl4208-61-04-013"]
# A right and a left switch three revolutions either side of the start whose inputs are high while
# the rotor is past them: active for 2005 = 0, the family's default polarity (docs/tmcm-1636-canopen.md).
SWITCHES = ["--set", "REF_R_AT=3", "--set", "REF_L_AT=-3"]
TRINAMIC_EDS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data",
                            "TMCM-1636-CANopen_Hw1.1_Fw1.12.eds")
# BaseNode402's state-change step: a TPDO must report the new state within 0.4 s of the RPDO.
STATE_STEP_TIMEOUT = 0.4

RPDO1, RPDO4 = 0x200 + NODE, 0x500 + NODE
TPDO1, TPDO2, TPDO3, TPDO4 = 0x180 + NODE, 0x280 + NODE, 0x380 + NODE, 0x480 + NODE
STATUSWORD_TPDOS = (TPDO1, TPDO2, TPDO3, TPDO4)  # every default TPDO maps 6041 first

# BaseNode402 (python-canopen 1.2.1) state masks, in its order; the current script's
# get_state() uses the same masks.
STATES = (
    ("NOT READY TO SWITCH ON", 0x4F, 0x00),
    ("SWITCH ON DISABLED", 0x4F, 0x40),
    ("READY TO SWITCH ON", 0x6F, 0x21),
    ("SWITCHED ON", 0x6F, 0x23),
    ("OPERATION ENABLED", 0x6F, 0x27),
    ("FAULT", 0x4F, 0x08),
    ("FAULT REACTION ACTIVE", 0x4F, 0x0F),
    ("QUICK STOP ACTIVE", 0x6F, 0x07),
)
SW_TARGET_REACHED, SW_SET_POINT_ACK, SW_HOMING_ERROR = 1 << 10, 1 << 12, 1 << 13
SW_WARNING, SW_HOMING_ATTAINED = 1 << 7, 1 << 12


def state_of(statusword):
    for name, mask, value in STATES:
        if statusword & mask == value:
            return name
    return None


def statusword_of(msg):
    """6041 of a default TPDO (mapped first in all four), else None."""
    if msg.arbitration_id in STATUSWORD_TPDOS and len(msg.data) >= 2:
        return struct.unpack_from("<H", bytes(msg.data))[0]
    return None


def load_trinamic_eds():
    eds = configparser.ConfigParser(interpolation=None, strict=False)
    eds.optionxform = str
    eds.read(TRINAMIC_EDS, encoding="latin-1")
    return eds


# python-canopen's (size, signed) of the EDS DataTypes the scripts touch.
DATA_TYPES = {0x1: (1, False), 0x2: (1, True), 0x3: (2, True), 0x4: (4, True), 0x5: (1, False), 0x6: (2, False),
              0x7: (4, False)}


class Tmcm1636CanopenServer(mh.Server):
    """`motwin serve --module tmcm-1636 --firmware canopen` on the reference motor, its bus
    served as socketcand on a free port."""

    BANNER = r"motwin: tmcm-1636 \(CANopen V1\.12\) eeprom (.+)"
    PORT_ENDPOINTS = {"can-socketcand": "can_port"}

    def __init__(self, motwin, state_dir, speed=SPEED, extra_args=()):
        super().__init__(motwin, state_dir, tcp=False, speed=speed,
                         extra_args=["--firmware", "canopen", "--can", "socketcand:127.0.0.1:0"] + REFERENCE_MOTOR +
                         list(extra_args))

    def bus(self):
        return CanopenClient(self.can_port)


class Master:
    """What python-canopen does for the scripts, in raw frames: SDO with the EDS's data types,
    NMT, RPDOs; `bus` is the master's client, `listener` a second client on the same bus that
    sees the master's frames with their bus times (opened while a replay measures them)."""

    def __init__(self, bus, eds):
        self.bus = bus
        self.eds = eds
        self.listener = None

    def close_listener(self):
        if self.listener is not None:
            self.listener.close()
            self.listener = None

    def _type(self, index, sub):
        section = f"{index:04X}" if f"{index:04X}sub0" not in self.eds else f"{index:04X}sub{sub:X}"
        check(section in self.eds, f"{index:04X} sub {sub} is not in Trinamic's EDS (python-canopen: KeyError)")
        return DATA_TYPES[int(self.eds[section]["DataType"], 0)]

    def read(self, index, sub=0):
        size, signed = self._type(index, sub)
        value = self.bus.upload_u(NODE, index, sub)
        return value - (1 << (8 * size)) if signed and value >= 1 << (8 * size - 1) else value

    def write(self, index, sub, value):
        size, _ = self._type(index, sub)
        self.bus.download(NODE, index, sub, value & ((1 << (8 * size)) - 1), size)

    def write_all(self, settings):
        for index, sub, value in settings:
            self.write(index, sub, value)

    def check_read_back(self, settings, reads):
        """The scripts' prints of the configuration: each read returns what was written."""
        written = {(index, sub): value for index, sub, value in settings}
        for index, sub in reads:
            check_equal(self.read(index, sub), written[(index, sub)], f"{index:04X} sub {sub} read back")

    def sim_now(self):
        return self.bus.sim_now(NODE)

    def wait_sim(self, seconds):
        self.bus.wait_sim(NODE, seconds)

    def wait_until(self, what, probe, done, sim_budget):
        """A script's loop without a timeout (`while not done(probe()): sleep`), bounded by
        `sim_budget` seconds of simulated time; the failure names the statusword and 6061."""
        try:
            return self.bus.poll_sim(NODE, probe, done, sim_budget, what, interval=0.01)
        except TestFailure as failure:
            statusword = self.bus.upload_u(NODE, 0x6041, 0)
            raise TestFailure(f"{failure}; 6041 = {statusword:#06x} ({state_of(statusword)}), "
                              f"6061 = {self.read(0x6061)}") from None

    # PDOs -------------------------------------------------------------------------------------
    def read_pdo_configuration(self):
        """python-canopen 1.2.1's pdo.read() (load_configuration() and setup_402_state_machine()
        make it): 44 uploads in its order, each checked against the EDS's defaults, which the
        scripts rely on (RPDO 1 / RPDO 4 / TPDO 4 layouts, COB-IDs valid)."""
        uploads = 0
        for index, sub, expected in PDO_CONFIGURATION_UPLOADS:
            check_equal(self.bus.upload_u(NODE, index, sub), expected, f"pdo.read(): {index:04X} sub {sub}")
            uploads += 1
        check_equal(uploads, 44, "pdo.read() uploads")

    def send_rpdo1(self, controlword):
        self.bus.send(RPDO1, struct.pack("<H", controlword))

    def state_step(self, controlword, target):
        """BaseNode402's `node.state = target` for one step: the controlword by RPDO 1, then its
        cached statusword (the last TPDO mapping 6041) must show the target within 0.4 s of the
        frame. The listener sees the RPDO and the TPDOs with their bus times; every TPDO carrying
        6041 after the first with the new state shows it too (BaseNode402 caches whichever comes
        last)."""
        listener = self.listener
        self.send_rpdo1(controlword)
        sent = listener.receive(lambda m: m.arbitration_id == RPDO1 and bytes(m.data) == struct.pack("<H", controlword),
                                FRAME_TIMEOUT, f"RPDO 1 controlword {controlword:#04x}")
        reported = listener.receive(lambda m: statusword_of(m) is not None and state_of(statusword_of(m)) == target,
                                    FRAME_TIMEOUT, f"a TPDO with the statusword of {target}")
        delay = reported.timestamp - sent.timestamp
        check(0 <= delay <= STATE_STEP_TIMEOUT,
              f"controlword {controlword:#04x}: {target} reported {delay:.4f} s (simulated) after the RPDO")
        later = self.bus.frames_seen_by(listener, NODE, lambda m: statusword_of(m) is not None)
        check_equal([state_of(statusword_of(m)) for m in later], [target] * len(later),
                    f"states of the TPDOs after controlword {controlword:#04x}")
        return statusword_of(later[-1]) if later else statusword_of(reported)


def pdo_configuration_uploads():
    """(index, sub, EDS default) of the 44 uploads of pdo.read(): per map the COB-ID, the
    transmission type, for types 254/255 of a TPDO the inhibit time and event timer (sub 3 and 5;
    the RPDO records have none), the mapping count and entries. RPDO COB-IDs carry bit 30."""
    uploads = []
    rpdo_maps = ([0x60400010], [0x60400010, 0x60600008], [0x60400010, 0x607A0020], [0x60400010, 0x60FF0020])
    for n, entries in enumerate(rpdo_maps):
        uploads += [(0x1400 + n, 1, 0x40000000 | (0x200 + 0x100 * n + NODE)), (0x1400 + n, 2, 0xFF),
                    (0x1600 + n, 0, len(entries))]
        uploads += [(0x1600 + n, i, entry) for i, entry in enumerate(entries, start=1)]
    tpdo_maps = ([0x60410010], [0x60410010, 0x60610008], [0x60410010, 0x60640020], [0x60410010, 0x606C0020])
    for n, (entries, transmission) in enumerate(zip(tpdo_maps, (0xFF, 0xFF, 0x01, 0xFE))):
        uploads += [(0x1800 + n, 1, 0x180 + 0x100 * n + NODE), (0x1800 + n, 2, transmission)]
        if transmission >= 254:
            uploads += [(0x1800 + n, 3, 0), (0x1800 + n, 5, 0)]
        uploads += [(0x1A00 + n, 0, len(entries))]
        uploads += [(0x1A00 + n, i, entry) for i, entry in enumerate(entries, start=1)]
    return uploads


PDO_CONFIGURATION_UPLOADS = pdo_configuration_uploads()


def velocity_of(msg):
    """606C of TPDO 4 (6041 u16, 606C i32)."""
    return struct.unpack_from("<i", bytes(msg.data), 2)[0]


# --- The current example ------------------------------------------------------------------------

def sdo_go_to_operation_enabled(master):
    """The script's go_to_operation_enabled(): 6041 read by SDO and decoded; from
    'Switch on disable' the controlwords 6, 7, 15 by SDO, each followed by sleep(0.1) and a
    loop reading 6041 until the expected state (no timeout; 'Fault' raises)."""
    state = state_of(master.read(0x6041))
    # Any state but these crashes the script (KeyError); at power-up it is switch on disabled.
    check_equal(state, "SWITCH ON DISABLED", "6041 before go_to_operation_enabled()")
    for controlword, target in ((6, "READY TO SWITCH ON"), (7, "SWITCHED ON"), (15, "OPERATION ENABLED")):
        master.write(0x6040, 0, controlword)
        master.wait_sim(0.1)
        statusword = master.wait_until(f"6041 after controlword {controlword}", lambda: master.read(0x6041),
                                       lambda sw: state_of(sw) in (target, "FAULT"), 5.0)
        check(state_of(statusword) == target,
              f"controlword {controlword}: 6041 = {statusword:#06x} (StateMachineFault)")


# 606C is measured, and jitters most where a motion starts: a ramp may go back by 30 rpm, two
# ABN counts (of 4096 per revolution) in a millisecond.
MEASUREMENT_STEPS_RPM = 30


def check_ramp(samples, since, window, start, target, acceleration, what):
    """TPDO 4 samples (bus time, 606C) of a velocity step from `start` to `target` at
    `acceleration` rpm/s taken `since` for `window` seconds: a sample about every millisecond
    while the velocity changes, not many more, a monotone ramp (within the measurement's
    resolution) at the profile's slope, no more than 10 rpm of overshoot, then a steady value
    within 5 rpm of the target."""
    check(samples, f"{what}: no TPDO 4")
    times = [t - since for t, _ in samples]
    values = [v for _, v in samples]
    check(abs(values[0] - start) <= 5, f"{what}: first sample {values[0]} rpm")
    nominal = abs(target - start) / acceleration
    reached = next((i for i, v in enumerate(values) if abs(v - target) <= 5), None)
    check(reached is not None, f"{what}: {target} rpm not reached; last samples {values[-10:]}")
    check(0.8 * nominal <= times[reached] <= nominal + 0.15,
          f"{what}: within 5 rpm of {target} after {times[reached]:.3f} s (the profile takes {nominal:.3f} s)")
    direction = 1 if target > start else -1
    ramp = values[:reached + 1]
    best = ramp[0]
    for v in ramp:
        check(direction * (v - best) >= -MEASUREMENT_STEPS_RPM,
              f"{what}: the ramp goes back from {best} to {v} rpm: {ramp[::10]}")
        best = max(best, v) if direction > 0 else min(best, v)
    # Slope between a quarter and three quarters of the step.
    quarter, three_quarters = start + (target - start) / 4, start + 3 * (target - start) / 4
    t1 = next(t for t, v in zip(times, values) if direction * (v - quarter) >= 0)
    t2 = next(t for t, v in zip(times, values) if direction * (v - three_quarters) >= 0)
    slope = abs(target - start) / 2 / (t2 - t1)
    check(0.8 * acceleration <= slope <= 1.25 * acceleration, f"{what}: ramp slope {slope:.0f} rpm/s")
    check(reached + 1 >= 0.6 * times[reached] * 1000,
          f"{what}: {reached + 1} TPDO 4 in the {times[reached]:.3f} s ramp")
    # One look for a change per service millisecond, and one more after each frame the node
    # receives (an SDO request of the replay): about one per millisecond in all.
    check(len(times) <= 1.05 * window * 1000 + 20, f"{what}: {len(times)} TPDO 4 in {window} s")
    overshoot = max(direction * (v - target) for v in values)
    check(overshoot <= 10, f"{what}: {overshoot} rpm of overshoot")
    settled = [v for t, v in zip(times, values) if t >= times[reached] + 0.5]
    check(all(abs(v - target) <= 5 for v in settled), f"{what}: not steady at {target} rpm: {settled[::20]}")
    check(abs(values[-1] - target) <= 5, f"{what}: last sample {values[-1]} rpm")


def sent_at(bus, listener, cob_id, data):
    """Sends a frame; returns its bus time (simulated seconds) as `listener`, a second socketcand
    client on the bus, sees it."""
    bus.send(cob_id, data)
    return listener.receive(lambda m: m.arbitration_id == cob_id and bytes(m.data) == data, FRAME_TIMEOUT,
                            f"the frame {cob_id:#x} {data.hex()}").timestamp


def in_window(frames, since):
    """The frames stamped at or after `since` (collect_sim also returns those that came between
    the last marker and `since`)."""
    return [m for m in frames if m.timestamp >= since]


def test_pv_position_moves_using_pdo(motwin):
    """pv_position_moves_using_pdo.py: the phase ADC offsets calibrated with the motor off
    (2055 = 0), the encoder, profile and window settings, 2055 = 3, 6060 = 3 (pv),
    load_configuration() (44 uploads), NMT start, the SDO state walk 6 / 7 / 15, RPDO 4
    controlword 15 with 60FF = 500, 5 s, 60FF = 0, 2 s, NMT pre-operational. The script plots
    the TPDO 4 samples (606C): they ramp at 6083 = 2000 rpm/s to 500 rpm, hold it, and ramp
    back to 0."""
    eds = load_trinamic_eds()
    with TempDir() as tmp, Tmcm1636CanopenServer(motwin, os.path.join(tmp, "state")) as server, \
            server.bus() as bus:
        master = Master(bus, eds)
        last_commutation_mode = master.read(0x2055)
        master.write(0x2055, 0, 0)
        for raw, offset in ((1, 3), (2, 4)):
            samples = [master.read(0x2060, raw) for _ in range(40)]
            mean = round(statistics.mean(samples))
            check(abs(mean - 32768) <= 500,
                  f"2060 sub {raw}: the phase ADC of the motor at rest reads {mean}, not mid-scale")
            master.write(0x2060, offset, mean)
            check_equal(master.read(0x2060, offset), mean, f"2060 sub {offset} (offset) read back")
        master.write(0x2055, 0, last_commutation_mode)
        master.write_all(((0x2080, 1, 1), (0x2080, 2, 4096), (0x6083, 0, 2000), (0x6081, 0, 4000)))
        steps = master.read(0x2080, 2)
        check_equal(steps, 4096, "2080 sub 2 read back")
        master.write(0x2058, 0, steps)
        master.write(0x6067, 0, int(master.read(0x2080, 2) / 8))
        master.write_all(((0x6068, 0, 100), (0x2055, 0, 3), (0x6060, 0, 3)))
        master.check_read_back(((0x2058, 0, 4096), (0x6067, 0, 512), (0x6068, 0, 100), (0x2055, 0, 3), (0x6060, 0, 3)),
                               ((0x2058, 0), (0x6067, 0), (0x6068, 0), (0x2055, 0), (0x6060, 0)))
        master.read_pdo_configuration()
        bus.nmt(NMT_START, NODE)
        sdo_go_to_operation_enabled(master)

        # The ramps are timed from the RPDOs' bus times, as a second client on the bus sees them:
        # a busy host delays a frame by milliseconds of simulated time after a sim_now().
        with server.bus() as listener:
            since = sent_at(bus, listener, RPDO4, struct.pack("<Hi", 15, 500))
            up = in_window(bus.collect_sim(NODE, 5.0, lambda m: m.arbitration_id == TPDO4, since=since), since)
            since_stop = sent_at(bus, listener, RPDO4, struct.pack("<Hi", 15, 0))
            down = in_window(bus.collect_sim(NODE, 2.0, lambda m: m.arbitration_id == TPDO4, since=since_stop),
                             since_stop)
        for msg in up + down:
            check_equal(len(msg.data), 6, "TPDO 4 length (6041 + 606C)")
            check_equal(state_of(statusword_of(msg)), "OPERATION ENABLED", f"TPDO 4 state ({bytes(msg.data).hex()})")
        check_ramp([(m.timestamp, velocity_of(m)) for m in up], since, 5.0, 0, 500, 2000, "60FF = 500")
        check_ramp([(m.timestamp, velocity_of(m)) for m in down], since_stop, 2.0, 500, 0, 2000, "60FF = 0")
        check_equal(velocity_of(down[-1]), 0, "the last TPDO 4: 606C")
        check(statusword_of(down[-1]) & SW_TARGET_REACHED, f"the last TPDO 4: 6041 {statusword_of(down[-1]):#06x} "
                                                           "without bit 10 (target velocity reached)")
        bus.nmt(NMT_PREOP, NODE)
        bus.frames_until_marker(NODE)
        check_equal(bus.collect_sim(NODE, 0.2, lambda m: m.arbitration_id in STATUSWORD_TPDOS), [],
                    "TPDOs in pre-operational")
        server.stop()


# --- The legacy examples ------------------------------------------------------------------------

def setup_402_state_machine(master):
    """BaseNode402.setup_402_state_machine(): NMT pre-operational, pdo.read(), NMT start; its
    `state = 'SWITCH ON DISABLED'` finds the cached statusword of the TPDOs sent on entering
    operational (otherwise it would send controlword 0 and wait 0.4 s for a TPDO)."""
    master.bus.nmt(NMT_PREOP, NODE)
    master.read_pdo_configuration()
    master.bus.nmt(NMT_START, NODE)
    listener = master.listener
    nmt = listener.receive(lambda m: m.arbitration_id == 0 and bytes(m.data) == bytes([NMT_START, NODE]),
                           FRAME_TIMEOUT, "NMT start")
    first = listener.receive(lambda m: statusword_of(m) is not None, FRAME_TIMEOUT, "a TPDO on entering operational")
    check(first.timestamp - nmt.timestamp <= STATE_STEP_TIMEOUT,
          f"the first TPDO {first.timestamp - nmt.timestamp:.4f} s (simulated) after NMT start")
    check_equal(state_of(statusword_of(first)), "SWITCH ON DISABLED", f"TPDO {first.arbitration_id:#x} after NMT start")


def legacy_start(master, mode, settings, reads, switch_parameters=3, before_start=()):
    """What every legacy script does before its body: addDs402Node() and the script itself each
    call setup_402_state_machine(); 1008 and 1009 printed; the configuration written and printed;
    reset_from_fault() (nothing: the cached state is not FAULT); `before_start` (homing: 2005 and
    6098); startXX(): 2005 = 3 (not in homing), READY TO SWITCH ON and SWITCHED ON by RPDO 1, 6060
    read, written, read, OPERATION ENABLED."""
    setup_402_state_machine(master)
    setup_402_state_machine(master)
    check_equal(master.bus.upload(NODE, 0x1008, 0), b"TMCM-1636", "1008 Manufacturer Device Name")
    check_equal(master.bus.upload(NODE, 0x1009, 0), b"1.1", "1009 Manufacturer Hardware Version")
    master.write_all(settings)
    master.check_read_back(settings, reads)
    master.write_all(before_start)
    if switch_parameters is not None:
        master.write(0x2005, 0, switch_parameters)
    master.state_step(0x06, "READY TO SWITCH ON")
    master.state_step(0x07, "SWITCHED ON")
    if master.read(0x6060) != mode:
        master.write(0x6060, 0, mode)
    check_equal(master.read(0x6060), mode, "MODE OF OPERATION SET TO")
    return master.state_step(0x0F, "OPERATION ENABLED")


@contextlib.contextmanager
def legacy_replay(motwin, speed=SPEED, extra_args=()):
    """A fresh server, the master's client and a listener for the start of a legacy script:
    yields (server, master); master.listener until master.close_listener() (a client that
    stops reading would pile up the TPDO stream of a long body until the server drops it)."""
    with TempDir() as tmp, Tmcm1636CanopenServer(motwin, os.path.join(tmp, "state"), speed=speed,
                                                 extra_args=extra_args) as server, server.bus() as bus:
        master = Master(bus, load_trinamic_eds())
        master.listener = server.bus()
        try:
            yield server, master
        finally:
            master.close_listener()


ENCODER_READS = ((0x2056, 0), (0x2055, 0), (0x2080, 2), (0x2080, 1))


def test_encoder_pp_mode(motwin):
    """encoder_pp_mode.py: ABN encoder, 4096 steps and position scaler 4096, 6081 = 1000 rpm,
    6083 = 500 rpm/s; 607A = 50 x 2080 sub 2 (50 revolutions), RPDO 1 controlword 0x0F and 0x1F
    back to back (the new set-point edge), then its loop until |607A - 6064| < 100; 607A = 0 and
    the same. Half a second after each the motor still holds the target."""
    settings = ((0x2056, 0, 4), (0x2003, 0, 1500), (0x6081, 0, 1000), (0x2055, 0, 3), (0x2080, 1, 1),
                (0x2080, 2, 4096), (0x2058, 0, 4096), (0x6083, 0, 500))
    with legacy_replay(motwin) as (server, master):
        legacy_start(master, 1, settings, ENCODER_READS)
        master.close_listener()
        for target in (master.read(0x2080, 2) * 50, 0):
            master.write(0x607A, 0, target)
            check_equal(master.read(0x607A), target, "607A read back")
            master.send_rpdo1(0x0F)
            master.send_rpdo1(0x1F)
            try:
                master.wait_until(f"|607A - 6064| < 100 moving to {target}",
                                  lambda: (master.read(0x607A), master.read(0x6064)),
                                  lambda v: abs(v[0] - v[1]) < 100, 15.0)
            except TestFailure as failure:
                # What a refused set-point looks like (bit 7 warning, bit 12 never set).
                raise TestFailure(f"{failure}; 6081 = {master.read(0x6081)}, 6083 = {master.read(0x6083)}, "
                                  f"6084 = {master.read(0x6084)} (the script leaves 6084 at the EDS default)") from None
            master.wait_sim(0.5)
            position = master.read(0x6064)
            check(abs(position - target) < 100, f"6064 {position} half a second after reaching {target}")
        server.stop()


def pv_body(master):
    """The body of the three pv scripts: 60FF = 2000, loop until |606C - 60FF| < 10, hold 3 s,
    60FF = 0, loop until |606C| < 10. The velocity is still within 10 rpm of 2000 after the hold
    and stays at 0 half a second after the stop."""
    master.write(0x60FF, 0, 2000)
    master.wait_until("|606C - 60FF| < 10 at 2000 rpm", lambda: (master.read(0x606C), master.read(0x60FF)),
                      lambda v: v[1] == 2000 and abs(v[0] - v[1]) < 10, 15.0)
    master.wait_sim(3.0)
    velocity = master.read(0x606C)
    check(abs(velocity - 2000) < 10, f"606C {velocity} rpm after holding 2000 rpm for 3 s")
    master.write(0x60FF, 0, 0)
    check_equal(master.read(0x60FF), 0, "60FF read back")
    master.wait_until("|606C - 60FF| < 10 at 0 rpm", lambda: (master.read(0x606C), master.read(0x60FF)),
                      lambda v: v[1] == 0 and abs(v[0]) < 10, 15.0)
    master.wait_sim(0.5)
    velocity = master.read(0x606C)
    check(abs(velocity) < 10, f"606C {velocity} rpm half a second after reaching 0")


def test_encoder_pv_mode(motwin):
    """encoder_pv_mode.py: three-phase BLDC with 4 pole pairs, ABN encoder (4096 steps, direction
    1, initialisation mode 0), 6083 = 500 rpm/s, pv: 2000 rpm and back to 0."""
    settings = ((0x2056, 0, 4), (0x2050, 0, 3), (0x2003, 0, 1500), (0x2004, 0, 1500), (0x2080, 2, 4096),
                (0x2080, 1, 1), (0x2080, 3, 0), (0x2055, 0, 3), (0x6083, 0, 500))
    with legacy_replay(motwin) as (server, master):
        legacy_start(master, 3, settings, ENCODER_READS)
        master.close_listener()
        pv_body(master)
        server.stop()


def test_hall_pv_mode(motwin):
    """hall_pv_mode.py: digital hall commutation (2055 = 2; hall direction 0, polarity 1, offset
    0), 6083 = 500 rpm/s, pv: 2000 rpm and back to 0."""
    settings = ((0x2056, 0, 4), (0x2003, 0, 1500), (0x2055, 0, 2), (0x2070, 2, 0), (0x2070, 1, 1), (0x2070, 4, 0),
                (0x6083, 0, 500))
    reads = ((0x2056, 0), (0x2055, 0), (0x2070, 2), (0x2070, 1), (0x2070, 4))
    with legacy_replay(motwin) as (server, master):
        legacy_start(master, 3, settings, reads)
        master.close_listener()
        pv_body(master)
        server.stop()


def test_openloop_pv_mode(motwin):
    """openloop_pv_mode.py: open-loop commutation (2055 = 1) with 1000 mA, 6083 = 500 rpm/s, pv:
    606C converges on 2000 rpm and back to 0 as in closed loop."""
    settings = ((0x2056, 0, 4), (0x2004, 0, 1000), (0x2003, 0, 1500), (0x2055, 0, 1), (0x6083, 0, 500))
    with legacy_replay(motwin) as (server, master):
        legacy_start(master, 3, settings, ((0x2056, 0), (0x2055, 0)))
        master.close_listener()
        pv_body(master)
        server.stop()


def test_encoder_hm_mode(motwin):
    """encoder_hm_mode.py: homing method 17 (negative limit switch) with the switches used
    (2005 = 0), fast 1000 rpm, slow 500 rpm, 500 rpm/s; RPDO 1 0x1F, then the script reads 6041
    by SDO until bit 10 is set. Right after the start bit 10 is clear (else the script would end
    at once), it sets with bit 12 (homing attained) and without bit 13, and 6064 is then the home
    offset, 0, within one encoder step. The TPDOs show the same: bit 10 comes back only with bit 12."""
    settings = ((0x2056, 0, 4), (0x2003, 0, 1500), (0x2055, 0, 3), (0x2080, 2, 4096), (0x2080, 1, 1))
    with legacy_replay(motwin, speed=HOMING_SPEED, extra_args=SWITCHES) as (server, master):
        # After the configuration's prints: the homing speeds and acceleration; after
        # reset_from_fault(): 2005 = 0 (switches used, default polarity) and method 17.
        homing = ((0x6099, 1, 1000), (0x6099, 2, 500), (0x609A, 0, 500), (0x2005, 0, 0), (0x6098, 0, 17))
        legacy_start(master, 6, settings, ENCODER_READS, switch_parameters=None, before_start=homing)
        check_equal(master.read(0x60FD) & 0x3, 0, "60FD: neither limit switch active at the start")
        master.send_rpdo1(0x1F)
        statusword = master.read(0x6041)
        check_equal(statusword & SW_TARGET_REACHED, 0, f"6041 {statusword:#06x} right after 0x1F: bit 10")
        statusword = master.wait_until("6041 bit 10 (homing)", lambda: master.read(0x6041),
                                       lambda sw: sw & SW_TARGET_REACHED, 20.0)
        check_equal(statusword & (SW_HOMING_ATTAINED | SW_HOMING_ERROR), SW_HOMING_ATTAINED,
                    f"6041 {statusword:#06x}: bit 12 (attained) without bit 13 (error)")
        # 6064 counts 2058 units per revolution (65536 by default) of an encoder with 2080:2 steps:
        # at rest the servo stays within one encoder step of the home offset.
        encoder_step = master.read(0x2058) // master.read(0x2080, 2)
        position = master.read(0x6064)
        check(abs(position) <= encoder_step,
              f"6064 after homing: {position}, more than one encoder step ({encoder_step}) from the home offset 607C = 0")
        check_equal(master.read(0x607C), 0, "607C")
        master.send_rpdo1(0x0F)
        frames = master.bus.frames_seen_by(master.listener, NODE, lambda m: m.arbitration_id in (RPDO1, TPDO1))
        started = next(i for i, m in enumerate(frames) if m.arbitration_id == RPDO1 and bytes(m.data) == b"\x1f\x00")
        reported = [statusword_of(m) for m in frames[started:] if m.arbitration_id == TPDO1]
        done = next((i for i, sw in enumerate(reported) if sw & SW_TARGET_REACHED), None)
        check(done is not None and done > 0, f"TPDO 1 statuswords after 0x1F: {[hex(sw) for sw in reported]}")
        check(reported[done] & SW_HOMING_ATTAINED, f"TPDO 1 statuswords after 0x1F: {[hex(sw) for sw in reported]}")
        server.stop()


def test_encoder_csp_mode(motwin):
    """encoder_csp_mode.py: ABN encoder, 2058 = 4096, the script's gains (2041 1000/1000, 2042
    2000/100, 2043 sub 1 10), csp without SYNC: 607A stepped by SDO to 4096 x r for r = 0..9, one
    step per second, then the loop until |607A - 6064| < 100; 607A = 0 and the same."""
    settings = ((0x2056, 0, 4), (0x2003, 0, 1500), (0x2055, 0, 3), (0x2080, 2, 4096), (0x2058, 0, 4096),
                (0x2080, 1, 1), (0x6083, 0, 500))
    gains = ((0x2041, 1, 1000), (0x2041, 2, 1000), (0x2042, 1, 2000), (0x2042, 2, 100), (0x2043, 1, 10))
    with legacy_replay(motwin) as (server, master):
        legacy_start(master, 8, settings, ENCODER_READS, before_start=gains)
        master.close_listener()
        positions = []
        for rotations in range(10):
            master.write(0x607A, 0, master.read(0x2080, 2) * rotations)
            check_equal(master.read(0x607A), 4096 * rotations, "607A read back")
            positions.append(master.read(0x6064))
            master.wait_sim(1.0)
        check(all(b >= a - 100 for a, b in zip(positions, positions[1:])) and positions[-1] > 4096 * 7,
              f"6064 follows the steps: {positions}")
        for target in (36864, 0):
            if target == 0:
                master.write(0x607A, 0, 0)
                check_equal(master.read(0x607A), 0, "607A read back")
            master.wait_until(f"|607A - 6064| < 100 at {target}", lambda: (master.read(0x607A), master.read(0x6064)),
                              lambda v: abs(v[0] - v[1]) < 100, 10.0)
        server.stop()


def test_encoder_csv_mode(motwin):
    """encoder_csv_mode.py: csv without SYNC, 60FF stepped by SDO 0, 200, ..., 2000 rpm, one step
    per second, then the loop until |606C - 60FF| < 10, 3 s, 60FF = 0 and the same."""
    settings = ((0x2056, 0, 4), (0x2003, 0, 1500), (0x2055, 0, 3), (0x2080, 2, 4096), (0x2080, 1, 1))
    with legacy_replay(motwin) as (server, master):
        legacy_start(master, 9, settings, ENCODER_READS)
        master.close_listener()
        for velocity in range(0, 2001, 200):
            master.write(0x60FF, 0, velocity)
            check_equal(master.read(0x60FF), velocity, "60FF read back")
            master.read(0x606C)
            master.wait_sim(1.0)
            actual = master.read(0x606C)
            check(abs(actual - velocity) < 10, f"606C {actual} rpm a second after 60FF = {velocity}")
        master.wait_until("|606C - 60FF| < 10 at 2000 rpm", lambda: (master.read(0x606C), master.read(0x60FF)),
                          lambda v: abs(v[0] - v[1]) < 10, 10.0)
        master.wait_sim(3.0)
        master.write(0x60FF, 0, 0)
        check_equal(master.read(0x60FF), 0, "60FF read back")
        master.wait_until("|606C - 60FF| < 10 at 0 rpm", lambda: (master.read(0x606C), master.read(0x60FF)),
                          lambda v: abs(v[0] - v[1]) < 10, 10.0)
        server.stop()


def test_encoder_cst_mode(motwin):
    """encoder_cst_mode.py: cst, 6071 = 1000, 3 s, -1000, 3 s, 0, each read back (all the script
    checks). Beyond it: the TPDO 4 samples meanwhile show the motor accelerating in the
    commanded direction (and coasting down at 0); then, with TPDO 2 remapped to 6041, 6077 and
    606C, the actual torque follows 6071 while the motor accelerates."""
    settings = ((0x2056, 0, 4), (0x2003, 0, 1500), (0x2055, 0, 3), (0x2080, 2, 4096), (0x2080, 1, 1))
    with legacy_replay(motwin) as (server, master):
        legacy_start(master, 10, settings, ENCODER_READS)
        master.close_listener()
        bus = master.bus
        for torque in (1000, -1000, 0):
            since = master.sim_now()
            master.write(0x6071, 0, torque)
            check_equal(master.read(0x6071), torque, "6071 read back")
            frames = bus.collect_sim(NODE, 3.0, lambda m: m.arbitration_id == TPDO4, since=since)
            velocities = [velocity_of(m) for m in frames]
            check(len(velocities) > 100, f"6071 = {torque}: {len(velocities)} TPDO 4 in 3 s")
            if torque:
                sign = 1 if torque > 0 else -1
                early = [v for m, v in zip(frames, velocities) if m.timestamp - since <= 0.1]
                check(all(sign * (b - a) >= -20 for a, b in zip(early, early[1:])),
                      f"6071 = {torque}: 606C does not accelerate that way: {early[::5]}")
                check(sign * velocities[-1] > 3000, f"6071 = {torque}: 606C {velocities[-1]} rpm after 3 s")
            else:
                check(abs(velocities[-1]) < abs(velocities[0]),
                      f"6071 = 0: 606C from {velocities[0]} to {velocities[-1]}")
        # Beyond the script: 6077 in a TPDO with the velocity.
        master.wait_until("606C = 0 with 6071 = 0", lambda: master.read(0x606C), lambda v: v == 0, 5.0)
        bus.configure_pdo(NODE, 0x1801, TPDO2, 0xFF, [0x60410010, 0x60770010, 0x606C0020])
        for torque in (1000, -1000):
            master.write(0x6071, 0, torque)
            # From the write's confirmation: the node took 6071 at the latest then (a busy host
            # delays the request itself by milliseconds of simulated time).
            since = master.sim_now()
            frames = bus.collect_sim(NODE, 0.5, lambda m: m.arbitration_id == TPDO2, since=since)
            samples = [struct.unpack_from("<hi", bytes(m.data), 2) + (m.timestamp - since,) for m in frames]
            # While the motor accelerates towards the commanded direction, up to 3000 rpm, after
            # the first 10 ms (the current regulator's rise).
            accelerating = [actual for actual, velocity, t in samples
                            if t >= 0.01 and torque * velocity >= 0 and abs(velocity) < 3000]
            check(len(accelerating) >= 10, f"6071 = {torque}: samples {samples[:20]}")
            mean = statistics.mean(accelerating)
            check(abs(mean - torque) <= 150 and all(a * torque > 0 for a in accelerating),
                  f"6071 = {torque}: 6077 while accelerating {accelerating[::5]} (mean {mean:.0f} mA)")
        master.write(0x6071, 0, 0)
        server.stop()


if __name__ == "__main__":
    run_can_tests([test_pv_position_moves_using_pdo, test_encoder_pp_mode, test_encoder_pv_mode, test_hall_pv_mode,
                   test_openloop_pv_mode, test_encoder_hm_mode, test_encoder_csp_mode, test_encoder_csv_mode,
                   test_encoder_cst_mode])

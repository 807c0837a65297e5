#!/usr/bin/python3
"""The web console on the TMCM-1636's CANopen firmware (`serve --module tmcm-1636 --firmware
canopen`, docs/tmcm-1636-canopen.md), alone and as a `--node` beside a TMCM-3216, as it serves the
TMCM-3216 (docs/web-console.md): over the WebSocket protocol (python3-websocket) the object listing
is Trinamic's EDS 1.12 entry for entry with its names, values read and written by SDO (a CAN master
on socketcand reads what the console wrote), the NMT state heard, TPDO 4 (0x480 + node) in the bus
monitor while the drive ramps in pv, the board's simulated signals set from the console and read by
the firmware (2702, 60FD, 270E), and the shaft of a physical motor following a profile position
move. In headless Chromium (Selenium): the Parameters view's objects and an edit, SDO from the
Console view, the CANopen view (NMT, the statusword decoded, the PDO table named as on the
TMCM-3216, TPDO 4 in the monitor), the World view's controls seen by the firmware and its drawn
shaft following the move, and a node of a bus. Screenshots: <build>/test-artefacts/web-browser/
tmcm1636-canopen*.png."""

import configparser
import os
import re
import struct
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import motwin_harness as mh  # noqa: E402
from canopen_harness import CanopenClient, run_can_tests  # noqa: E402
from motwin_harness import TempDir, check, check_equal  # noqa: E402
import browser_harness as bh  # noqa: E402
import web_harness as wh  # noqa: E402

try:  # without Selenium, bh.HeadlessChromium skips the browser tests before any of these is used
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import Select
except ImportError:  # pragma: no cover - reported as a skip
    pass

TRINAMIC_EDS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data",
                            "TMCM-1636-CANopen_Hw1.1_Fw1.12.eds")
REFERENCE_MOTOR = "qbl4208-61-04-013"
POSITION_UNITS_PER_REV = 65536  # 2058 Position Scaler's default
PV_VELOCITY = 300               # rpm
PV_ACCELERATION = 2000          # rpm/s (6083 is 0 by default: no ramp would start)
PP_VELOCITY = 60                # rpm: two turns take two simulated seconds
SUPPLY_FULL_SCALE_V = 66.0      # ADC_VM (270E sub 3): 12 bits of 0..66 V (the VSUPPLY signal's description)
SAMPLED_AFTER_US = 2000         # simulated time after which a switch set in the world shows in 60FD
CONDITION_TIMEOUT = 30.0        # wall seconds: a liveness bound for what must come


class CanopenWebServer(wh.WebServer):
    """`motwin serve --module tmcm-1636 --firmware canopen [--motor M]` on socketcand with the web
    console, both on free ports."""

    BANNER = r"motwin: tmcm-1636 \(CANopen V1\.12\) eeprom (.+)"
    PORT_ENDPOINTS = {"can-socketcand": "can_port", "web": "web_port"}

    def __init__(self, motwin, state_dir, motor=None):
        motor_args = ["--motor", motor] if motor else []
        super().__init__(motwin, state_dir, tcp=False,
                         extra_args=["--firmware", "canopen", "--can", "socketcand:127.0.0.1:0", *motor_args])


class CanopenBusServer(wh.WebBusServer):
    """`motwin serve --node tmcm-1636:firmware=canopen,node-id=5 --node tmcm-3216:node-id=1`."""

    FIRST_NODE = "tmcm-1636:firmware=canopen,node-id=5"
    BANNER = r"motwin: node tmcm-1636-1 tmcm-1636 \(CANopen V1\.12\) eeprom (.+)"


def wait_until(description, condition):
    """Polls `condition` (each poll a request to the serve) until it holds."""
    return mh.poll_until(description, condition, CONDITION_TIMEOUT, interval=0.01)


def eds_entries():
    """{(index, sub): name} of every entry of Trinamic's EDS, named as the console lists a
    sub-index: "OBJECT: SUB"."""
    eds = configparser.ConfigParser(interpolation=None, strict=True)
    eds.optionxform = str
    with open(TRINAMIC_EDS, encoding="latin-1") as f:
        eds.read_file(f)
    names = {}
    for section in eds.sections():
        m = re.fullmatch(r"([0-9A-Fa-f]{4})(?:[sS][uU][bB]([0-9A-Fa-f]{1,2}))?", section)
        if not m:
            continue
        index = int(m.group(1), 16)
        if m.group(2) is None:
            if "SubNumber" not in eds[section]:
                names[(index, 0)] = eds[section]["ParameterName"]
        else:
            names[(index, int(m.group(2), 16))] = f'{eds[m.group(1)]["ParameterName"]}: {eds[section]["ParameterName"]}'
    return names


def listed_objects(module):
    return {(o["index"], o["sub"]): o for section in module["sections"] if section["kind"] == "objects"
            for o in section["objects"]}


def sdo(console, module, op, index, sub=0, **fields):
    reply = console.ask(op, module=module, index=index, sub=sub, **fields)
    check(reply["ok"], f"{op} {index:04X}.{sub}: {reply}")
    return reply


def read(console, module, index, sub=0):
    return sdo(console, module, "sdo_read", index, sub)["value"]


def write_all(console, module, writes):
    for index, sub, value in writes:
        sdo(console, module, "sdo_write", index, sub, value=value)


def enable_pv(console, module, velocity):
    """pv with a ramp, the drive enabled, 60FF = velocity (as PyTrinamic's pv example, ideal motor)."""
    write_all(console, module, ((0x6083, 0, PV_ACCELERATION), (0x6060, 0, 3), (0x6040, 0, 6), (0x6040, 0, 7),
                                (0x6040, 0, 15), (0x60FF, 0, velocity)))


def move_to(console, target):
    """A profile position move (pp) to `target`, at PP_VELOCITY: the drive enabled, a new set-point."""
    write_all(console, 0, ((0x6060, 0, 1), (0x6081, 0, PP_VELOCITY), (0x6083, 0, 2000), (0x6084, 0, 2000),
                           (0x6040, 0, 6), (0x6040, 0, 7), (0x6040, 0, 15), (0x607A, 0, target),
                           (0x6040, 0, 0x1F), (0x6040, 0, 0x0F)))


def monitor_frames(console, seen):
    """Adds the frames of the `frames` pushes that came meanwhile to `seen` (one small request
    reads them in)."""
    console.ask("nmt_state")
    for push in console.pushes:
        if push["push"] == "frames":
            seen.extend(push["frames"])
    console.pushes.clear()
    return seen


def tpdo4_velocities(frames, node):
    """(statusword, velocity) of each TPDO 4 (6041 + 606C, its default mapping) of `node`."""
    return [struct.unpack_from("<Hi", bytes.fromhex(f["data"])) for f in frames
            if f["id"] == 0x480 + node and len(f["data"]) == 12]


def check_objects_like_the_eds(module, what):
    objects = listed_objects(module)
    eds = eds_entries()
    check_equal(sorted(objects), sorted(eds), f"{what}: the listed entries are the EDS's")
    wrong = [(key, objects[key]["name"], name) for key, name in eds.items() if objects[key]["name"] != name]
    check(not wrong, f"{what}: names unlike the EDS's: {wrong[:5]}")
    for key, name in (((0x2055, 0), "Commutation Mode"), ((0x2080, 2), "ABN Encoder Settings: Steps"),
                      ((0x6041, 0), "Statusword"), ((0x2702, 0), "Device Digital Inputs"),
                      ((0x270E, 3), "Analog Inputs: ADC_VM"), ((0x60FD, 0), "Digital Inputs")):
        check_equal(objects[key]["name"], name, f"{what}: the name of {key[0]:04X}.{key[1]}")
    return objects


def test_single_module_over_websocket(motwin):
    wh.require_websocket()
    with TempDir() as state, CanopenWebServer(motwin, state).start() as server, server.console() as console:
        listing = console.ask("list")["modules"]
        check_equal(len(listing), 1, "one module")
        module = listing[0]
        check_equal((module["product"], module["firmware"], module["protocol"], module["node_id"]),
                    ("TMCM-1636", "CANopen V1.12", "canopen", 1), "the module listed")
        objects = check_objects_like_the_eds(module, "tmcm-1636 canopen")
        check_equal([s["title"] for s in module["sections"]],
                    ["Communication profile area", "Manufacturer-specific profile area", "Device profile area"],
                    "sections as on the TMCM-3216")

        # Values by SDO, as the dictionary lists them, and typed.
        check_equal(console.ask("get", index=0x1008)["text"], "TMCM-1636", "1008 device name")
        for index, sub, value in ((0x1000, 0, 0x00420192), (0x6041, 0, 0x0240), (0x2080, 2, 8192),
                                  (0x2055, 0, 0), (0x2058, 0, POSITION_UNITS_PER_REV)):
            check_equal(console.ask("get", index=index, sub=sub)["value"], value, f"{index:04X}.{sub}")
            check_equal(objects[(index, sub)]["default"], value, f"{index:04X}.{sub}'s listed default")
        check_equal(console.ask("get", index=0x6060)["data"], "00", "6060: one byte as the dictionary types it")

        # SDO writes: the module's own checks answer, and a master on the bus reads what was written.
        check_equal(console.ask("set", index=0x2055, value=3)["ok"], True, "2055 = 3 (ABN encoder)")
        refused = console.ask("set", index=0x2055, value=9)
        check_equal((refused["ok"], refused["abort"]), (False, "0x06090031"), "2055 = 9: value too high")
        check_equal(console.ask("set", index=0x6041, value=1)["abort"], "0x06010002", "6041 is read only")
        sdo(console, 0, "sdo_write", 0x2080, 2, value=4096)
        with CanopenClient(server.can_port) as master:
            check_equal(master.upload_u(1, 0x2055, 0), 3, "2055 by a CAN master")
            check_equal(master.upload_u(1, 0x2080, 2), 4096, "2080.2 by a CAN master")
            master.download(1, 0x2080, 2, 8192, 2)
        check_equal(read(console, 0, 0x2080, 2), 8192, "2080.2 written by the master, read by the console")

        # NMT: the state the console hears (heartbeats once 1017 is set), start from the console.
        sdo(console, 0, "sdo_write", 0x1017, value=20)
        nmt_state = lambda: console.ask("nmt_state")["nodes"][0].get("nmt_state")  # noqa: E731
        wait_until("the heartbeat's pre-operational", lambda: nmt_state() == "pre-operational")
        check_equal(console.ask("nmt", command="start")["ok"], True, "NMT start")
        wait_until("operational", lambda: nmt_state() == "operational")
        check_equal(console.ask("list")["modules"][0]["nmt_state"], "operational", "list's nmt_state")

        # pv: TPDO 4 (6041 + 606C, event driven) in the bus monitor as the velocity ramps up.
        check_equal(console.ask("monitor")["ok"], True, "monitor on")
        enable_pv(console, 0, PV_VELOCITY)
        wait_until("606C at the target", lambda: read(console, 0, 0x606C) == PV_VELOCITY)
        frames = []
        wait_until("TPDO 4 at the target velocity in the monitor", lambda: any(
            velocity == PV_VELOCITY for _, velocity in tpdo4_velocities(monitor_frames(console, frames), 1)))
        tpdos = tpdo4_velocities(frames, 1)
        check(all(statusword & 0x6F == 0x27 for statusword, velocity in tpdos if velocity),
              f"operation enabled in each TPDO 4 of the motion: {tpdos[:3]}")
        velocities = [velocity for _, velocity in tpdos]
        check(any(0 < v < PV_VELOCITY for v in velocities), f"TPDO 4 on the ramp: {velocities[:10]}")
        check_equal(velocities, sorted(velocities), "TPDO 4's velocities rise")
        check_equal(read(console, 0, 0x6061), 3, "6061 mode display: pv")
        check({0x181, 0x281, 0x481, 0x701, 0x601, 0x581} <= {f["id"] for f in frames},
              f"TPDO 1, 2, 4, heartbeat and the console's SDO in the monitor: {sorted({f['id'] for f in frames})}")

        # The board's simulated world: the TMCM-1636's signals, set here, sensed by the firmware.
        world = console.ask("world")
        check_equal((world["ok"], world["settable"]), (True, True), "the world of a single module is settable")
        names = [signal["name"] for signal in world["signals"]]
        for name in ("GPI0", "GPI3", "AI0", "AI1", "VSUPPLY", "TEMP", "REF_L", "REF_R", "REF_H", "LOAD_TORQUE"):
            check(name in names, f"{name} among the signals: {names}")
        check_equal(world["axes"], [{"prefix": "", "position_rev": None, "speed_rpm": None, "torque_nm": None}],
                    "the ideal motor has no rotor to draw")
        check_equal(console.ask("world_set", signal="GPI1", value=1)["ok"], True, "GPI1 = 1")
        check_equal(read(console, 0, 0x2702), 0b10, "2702: GPI 1")
        check_equal(read(console, 0, 0x60FD) >> 16, 0b10, "60FD bits 16..19: GPI 1")
        sdo(console, 0, "sdo_write", 0x6040, value=6)  # 2005 is written in SWITCH ON DISABLED only
        sdo(console, 0, "sdo_write", 0x6040, value=0)
        sdo(console, 0, "sdo_write", 0x2005, value=0)  # both limit switches used
        for signal, bit in (("REF_L", 0), ("REF_R", 1), ("REF_H", 2)):
            levels = []
            for level in (0, 1):
                reply = console.ask("world_set", signal=signal, value=level)
                check_equal(reply["ok"], True, f"{signal} = {level}")
                # The axis samples its switches in its control tick, and the serve answers SDOs
                # between its batches of ticks (several within one simulated millisecond): 60FD
                # is read once the simulation has run on past the set.
                wait_until("the simulation to run on", lambda: console.ask("nmt_state")["sim_time_us"] >=
                           reply["sim_time_us"] + SAMPLED_AFTER_US)
                levels.append(read(console, 0, 0x60FD) & 0b111)
            check_equal(levels[0] ^ levels[1], 1 << bit, f"60FD: {signal} changes bit {bit} alone ({levels})")
        for volts in (24, 48):
            console.ask("world_set", signal="VSUPPLY", value=volts)
            adc = read(console, 0, 0x270E, 3)
            check(abs(adc - volts * 4095 / SUPPLY_FULL_SCALE_V) <= 1, f"270E.3 ADC_VM at {volts} V: {adc}")
        console.ask("world_set", signal="AI0", value=1234)
        check_equal(read(console, 0, 0x270E, 1), 1234, "270E.1 AIN_0")
        server.stop()


def test_shaft_follows_the_motor(motwin):
    """A physical motor: the world's shaft turns as 6064 counts in a profile position move."""
    wh.require_websocket()
    with TempDir() as state, CanopenWebServer(motwin, state, REFERENCE_MOTOR).start() as server, \
            server.console() as console:
        axis = console.ask("world", values_only=True)["axes"][0]
        start_rev = axis["position_rev"]
        check(isinstance(start_rev, float), f"a rotor to draw: {axis}")
        start_units = read(console, 0, 0x6064)
        target = start_units + 2 * POSITION_UNITS_PER_REV
        move_to(console, target)
        wait_until("target reached (6041 bit 10)", lambda: read(console, 0, 0x6041) & 0x400)
        units = read(console, 0, 0x6064)
        check(abs(units - target) <= 64, f"6064 at the target: {units}")
        axis = console.ask("world", values_only=True)["axes"][0]
        turned = axis["position_rev"] - start_rev
        check(abs(turned - (units - start_units) / POSITION_UNITS_PER_REV) < 0.01,
              f"the shaft turned {turned} rev as 6064 counted {units - start_units}")
        check(abs(turned - 2) < 0.01, f"two turns: {turned}")
        server.stop()


def test_node_beside_a_tmcm3216(motwin):
    wh.require_websocket()
    with TempDir() as state, CanopenBusServer(motwin, state).start() as server, server.console() as console:
        modules = console.ask("list")["modules"]
        check_equal([(m["product"], m["firmware"], m["protocol"], m["node_id"]) for m in modules],
                    [("TMCM-1636", "CANopen V1.12", "canopen", 5), ("TMCM-3216", "CANopen V1.04", "canopen", 1)],
                    "the two nodes listed")
        check_objects_like_the_eds(modules[0], "the tmcm-1636 node")
        check_equal(console.ask("get", module=0, index=0x1008)["text"], "TMCM-1636", "module 0's 1008")
        check_equal(console.ask("sdo_read", node=5, index=0x1008, sub=0)["text"], "TMCM-1636", "node 5's 1008")
        check_equal(console.ask("get", module=1, index=0x1008)["text"], "TMCM-3216", "module 1's 1008")
        sdo(console, 0, "sdo_write", 0x1017, value=20)
        check_equal(console.ask("nmt", node=0, command="start")["ok"], True, "NMT start, all nodes")
        wait_until("node 5 operational", lambda: console.ask("nmt_state")["nodes"][0].get("nmt_state") == "operational")
        check_equal(console.ask("monitor")["ok"], True, "monitor on")
        enable_pv(console, 0, PV_VELOCITY)
        frames = []
        wait_until("node 5's TPDO 4 at the target velocity", lambda: any(
            velocity == PV_VELOCITY for _, velocity in tpdo4_velocities(monitor_frames(console, frames), 5)))
        check(any(0 < v < PV_VELOCITY for _, v in tpdo4_velocities(frames, 5)), "node 5's TPDO 4 on the ramp")
        check_equal(read(console, 1, 0x6041), 0x0240, "the TMCM-3216's axis 0 untouched")
        check(not any(f["id"] == 0x481 for f in frames), "no TPDO 4 of node 1")
        # A node of a bus takes no scenario: its signals are listed, read only.
        world = console.ask("world", module=0)
        check_equal((world["ok"], world["settable"], len(world["axes"])), (True, False, 1), "node 5's world")
        check("GPI0" in [signal["name"] for signal in world["signals"]], "the TMCM-1636's signals")
        reply = console.ask("world_set", module=0, signal="GPI1", value=1)
        check(not reply["ok"] and "not set from here" in reply["error"], f"world_set refused: {reply}")
        server.stop()


# --- In the browser -------------------------------------------------------------------------------

class Browser(bh.ConsolePage):
    """The console's page, with the CANopen and World views' helpers."""

    def edit(self, key, text):
        field = self.find(f'input[data-key="{key}"]')
        field.click()
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys(text, Keys.ENTER)

    def axis_cell(self, name):
        cells = self.finds(f'#canopen-axes tr[data-axis="0"] td.{name}')
        return cells[0].text if cells else ""

    def rows(self, table):  # in one script: rows come and go while Selenium reads
        return self.js(f"return [...document.querySelectorAll('#{table} tbody tr')]"
                       ".map(r => [...r.cells].map(c => c.textContent));")

    def monitor_frames(self):
        return int(self.find("#monitor-note").text.split(" frames")[0].split("· ")[-1])

    def drawn_position(self):
        value = self.js('const d = document.querySelector("#world-axis-0 svg"); return d && d.dataset.positionRev;')
        return float(value) if value not in (None, "") else None


def check_pdo_table(browser, node):
    """The 8 PDOs named as on the TMCM-3216 ("TPDO 4"), with the EDS's default COB-IDs and mappings."""
    browser.wait("the PDOs read", lambda: browser.find("#canopen-pdo-note").text.startswith("8 of 8"))
    rows = {row[0]: row[1:] for row in browser.rows("canopen-pdos")}
    check_equal(rows["TPDO 4 (1803 / 1A03)"],
                ["0", f"0x{0x480 + node:X}", "yes", "254 event driven",
                 "6041.0 Statusword (16 bit) · 606C.0 Velocity Actual Value (32 bit)"], "TPDO 4's row")
    check_equal(rows["RPDO 1 (1400 / 1600)"], ["0", f"0x{0x200 + node:X}", "yes", "255 event driven",
                                               "6040.0 Controlword (16 bit)"], "RPDO 1's row")
    check_equal(sorted(rows), sorted([f"{kind}PDO {n} ({base + n - 1:04X} / {base + 0x200 + n - 1:04X})"
                                      for kind, base in (("R", 0x1400), ("T", 0x1800)) for n in range(1, 5)]),
                "the PDO rows")


def wait_for_tpdo4_in_monitor(browser, console, module, node):
    """TPDO 4 decoded in the monitor while the drive ramps in pv. The monitor keeps the last 500
    rows: should the ramp's TPDOs have scrolled out before the page was looked at (a loaded
    machine), the velocity changes again, once the page shows the last one and 20 frames more."""
    cob_id = f"0x{0x480 + node:03X}"
    targets = iter([2 * PV_VELOCITY, PV_VELOCITY] * 20)
    state = {"target": None, "frames_at_target": None}

    def in_motion(row):  # "TPDO 4 node N" with operation enabled and a velocity
        if row[1] != cob_id or row[2] != f"TPDO 4 node {node}":
            return False
        statusword, velocity = struct.unpack_from("<Hi", bytes.fromhex(row[3].replace(" ", "")))
        return statusword & 0x6F == 0x27 and 0 < velocity <= 2 * PV_VELOCITY

    def shown():
        if any(in_motion(row) for row in browser.rows("monitor")):
            return True
        if state["target"] is not None:
            if state["frames_at_target"] is None:
                if browser.axis_cell("velocity") == str(state["target"]):
                    state["frames_at_target"] = browser.monitor_frames()
                return False
            if browser.monitor_frames() <= state["frames_at_target"] + 20:
                return False
        state.update(target=next(targets), frames_at_target=None)
        sdo(console, module, "sdo_write", 0x60FF, value=state["target"])
        return False

    browser.wait("TPDO 4 of the motion in the monitor", shown)


def test_views_in_the_browser(motwin):
    """Parameters, Console and CANopen views on the single module (ideal motor)."""
    with bh.browser_and_server(Browser, CanopenWebServer, motwin) as (browser, server), \
            server.console() as console:
        sdo(console, 0, "sdo_write", 0x1017, value=100)  # heartbeats: every NMT state is heard
        browser.open_console(server.url("/"))
        browser.wait("the objects", lambda: browser.finds('tr[data-key="o2055.0"]') != [])
        check_equal(browser.find("#module-info").text, "TMCM-1636 · firmware CANopen V1.12", "the module line")
        browser.wait("a live value of 1008", lambda: browser.value_of("o1008.0") == "TMCM-1636")
        # The EDS's objects by name, live values, an edit in place and the module's refusal.
        browser.set_filter("2080")
        browser.wait("2080's rows", lambda: len(browser.finds("#parameters tbody tr[data-key]")) == 4)
        check_equal(browser.find('tr[data-key="o2080.2"] td.name').text, "ABN Encoder Settings: Steps", "2080.2's name")
        browser.wait("2080.2's value", lambda: browser.value_of("o2080.2") == "8192")
        browser.set_filter("commutation mode")
        browser.wait("2055's row", lambda: browser.finds('input[data-key="o2055.0"]') != [])
        browser.edit("o2055.0", "3")
        browser.wait("the SDO reply", lambda: browser.reply_of("o2055.0") == "ok")
        browser.wait("2055 to read 3", lambda: browser.value_of("o2055.0") == "3")
        check_equal(read(console, 0, 0x2055), 3, "2055 over the protocol")
        browser.edit("o2055.0", "9")
        browser.wait("the abort", lambda: browser.reply_of("o2055.0").startswith("abort 0x06090031"))
        browser.set_filter("statusword")
        browser.wait("6041's live value", lambda: browser.value_of("o6041.0") == str(0x0240))
        browser.screenshot(motwin, "tmcm1636-canopen-objects")
        # The Console view: SDO by text.
        browser.show("console")
        browser.type_command("r 1008 0")
        browser.wait("the device name", lambda: any('"TMCM-1636"' in line for line in browser.console_lines()))
        browser.type_command("w 2080 2 4096")
        browser.wait("the 2080.2 write", lambda: any(line.startswith("write 2080.2: ok")
                                                     for line in browser.console_lines()))
        check_equal(read(console, 0, 0x2080, 2), 4096, "2080.2 written from the Console view")

        # The CANopen view.
        browser.show("canopen")
        nmt_state = lambda: browser.find("#canopen-nmt-state").text  # noqa: E731
        browser.wait("NMT pre-operational", lambda: nmt_state() == "pre-operational")
        check_equal(len(browser.finds("#canopen-axes tbody tr")), 1, "one axis (6041)")
        browser.wait("the axis decoded", lambda: browser.axis_cell("cia402-state") == "Switch on disabled")
        check_equal(browser.axis_cell("statusword"), "0x0240", "statusword")
        check_pdo_table(browser, 1)
        browser.find('[data-canopen-nmt="start"]').click()
        browser.wait("NMT operational", lambda: nmt_state() == "operational")
        browser.find("#monitor-hide-sdo").click()  # fewer rows: the TPDOs stay longer in view
        enable_pv(console, 0, PV_VELOCITY)
        browser.wait("operation enabled", lambda: browser.axis_cell("cia402-state") == "Operation enabled")
        browser.wait("pv shown", lambda: browser.axis_cell("mode") == "3 profile velocity")
        wait_for_tpdo4_in_monitor(browser, console, 0, 1)
        check_equal(browser.find("#canopen-error-register").text, "0x00", "error register")
        browser.driver.execute_script("document.getElementById('monitor').scrollIntoView(false);")
        browser.screenshot(motwin, "tmcm1636-canopen-monitor")
        browser.driver.execute_script("window.scrollTo(0, 0);")
        browser.screenshot(motwin, "tmcm1636-canopen")
        browser.show("parameters")
        browser.check_log_clean()
        server.stop()


def test_world_view_in_the_browser(motwin):
    """The World view on the single module with the reference motor: controls seen by the firmware,
    the drawn shaft following a profile position move."""
    with bh.browser_and_server(Browser, CanopenWebServer, motwin, REFERENCE_MOTOR) as (browser, server), \
            server.console() as console:
        browser.open_console(server.url("/"))
        browser.show("world")
        browser.wait("the World view's controls", lambda: browser.finds('input[type="checkbox"][data-signal="GPI1"]'))
        for signal in ("GPI0", "GPI3", "REF_L", "REF_R", "REF_H"):
            check(browser.finds(f'input[type="checkbox"][data-signal="{signal}"]'), f"a check box for {signal}")
        for signal in ("AI0", "VSUPPLY", "TEMP", "LOAD_TORQUE", "REF_L_AT"):
            check(browser.finds(f'input[type="number"][data-signal="{signal}"]'), f"a number input for {signal}")
        browser.find('input[type="checkbox"][data-signal="GPI1"]').click()
        wait_until("2702 to read GPI 1 set from the page", lambda: read(console, 0, 0x2702) == 0b10)
        field = browser.find('input[type="number"][data-signal="AI0"]')
        field.click()
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys("2000", Keys.ENTER)
        wait_until("270E.1 to read AI0 set from the page", lambda: read(console, 0, 0x270E, 1) == 2000)

        # The drawn shaft follows the motor through two turns of a pp move: on its way (two
        # simulated seconds; a page stalled for all of them sees the next move), then at the end.
        browser.wait("the shaft drawn", lambda: browser.drawn_position() is not None)
        for attempt in range(3):
            start_units = read(console, 0, 0x6064)
            start_rev = console.ask("world", values_only=True)["axes"][0]["position_rev"]
            move_to(console, start_units + 2 * POSITION_UNITS_PER_REV)
            seen_on_its_way = False

            def arrived():
                nonlocal seen_on_its_way
                seen_on_its_way = seen_on_its_way or 0.05 < browser.drawn_position() - start_rev < 1.95
                return read(console, 0, 0x6041) & 0x400  # target reached

            browser.wait("target reached (6041 bit 10)", arrived)
            if seen_on_its_way:
                break
        check(seen_on_its_way, "the drawn shaft seen on its way in one of three moves")
        turned = (read(console, 0, 0x6064) - start_units) / POSITION_UNITS_PER_REV
        check(abs(turned - 2) < 0.001, f"6064 counted two turns: {turned}")
        browser.wait("the drawn shaft at the target", lambda: abs(browser.drawn_position() - start_rev - turned) < 0.01)
        browser.screenshot(motwin, "tmcm1636-canopen-world")
        browser.show("parameters")
        browser.wait("the World view's session to close", lambda: not browser.js("return window.MotwinWorld.running"))
        browser.check_log_clean()
        server.stop()


def test_bus_node_in_the_browser(motwin):
    """The TMCM-1636 as node 5 of a bus beside a TMCM-3216: its CANopen view, its World read only."""
    with bh.browser_and_server(Browser, CanopenBusServer, motwin) as (browser, server), \
            server.console() as console:
        sdo(console, 0, "sdo_write", 0x1017, value=100)
        browser.open_console(server.url("/"))
        browser.wait("the module picker", lambda: len(browser.finds("#module-picker option")) == 2)
        check_equal([o.text for o in browser.finds("#module-picker option")],
                    ["tmcm-1636-1 (node 5)", "tmcm-3216-2 (node 1)"], "the picker")
        browser.wait("the node's objects", lambda: browser.finds('tr[data-key="o2055.0"]') != [])
        browser.show("canopen")
        browser.wait("the axis decoded", lambda: browser.axis_cell("cia402-state") == "Switch on disabled")
        check_pdo_table(browser, 5)
        browser.find('[data-canopen-nmt="start"]').click()
        browser.wait("NMT operational", lambda: browser.find("#canopen-nmt-state").text == "operational")
        browser.find("#monitor-hide-sdo").click()
        enable_pv(console, 0, PV_VELOCITY)
        wait_for_tpdo4_in_monitor(browser, console, 0, 5)
        browser.screenshot(motwin, "tmcm1636-canopen-node")
        browser.show("world")
        browser.wait("the World view's controls", lambda: browser.finds('input[type="checkbox"][data-signal="GPI1"]'))
        check(browser.find('input[type="checkbox"][data-signal="GPI1"]').get_attribute("disabled") is not None,
              "read only on a node of a bus")
        browser.wait("the read-only note", lambda: "read only" in browser.find("#world-note").text)
        # The other node: the TMCM-3216's three axes.
        Select(browser.find("#module-picker")).select_by_value("1")
        browser.show("canopen")
        browser.wait("the TMCM-3216's axes", lambda: len(browser.finds("#canopen-axes tbody tr")) == 3)
        browser.check_log_clean()
        server.stop()


if __name__ == "__main__":
    run_can_tests([test_single_module_over_websocket, test_shaft_follows_the_motor, test_node_beside_a_tmcm3216,
                   test_views_in_the_browser, test_world_view_in_the_browser, test_bus_node_in_the_browser])

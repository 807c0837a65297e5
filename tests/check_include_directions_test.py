#!/usr/bin/python3
"""Tests of tests/check_include_directions.py on small synthetic source trees (in a temp dir):
each forbidden direction fails naming the file and the line, a tree that keeps the rules passes.
Standard library only; CTest runs it as include_directions_checker."""

import os
import subprocess
import sys
import tempfile
import unittest

CHECKER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_include_directions.py")

# A tree that keeps every rule: each layer includes what it may, cli/ includes every layer, a
# module's files include their own module in other layers, the registry names every module.
CLEAN_TREE = {
    "types/can_frame.h": "#pragma once\n#include <cstdint>\n",
    "board/can_controller.h": '#pragma once\n#include "types/can_frame.h"\n#include "board/stepper_drive.h"\n',
    "board/stepper_drive.h": "#pragma once\n#include <cstdint>\n",
    "board/modules/tmcm3216/tmcm3216_board.h": '#include "board/stepper_drive.h"\n',
    "core/canopen/pdo.h": '#include "board/can_controller.h"\n#include "types/can_frame.h"\n#include "sdo_abort.h"\n',
    "core/canopen/sdo_abort.h": "#pragma once\n",
    "core/modules/tmcm3216/tmcm3216.h": '#include "core/canopen/pdo.h"\n'
                                        '#include "board/modules/tmcm3216/tmcm3216_board.h"\n',
    "core/modules/tmcm1636/tmcm1636.h": '#include "core/canopen/sdo_abort.h"\n',
    "sim/modules/tmcm3216/tmcm3216_sim_board.cpp": '#include "core/modules/tmcm3216/tmcm3216_hardware.h"\n'
                                                   '#include "core/canopen/sdo_abort.h"\n'
                                                   '#include "sim/stepper_plant.h"\n',
    "core/modules/tmcm3216/tmcm3216_hardware.h": "#pragma once\n",
    "sim/stepper_plant.h": '#include "board/stepper_drive.h"\n',
    "host/modules/tmcm3216/tmcm3216_virtual_module.cpp": '#include "sim/modules/tmcm3216/tmcm3216_sim_board.cpp"\n',
    "host/module_registry.cpp": '#include "core/modules/tmcm1636/tmcm1636.h"\n'
                                '#include "host/modules/tmcm3216/tmcm3216_virtual_module.cpp"\n',
    "tools/eds_writer.cpp": '#include "host/module_registry.cpp"\n#include <string>\n',
    "cli/main.cpp": '#include "tools/eds_writer.cpp"\n#include "host/module_registry.cpp"\n'
                    '#include "core/canopen/pdo.h"\n#include "cli/commands.h"\n',
    "cli/commands.h": "#pragma once\n",
}


def write_tree(root, files):
    for relative, text in files.items():
        path = os.path.join(root, "src", relative)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as out:
            out.write(text)


def run_checker(files):
    with tempfile.TemporaryDirectory() as root:
        write_tree(root, files)
        result = subprocess.run([sys.executable, CHECKER, os.path.join(root, "src")], capture_output=True,
                                text=True, check=False)
        return result.returncode, result.stdout + result.stderr


class IncludeDirections(unittest.TestCase):
    def assert_fails_at(self, path, line, text, wanted):
        """A clean tree plus `path` (whose line `line` is the bad include) fails naming both."""
        files = dict(CLEAN_TREE)
        files[path] = text
        status, output = run_checker(files)
        self.assertEqual(status, 1, output)
        violations = [l for l in output.splitlines() if l.startswith("src/")]
        self.assertEqual(len(violations), 1, output)
        self.assertTrue(violations[0].startswith(f"src/{path}:{line}: "), output)
        self.assertIn(wanted, violations[0])

    def test_a_tree_that_keeps_the_rules_passes(self):
        status, output = run_checker(CLEAN_TREE)
        self.assertEqual(status, 0, output)
        self.assertIn(f"{len(CLEAN_TREE)} files checked", output)

    def test_board_includes_core(self):
        # The leak issue 15 found: the CAN controller seam included the core's frame type.
        self.assert_fails_at("board/can_controller.h", 3,
                             '#pragma once\n#include <cstdint>\n#include "core/can/can_frame.h"\n',
                             'board/ includes "core/can/can_frame.h"')

    def test_types_include_nothing_of_the_project(self):
        self.assert_fails_at("types/result.h", 2, '#pragma once\n#include "board/stepper_drive.h"\n',
                             'types/ includes "board/stepper_drive.h"')

    def test_core_includes_host(self):
        self.assert_fails_at("core/canopen/nmt.h", 4, '#pragma once\n\n#include <cstdint>\n#include "host/can_bus.h"\n',
                             'core/ includes "host/can_bus.h"')

    def test_core_includes_sim(self):
        self.assert_fails_at("core/motion/ramp.cpp", 1, '#include "sim/stepper_plant.h"\n',
                             'core/ includes "sim/stepper_plant.h"')

    def test_sim_includes_host(self):
        self.assert_fails_at("sim/modules/tmcm1636/motor_description.cpp", 2,
                             '#include "sim/modules/tmcm1636/motor_description.h"\n#include "host/eeprom_file.h"\n',
                             'sim/ includes "host/eeprom_file.h"')

    def test_sim_includes_a_module_profile(self):
        # The leak issue 15 found: the motor description read the TMCM-1636's parameter table.
        self.assert_fails_at("sim/modules/tmcm1636/motor_description.cpp", 3,
                             '#include "sim/modules/tmcm1636/motor_description.h"\n\n'
                             '#include "core/modules/tmcm1636/tmcm1636.h"\n',
                             'sim/ includes "core/modules/tmcm1636/tmcm1636.h"')

    def test_host_includes_tools(self):
        self.assert_fails_at("host/serve.cpp", 1, '#include "tools/tmcl_client.h"\n', 'host/ includes "tools/tmcl_client.h"')

    def test_nothing_below_cli_includes_cli(self):
        for path in ("tools/assembler.cpp", "host/runtime.cpp", "sim/scenario.cpp", "core/tmcl/engine.cpp",
                     "board/io.h", "types/frame.h"):
            with self.subTest(path=path):
                self.assert_fails_at(path, 2, '// below cli\n#include "cli/commands.h"\n', 'includes "cli/commands.h"')

    def test_a_relative_include_is_checked_where_it_lands(self):
        self.assert_fails_at("board/modules/tmcm3216/io.h", 1, '#include "../../../core/canopen/sdo_abort.h"\n',
                             'board/ includes "core/canopen/sdo_abort.h"')

    def test_a_module_includes_another_module(self):
        self.assert_fails_at("host/modules/tmcm142/tmcm142_virtual_module.cpp", 2,
                             '#include "core/modules/tmcm142/tmcm142.h"\n#include "core/modules/tmcm3216/tmcm3216.h"\n',
                             "module tmcm142 includes \"core/modules/tmcm3216/tmcm3216.h\" of module tmcm3216")
        self.assert_fails_at("sim/modules/tmcm142/tmcm142_sim_board.cpp", 2,
                             '#include "sim/stepper_plant.h"\n#include "sim/modules/tmcm3216/tmcm3216_sim_board.cpp"\n',
                             "module tmcm142 includes \"sim/modules/tmcm3216/tmcm3216_sim_board.cpp\" of module tmcm3216")

    def test_every_violation_is_listed(self):
        files = dict(CLEAN_TREE)
        files["board/a.h"] = '#include "core/canopen/pdo.h"\n#include "sim/stepper_plant.h"\n'
        files["host/b.cpp"] = '#include "cli/commands.h"\n'
        status, output = run_checker(files)
        self.assertEqual(status, 1, output)
        self.assertIn("src/board/a.h:1: ", output)
        self.assertIn("src/board/a.h:2: ", output)
        self.assertIn("src/host/b.cpp:1: ", output)
        self.assertIn("3 include(s) cross the allowed direction", output)


if __name__ == "__main__":
    unittest.main()

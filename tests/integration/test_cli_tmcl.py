#!/usr/bin/python3
"""`motwin tmcl` against a running `motwin serve`, and the --help of the commands.

Output format (src/cli/tmcl_command.cpp): 'status CODE (MEANING) value VALUE', for 136 type 0
'version STRING'. Exit status 0 on status 100, non-zero on an error status, on no connection,
on no reply and on bad usage (with an error line on stderr).
"""

import os
import re
import socket
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import GAP, Server, TempDir, check, check_equal, run_tests  # noqa: E402

CLI_TIMEOUT = 30.0
REPLY_LINE = re.compile(r"status (\d+) \(([^)]*)\) value (-?\d+)")


def run(motwin, *args):
    result = subprocess.run([motwin, *args], stdin=subprocess.DEVNULL, capture_output=True, timeout=CLI_TIMEOUT)
    return result.returncode, result.stdout.decode("utf-8", "replace"), result.stderr.decode("utf-8", "replace")


def tmcl(motwin, transport, *instruction):
    return run(motwin, "tmcl", *transport, *instruction)


def parse_status_value(stdout, what):
    matches = REPLY_LINE.findall(stdout)
    check(len(matches) == 1, f"{what}: expected one 'status N (..) value V' line, stdout {stdout!r}")
    return int(matches[0][0]), int(matches[0][2])


def expect_ok(motwin, transport, *instruction, value=None):
    what = f"motwin tmcl {' '.join(transport)} {' '.join(instruction)}"
    code, out, err = tmcl(motwin, transport, *instruction)
    check_equal(code, 0, f"{what}: exit status (stdout {out!r}, stderr {err!r})")
    status, got = parse_status_value(out, what)
    check_equal(status, 100, f"{what}: status")
    if value is not None:
        check_equal(got, value, f"{what}: value")
    return got


def free_port():
    """A port nobody listens on (bound then released)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_tcp(motwin):
    with TempDir() as tmp:
        with Server(motwin, os.path.join(tmp, "state"), speed="fast") as server:
            tcp = ("--tcp", f"127.0.0.1:{server.tcp_port}")
            expect_ok(motwin, tcp, "MVP", "ABS", "0", "90000", value=90000)
            expect_ok(motwin, tcp, "GAP", "50", "0", value=90000)
            # The move really happens: AP 52 reaches the target.
            with server.tcp() as c:
                c.wait_for("AP 52 = 90000", lambda: c.gap(52) == 90000 and c.gap(55) == 1, 20.0)
            expect_ok(motwin, tcp, "GAP", "52", "0", value=90000)
            # TMCL-IDE syntax with commas, hexadecimal, negative values.
            expect_ok(motwin, tcp, "MVP ABS, 0, -8192", value=-8192)
            expect_ok(motwin, tcp, "GAP", "50,", "0", value=-8192)
            expect_ok(motwin, tcp, "SAP", "43", "0", "0x0BB8", value=3000)
            expect_ok(motwin, tcp, "GAP", "43", "0", value=3000)
            expect_ok(motwin, tcp, "SGP", "12", "2", "-77", value=-77)
            expect_ok(motwin, tcp, "GGP", "12", "2", value=-77)
            expect_ok(motwin, tcp, "136", "1", value=0x06640109)
            code, out, err = tmcl(motwin, tcp, "136", "0")
            check_equal(code, 0, f"136 0: exit status ({err!r})")
            check("1636V109" in out, f"136 0: version not printed: {out!r}")

            # Error status: read-only parameter -> status 3, non-zero exit, error on stderr.
            code, out, err = tmcl(motwin, tcp, "SAP", "42", "0", "5")
            check(code != 0, f"SAP 42 0 5 (read-only) exited 0: {out!r}")
            check_equal(parse_status_value(out, "SAP 42 0 5")[0], 3, "SAP 42 0 5: status")
            check(err.strip() != "", "SAP 42 0 5: no error on stderr")
            code, out, err = tmcl(motwin, tcp, "SAP", "43", "0", "300000")
            check(code != 0, "SAP 43 out of range exited 0")
            check_equal(parse_status_value(out, "SAP 43 300000")[0], 4, "SAP 43 300000: status")
            expect_ok(motwin, tcp, "GAP", "43", "0", value=3000)

            # Usage errors: non-zero, message on stderr, nothing sent.
            for bad in (("FOO", "1", "2"), ("SAP", "43", "0", "abc"), ()):
                code, out, err = tmcl(motwin, tcp, *bad)
                check(code != 0, f"motwin tmcl {' '.join(bad)!r} exited 0: {out!r}")
                check(err.strip() != "", f"motwin tmcl {' '.join(bad)!r}: no error on stderr")
            code, out, err = run(motwin, "tmcl", "GAP", "43", "0")
            check(code != 0 and err.strip() != "", "motwin tmcl without --tcp/--serial must fail with a message")

            # No reply (another module address): non-zero, error on stderr, in bounded time.
            code, out, err = tmcl(motwin, ("--module-address", "5", "--timeout-ms", "300", *tcp), "GAP", "43", "0")
            check(code != 0, f"GAP to module 5 (no reply) exited 0: {out!r}")
            check(err.strip() != "", "GAP to module 5: no error on stderr")
            expect_ok(motwin, tcp, "GAP", "43", "0", value=3000)
            server.stop()


def test_connection_refused(motwin):
    port = free_port()
    code, out, err = tmcl(motwin, ("--tcp", f"127.0.0.1:{port}"), "GAP", "50", "0")
    check(code != 0, f"no server: exit status 0 (stdout {out!r})")
    check(err.strip() != "", "no server: no error message on stderr")
    check(REPLY_LINE.search(out) is None, f"no server: a reply was printed: {out!r}")


def test_serial(motwin):
    with TempDir() as tmp:
        link = os.path.join(tmp, "tmcm1636")
        with Server(motwin, os.path.join(tmp, "state"), tcp=False, pty_link=link, speed="fast") as server:
            serial = ("--serial", link)
            expect_ok(motwin, serial, "MVP", "ABS", "0", "90000", value=90000)
            expect_ok(motwin, serial, "GAP", "50", "0", value=90000)
            code, out, err = tmcl(motwin, serial, "SAP", "42", "0", "5")
            check(code != 0, "SAP 42 over the pty exited 0")
            check_equal(parse_status_value(out, "SAP 42 over pty")[0], 3, "SAP 42 over the pty: status")
            code, out, err = tmcl(motwin, serial, "136", "0")
            check(code == 0 and "1636V109" in out, f"136 0 over the pty: {code} {out!r} {err!r}")
            # pyserial next to the CLI: both reach the same module.
            with server.serial() as c:
                check_equal(c.request(GAP, 50).value, 90000, "AP 50 through pyserial")
            expect_ok(motwin, serial, "GAP", "50", "0", value=90000)
            server.stop()
    code, out, err = tmcl(motwin, ("--serial", "/nonexistent/motwin-tty"), "GAP", "50", "0")
    check(code != 0 and err.strip() != "", f"missing serial device: {code} {err!r}")


def test_help(motwin):
    for args, words in ((("--help",), ("serve", "tmcl")),
                        (("serve", "--help"), ("--tmcl-tcp", "--state-dir")),
                        (("tmcl", "--help"), ("--tcp", "--serial"))):
        code, out, err = run(motwin, *args)
        check_equal(code, 0, f"motwin {' '.join(args)}: exit status (stderr {err!r})")
        for word in words:
            check(word in out, f"motwin {' '.join(args)}: {word!r} not in the help text")
    code, out, err = run(motwin, "no-such-command")
    check(code != 0, "an unknown subcommand must fail")


def test_serve_startup_errors(motwin):
    """Start-up errors: exit status 2, a message on stderr, no 'ready', nothing clobbered."""
    with TempDir() as tmp:
        busy = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        busy.bind(("127.0.0.1", 0))
        busy.listen(1)
        regular_file = os.path.join(tmp, "not-a-link")
        with open(regular_file, "w") as f:
            f.write("keep me")
        state = os.path.join(tmp, "state")
        cases = [
            ("port in use", ["--tmcl-tcp", f"127.0.0.1:{busy.getsockname()[1]}", "--state-dir", state]),
            ("pty link is a regular file", ["--tmcl-pty", regular_file, "--state-dir", state]),
            ("pty link in a missing directory", ["--tmcl-pty", os.path.join(tmp, "missing", "pty"), "--state-dir", state]),
            ("state dir is a file", ["--tmcl-tcp", "127.0.0.1:0", "--state-dir", regular_file]),
            ("unknown module", ["--module", "tmcm-9999", "--tmcl-tcp", "127.0.0.1:0", "--state-dir", state]),
            ("bad speed", ["--speed", "sideways", "--tmcl-tcp", "127.0.0.1:0", "--state-dir", state]),
            ("zero speed", ["--speed", "0", "--tmcl-tcp", "127.0.0.1:0", "--state-dir", state]),
            ("bad port", ["--tmcl-tcp", "127.0.0.1:70000", "--state-dir", state]),
        ]
        try:
            for name, args in cases:
                code, out, err = run(motwin, "serve", *args)
                check_equal(code, 2, f"serve with {name}: exit status (stderr {err!r})")
                check("ready" not in out.split(), f"serve with {name} printed 'ready'")
                check(err.strip() != "", f"serve with {name}: no message on stderr")
        finally:
            busy.close()
        with open(regular_file) as f:
            check_equal(f.read(), "keep me", "a regular file at the pty link path must be left alone")


if __name__ == "__main__":
    run_tests([test_tcp, test_connection_refused, test_serial, test_help, test_serve_startup_errors])

"""qemu-system-arm running a Motwin firmware image on the MPS2 AN386 board (docs/firmware.md):
the command line both bench/firmware_figures.py and tests/integration/test_firmware_qemu.py
start it with, and one command on its human monitor."""
import socket

QEMU = "qemu-system-arm"


def qemu_command(image, monitor_path, serial, *extra):
    """qemu with `image`, no display or default devices, the monitor on a Unix socket and UART0
    on the character device `serial` (a qemu -serial argument); `extra` goes before -kernel."""
    return [QEMU, "-M", "mps2-an386", "-display", "none", "-nodefaults", *extra,
            "-monitor", f"unix:{monitor_path},server=on,wait=off", "-serial", serial, "-kernel", image]


def monitor_command(monitor_path, command, timeout=30.0):
    """One command on qemu's human monitor; returns what it printed up to the next prompt."""
    with socket.socket(socket.AF_UNIX) as sock:
        sock.settimeout(timeout)
        sock.connect(monitor_path)
        output = b""
        while not output.endswith(b"(qemu) "):
            output += sock.recv(4096)
        sock.sendall(command.encode() + b"\n")
        output = b""
        while not output.endswith(b"(qemu) "):
            output += sock.recv(4096)
        return output.decode(errors="replace")

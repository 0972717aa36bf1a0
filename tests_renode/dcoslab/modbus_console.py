"""The controller's `modbus state` console command (drivers/modbus/src/ModbusCommands.cpp), read by tests.

Both the RS-485 socket tests (test_modbus_rs485.py) and the lab line's
(test_modbus_line.py) wait on the controller's own counters: a wait in the
controller's emulated time, never a sleep of the host's.
"""

from dcoslab.waiting import wait_until


def modbus_state(console):
    """The counters of `modbus state` as {"frames.crc-errors": 0, ..., "frames.receiver": "idle"}.

    console is anything with command(line) -> output: an Emulator or a lab board.
    """
    result = {}
    for text in console.command("modbus state").splitlines():
        group, _, rest = text.partition(":")
        if group not in ("line", "frames", "slave", "master"):
            continue
        words = rest.split()
        for name, value in zip(words[0::2], words[1::2]):
            result[f"{group}.{name}"] = int(value) if value.isdigit() else value
    return result


def wait_for_state(console, predicate, what, timeout, pause=0.05):
    """Runs `modbus state` until predicate(state) holds; returns that state.

    timeout (seconds of wall time) only bounds a hung run.
    """
    return wait_until(lambda: modbus_state(console), predicate, f"the controller's modbus state: {what}", console,
                      timeout=timeout, pause=pause)

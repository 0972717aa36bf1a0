"""Waiting for an emulated event seen through the console.

Under -icount emulated time runs at its own pace, often faster than the
host's while the controller idles, so a test waits for what the controller
reports (a counter, a state) rather than for a time; the real-time bound
only fails a test that hangs, with what was seen last and the console
transcript.
"""

import time

DEFAULT_WAIT = 60.0


def wait_until(read, predicate, what, emulator, timeout=DEFAULT_WAIT, pause=0.05):
    """Calls read() until predicate(value) holds and returns that value.

    read usually runs a console command and parses it; what names the
    awaited event for the failure message, which also carries the last
    value read and emulator's console transcript.
    """
    deadline = time.monotonic() + timeout
    while True:
        value = read()
        if predicate(value):
            return value
        if time.monotonic() > deadline:
            # A lab board's console has no transcript of its own; the lab's
            # failure report prints every board's.
            transcript = getattr(emulator, "transcript", "")
            raise AssertionError(f"never reached: {what}; last seen {value}\n{transcript}")
        time.sleep(pause)

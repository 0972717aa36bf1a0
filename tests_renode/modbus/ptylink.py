"""Two pseudo-terminals joined back to back, as a null-modem cable joins two serial ports.

Each side is a /dev/pts/N path that a serial program opens as it would
/dev/ttyUSB0 (libmodbus, pyserial); whatever one side writes, the other
reads. The bytes pass through a thread of this process, which can also keep
a log of them. The link holds the terminals' slave ends open itself, in raw
mode, so that no echo or line editing touches a byte before a program has
set its own modes, and so that a side nobody has opened yet still buffers.
"""

import os
import select
import threading
import tty


class PtyLink:
    def __init__(self):
        self._masters = []
        self._slaves = []
        self.paths = []
        for _ in range(2):
            master, slave = os.openpty()
            tty.setraw(slave)
            self._masters.append(master)
            self._slaves.append(slave)
            self.paths.append(os.ttyname(slave))
        self._stop_read, self._stop_write = os.pipe()
        self.log = []
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        a, b = self._masters
        peer = {a: b, b: a}
        while True:
            ready, _, _ = select.select([a, b, self._stop_read], [], [], 1.0)
            if self._stop_read in ready:
                return
            for fd in ready:
                try:
                    data = os.read(fd, 4096)
                except OSError:
                    continue
                self.log.append((0 if fd == a else 1, data))
                os.write(peer[fd], data)

    def close(self):
        os.write(self._stop_write, b"x")
        self._thread.join(timeout=5)
        for fd in self._masters + self._slaves + [self._stop_read, self._stop_write]:
            os.close(fd)

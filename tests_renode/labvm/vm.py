"""Boots the lab VM (Debian's Linux under QEMU) and runs one command in it.

    from labvm import run, LabVM, SlcanSetup

    result = run("candump -n 1 vcan0 & sleep 1; cansend vcan0 123#11", vcan=["vcan0"])
    result.status, result.output            # exit status and output of the command

    with LabVM(script, slcan=SlcanSetup(bitrate=500000)) as vm:
        vm.expect("ready")                  # regex on the console, as the command prints
        vm.slcan.send_line("t123411223344") # Lawicel on the VM's second serial port
        result = vm.wait()

The command runs as root in a chroot of the host's root (read-only over 9p),
with the host's programs: can-utils, Debian's /usr/bin/python3 with python3-can,
iproute2. /tmp, /var/tmp and /run are empty tmpfs; `files` passed here appear
under /run/labvm/files/, and /run/labvm/lib.sh has shell helpers (lib.sh here,
e.g. labvm_wait_receiver to wait for candump to listen). Everything has a time-out, and every failure raises
LabVMError with the VM's whole console transcript.
"""

import os
import re
import secrets
import shlex
import signal
import subprocess
import sys
import tempfile
import threading
import time

from . import initramfs
from .kernel import DEFAULT_CACHE, LabVMSetupError, obtain_kernel
from .slcan import BITRATE_CODES, SlcanPort

DEFAULT_QEMU = "qemu-system-x86_64"
# The lab's own QEMU build (our device models compiled in): the script says
# where its binaries are for the current sources.
BUILD_QEMU_SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "qemu", "build_qemu.sh")
# A QEMU run from its build folder finds no firmware of its own: Debian's
# SeaBIOS and the option ROMs of qemu-system-data (PVH and Linux boot).
BUILT_QEMU_FIRMWARE = ("-L", "/usr/share/seabios", "-L", "/usr/share/qemu")
# Bounds for a hung VM, not measurements: a boot takes about 4 s on an idle
# machine (8 s without PVH), several times that on a busy one.
DEFAULT_BOOT_TIMEOUT = 180.0
DEFAULT_COMMAND_TIMEOUT = 120.0
# The 9p cache mode of the host's root: "loose" caches metadata and pages in
# the guest, which makes program start-up several times faster than "none";
# the guest may then miss a change the host makes while the VM runs.
DEFAULT_9P_CACHE = "loose"
# no_timer_check: at boot Linux checks that the 8254's interrupt arrives
# through the I/O APIC within a busy-wait of its own; under TCG on a loaded
# host the tick can come late, and the kernel then panics ("IO-APIC + timer
# doesn't work!", seen once in a full `make test`). The check exists for
# broken hardware; the emulated timer is sound, only slow.
KERNEL_ARGUMENTS = "console=ttyS0 panic=-1 loglevel=4 mitigations=off no_timer_check"


class LabVMError(AssertionError):
    """The lab VM did not boot, did not finish, or its setup failed; carries the console transcript."""


class SlcanSetup:
    """slcan on the VM's second serial port: `slcand -o -c -s<code> /dev/ttyS1 <interface>`, then up."""

    def __init__(self, interface="can0", bitrate=500000, tty="/dev/ttyS1"):
        if bitrate not in BITRATE_CODES:
            raise ValueError(f"slcan bit rate {bitrate} is not one of {sorted(BITRATE_CODES)}")
        if not re.match(r"^[A-Za-z0-9_.-]{1,15}$", interface):
            raise ValueError(f"{interface!r} is not a network interface name")
        self.interface = interface
        self.bitrate = bitrate
        self.tty = tty

    @property
    def speed_code(self):
        return BITRATE_CODES[self.bitrate]

    def setup_lines(self):
        name = self.interface
        return [
            f"slcand -o -c -s{self.speed_code} {shlex.quote(self.tty)} {name}",
            # slcand forks before it attaches and renames; wait for the interface.
            f". /run/labvm/lib.sh; deadline=$(($(labvm_uptime) + 10)); while [ ! -e /sys/class/net/{name} ]; do "
            f"if [ $(labvm_uptime) -ge $deadline ]; then echo 'slcand made no {name} in 10 s' >&2; exit 1; fi; "
            f"sleep 0.05; done",
            f"ip link set {name} up",
        ]


def built_qemu_x86_64():
    """The qemu-system-x86_64 built with the lab's device models for the current sources; LabVMError if not built."""
    try:
        printed = subprocess.run([BUILD_QEMU_SCRIPT, "--print-path"], capture_output=True, text=True, timeout=60,
                                 check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError) as error:
        raise LabVMError(f"cannot ask {BUILD_QEMU_SCRIPT} where the built QEMU is: {error}") from None
    path = os.path.join(os.path.dirname(printed), "qemu-system-x86_64")
    if not os.access(path, os.X_OK):
        raise LabVMError(f"the QEMU with the lab's device models is not built for the current sources (expected "
                         f"{path}); build it with 'make emulator' or {BUILD_QEMU_SCRIPT}")
    return path


class _HubCardSetup:
    """What both SJA1000 cards' setups share: their buses and name at the lab CAN bus hub, checked, the hub's
    properties of their QEMU device, and the lines that configure and bring up each wired chip's interface
    (the interface names come from the card's `channels`, whose last field each is)."""

    def __init__(self, hub, buses, name, bitrate, hub_timeout, what):
        if not any(buses):
            raise ValueError(f"the card needs at least one {what} on a bus")
        for bus in buses:
            if bus is not None and not re.match(r"^[A-Za-z0-9_-]{1,32}$", bus):
                raise ValueError(f"{bus!r} is not a lab bus name")
        if not re.match(r"^[A-Za-z0-9_-]{1,32}$", name):
            raise ValueError(f"{name!r} is not a hub participant name (one word, no dots)")
        if "," in hub:
            raise ValueError(f"the hub's socket path {hub!r} may not contain a comma (a QEMU option separator)")
        self.hub = hub
        self.buses = tuple(buses)
        self.name = name
        self.bitrate = bitrate
        self.hub_timeout = hub_timeout

    def hub_properties(self):
        """The QEMU device's properties that join the card to the hub, its wired buses last."""
        properties = [f"hub={self.hub}", f"hub-name={self.name}", "hub-realtime=on", f"hub-timeout={self.hub_timeout}"]
        return properties + [f"bus{index}={bus}" for index, bus in enumerate(self.buses) if bus]

    def setup_lines(self):
        if self.bitrate is None:
            return []
        lines = []
        for *_, name in self.channels:
            lines += [f"ip link set {name} type can bitrate {int(self.bitrate)}", f"ip link set {name} up"]
        return lines


class Sja1000Setup(_HubCardSetup):
    """Our ISA SJA1000 card (QEMU device isa-sja1000) in the VM, on buses of the lab CAN bus hub, driven by
    Linux's own sja1000_isa driver (docs/guide/lab-vm.md, "The ISA SJA1000 card").

    The card's link joins the hub as a real-time participant (hub-realtime=on): the VM runs without -icount,
    so it cannot be held at the hub's boundaries; see docs/protocols/labbus.md. Channel 0 is wired to bus0,
    channel 1 to bus1 (None: the channel is not used and gets no driver); Linux names them can0 and can1 in
    that order. With a bitrate the setup configures and brings up each interface; with None it leaves that to
    the command. The interrupt lines default to 5 and 7, which nothing in the VM uses: the PCI interrupt
    links (virtio-9p) take 10 and 11 on QEMU's pc machine.
    """

    def __init__(self, hub, bus0="can0", bus1=None, name="linux", bitrate=500000, iobase=0x280, irq0=5, irq1=7,
                 hub_timeout=60):
        super().__init__(hub, (bus0, bus1), name, bitrate, hub_timeout, "channel")
        self.iobase = iobase
        self.irqs = (irq0, irq1)

    @property
    def channels(self):
        """The channels wired to a bus: (channel, port, irq, interface name in the VM)."""
        used = [index for index in (0, 1) if self.buses[index]]
        return [(index, self.iobase + 0x20 * index, self.irqs[index], f"can{number}")
                for number, index in enumerate(used)]

    def interface(self, channel=0):
        """The VM's interface name for a channel of the card."""
        for index, _, _, name in self.channels:
            if index == channel:
                return name
        raise ValueError(f"channel {channel} of the card is not wired to a bus")

    def device_argument(self):
        properties = [f"iobase={self.iobase:#x}", f"irq0={self.irqs[0]}", f"irq1={self.irqs[1]}"]
        return "isa-sja1000," + ",".join(properties + self.hub_properties())

    def load_line(self):
        """The modprobe line: sja1000_isa takes arrays, one entry per chip (its clk defaults to 16 MHz)."""
        channels = self.channels
        return (f"sja1000_isa port={','.join(f'{port:#x}' for _, port, _, _ in channels)} "
                f"irq={','.join(str(irq) for _, _, irq, _ in channels)}")


class KvaserPciSetup(_HubCardSetup):
    """The lab's Kvaser PCIcan (QEMU device lab-kvaser-pci) in the VM, its chips on buses of the lab CAN bus hub,
    driven by Linux's own kvaser_pci driver (docs/guide/lab-vm.md, "The Kvaser PCI card").

    The card carries one chip per entry of `buses` (1 to 4; a real PCIcan has 1, 2 or 4): chip n is wired to
    buses[n], or to no bus for None (a chip alone on its bus). Linux's driver counts the chips and makes one
    interface per chip, can0 for chip 0 and so on, whether wired or not. The card's link joins the hub as a
    real-time participant (hub-realtime=on), like Sja1000Setup's. The BIOS places the card and routes its INTA#
    (to 10 or 11 on QEMU's pc machine, shared with the virtio-9p device's INTx, which PCI allows). With a bitrate
    the setup configures and brings up the interface of each wired chip; with None it leaves that to the command.
    Use it as LabVM's `sja1000=`, in place of a Sja1000Setup.
    """

    def __init__(self, hub, buses=("can0",), name="linux", bitrate=500000, hub_timeout=60):
        buses = tuple(buses)
        if not 1 <= len(buses) <= 4:
            raise ValueError(f"a Kvaser PCIcan carries 1 to 4 chips, not {len(buses)}")
        super().__init__(hub, buses, name, bitrate, hub_timeout, "chip")

    @property
    def channels(self):
        """The chips wired to a bus: (chip, bus, interface name in the VM)."""
        return [(index, bus, f"can{index}") for index, bus in enumerate(self.buses) if bus]

    def interface(self, channel=0):
        """The VM's interface name for a chip of the card: the driver names every chip, in order."""
        if not 0 <= channel < len(self.buses):
            raise ValueError(f"the card carries {len(self.buses)} chips, not chip {channel}")
        return f"can{channel}"

    def device_argument(self):
        return "lab-kvaser-pci," + ",".join([f"channels={len(self.buses)}"] + self.hub_properties())

    def load_line(self):
        """The modprobe line: kvaser_pci binds to the card by its PCI identity and takes no options."""
        return "kvaser_pci"


class Result:
    """What one run of the lab VM gave."""

    def __init__(self, status, output_bytes, transcript, timed_out, boot_seconds, run_seconds, argv):
        self.status = status
        self.output_bytes = output_bytes
        self.output = output_bytes.decode("utf-8", "replace")
        self.transcript = transcript
        self.timed_out = timed_out
        self.boot_seconds = boot_seconds  # QEMU start to the command's start (wall time)
        self.run_seconds = run_seconds  # the command (wall time)
        self.argv = argv

    def __repr__(self):
        return (f"Result(status={self.status}, timed_out={self.timed_out}, boot {self.boot_seconds:.1f} s, "
                f"run {self.run_seconds:.1f} s, output={self.output[:200]!r})")

    def check(self):
        """Returns self if the command succeeded; raises LabVMError with output and transcript if not."""
        if self.status != 0:
            why = "was killed at its time-out" if self.timed_out else f"ended with status {self.status}"
            raise LabVMError(f"the command in the lab VM {why}\n----- its output -----\n{self.output}"
                             f"\n----- console transcript -----\n{self.transcript}\n----- end of transcript -----")
        return self


def _command_script(command):
    if isinstance(command, (list, tuple)):
        if not command:
            raise ValueError("empty command")
        return "exec " + " ".join(shlex.quote(str(part)) for part in command) + "\n"
    if not isinstance(command, str) or not command.strip():
        raise ValueError("the command is a shell script (str) or an argument list")
    return command if command.endswith("\n") else command + "\n"


class LabVM:
    """One boot of the lab VM running one command; see the module docstring.

    command: shell script text (run by /bin/sh) or an argument list.
    vcan: names of vcan interfaces to create and bring up (e.g. ["vcan0"]).
    slcan: a SlcanSetup (or True for can0 at 500 kbit/s) to join can0 to the
        host through the unix socket `slcan_socket_path`; `slcan` then is a
        connected SlcanPort unless connect_slcan=False (another program will).
    setup: more shell lines run before the command, in the chroot, with -e.
    sja1000: one of the lab's SJA1000 cards on the lab hub's buses, with its Linux driver loaded at boot: a
        Sja1000Setup (the ISA card, sja1000_isa) or a KvaserPciSetup (the Kvaser PCIcan, kvaser_pci); can0,
        can1, ... The VM then runs on the QEMU built with the lab's models unless qemu names another. Not
        together with slcan (both would be can0).
    load: modprobe lines run at boot, e.g. "sja1000_isa port=0x2a0 irq=10".
    modules: more modules to put in the initramfs (loadable on demand).
    files: {relative name: str or bytes} placed under /run/labvm/files/.
    timeout: seconds the command may run; boot_timeout: seconds to boot.
    qemu, qemu_args: the emulator binary and extra arguments (e.g. -device
        for a board model; a QEMU built in-tree also needs "-L" BIOS paths).
    memory_mib, cpus, cpu: the guest's memory, CPU count and QEMU CPU model.
    pvh: boot the uncompressed kernel through its PVH entry (about 4 s
        faster than the compressed vmlinuz); False boots vmlinuz.
    ninep_cache: the 9p cache mode of the host's root (see DEFAULT_9P_CACHE).
    kernel_arguments: more kernel command line arguments.
    cwd: the folder the command starts in (default /); the host's folders
        have the same paths in the VM.
    interactive: console on this terminal (labvm.py shell); no capture.
    console_log: a binary file the console is copied to as it arrives.
    log: a function for progress messages (kernel download, ...); default stderr.
    """

    def __init__(self, command, *, vcan=(), slcan=None, sja1000=None, setup=(), load=(), modules=(), files=None,
                 timeout=DEFAULT_COMMAND_TIMEOUT, boot_timeout=DEFAULT_BOOT_TIMEOUT, qemu=None,
                 qemu_args=(), memory_mib=1024, cpus=1, cpu="max", pvh=True, ninep_cache=DEFAULT_9P_CACHE,
                 kernel_arguments="", cwd=None, cache_dir=DEFAULT_CACHE, connect_slcan=True, interactive=False,
                 console_log=None, log=None):
        self.command_script = _command_script(command)
        if cwd and any(cwd == hidden or cwd.startswith(hidden + "/") for hidden in ("/tmp", "/var/tmp", "/run")):
            self._early_warning = (f"labvm: the command starts in {cwd}, but the VM's /tmp, /var/tmp and /run "
                                   "are its own, empty tmpfs: the host's files there are not visible")
        else:
            self._early_warning = None
        if cwd:
            # The host's root is the VM's root, so a host folder has the same
            # path inside, except under /tmp, /var/tmp and /run.
            quoted = shlex.quote(cwd)
            self.command_script = (
                f"cd {quoted} 2>/dev/null || {{ echo 'labvm: no folder '{quoted}' in the VM (its /tmp, /var/tmp "
                f"and /run are its own); running in /' >&2; cd /; }}\n" + self.command_script)
        self.vcan = list(vcan)
        for name in self.vcan:
            if not re.match(r"^[A-Za-z0-9_.-]{1,15}$", name):
                raise ValueError(f"{name!r} is not a network interface name")
        self.slcan_setup = SlcanSetup() if slcan is True else slcan
        self.sja1000 = sja1000
        if sja1000 is not None and self.slcan_setup is not None:
            raise ValueError("slcan and the SJA1000 card would both be can0 in the VM; use one of them")
        self.setup = list(setup)
        load = [line.strip() for line in load if line.strip()]
        if sja1000 is not None:
            load.insert(0, sja1000.load_line())
        self.load = list(initramfs.DEFAULT_LOAD) + load
        self.modules = list(modules) + [line.split()[0] for line in load]
        self.files = dict(files or {})
        self.timeout = float(timeout)
        self.boot_timeout = float(boot_timeout)
        # Resolved when the VM starts (the built QEMU is looked up then).
        self.qemu = qemu
        self.qemu_args = list(qemu_args)
        self.memory_mib = int(memory_mib)
        self.cpus = int(cpus)
        self.cpu = cpu
        self.pvh = pvh
        self._kernel_image = None
        if ninep_cache not in ("none", "loose", "mmap", "fscache"):
            raise ValueError(f"9p cache mode {ninep_cache!r} is not none, loose, mmap or fscache")
        self.ninep_cache = ninep_cache
        self.kernel_arguments = kernel_arguments
        self.cache_dir = cache_dir
        self.connect_slcan = connect_slcan
        self.interactive = interactive
        self.console_log = console_log
        self.log = log or (lambda message: print(message, file=sys.stderr))
        self.nonce = secrets.token_hex(6)
        self.argv = []
        self.kernel = None
        self.slcan = None  # the connected SlcanPort, if any
        self._workdir = None
        self._process = None
        self._reader = None
        self._buffer = bytearray()
        self._cursor = 0
        self._closed = False
        self._condition = threading.Condition()
        self._started_at = None
        self._begin_at = None
        self._result = None
        self._stderr = None

    # -- paths --------------------------------------------------------------

    @property
    def slcan_socket_path(self):
        """The unix socket of the VM's ttyS1 (Lawicel ASCII), or None without slcan."""
        if self.slcan_setup is None or self._workdir is None:
            return None
        return os.path.join(self._workdir.name, "slcan.sock")

    # -- life cycle ---------------------------------------------------------

    def _config(self):
        values = {
            "LABVM_NONCE": self.nonce,
            "LABVM_MODE": "shell" if self.interactive else "batch",
            "LABVM_LOAD": "\n".join(list(initramfs.BOOT_MODULES) + self.load),
            "LABVM_9P_CACHE": self.ninep_cache,
            "LABVM_TIMEOUT": str(max(1, int(round(self.timeout)))),
            "LABVM_TERM": os.environ.get("TERM", "vt100") if self.interactive else "dumb",
        }
        return "".join(f"{name}={shlex.quote(value)}\n" for name, value in values.items())

    def _setup_script(self):
        lines = []
        for name in self.vcan:
            lines += [f"ip link add dev {name} type vcan", f"ip link set {name} up"]
        if self.slcan_setup is not None:
            lines += self.slcan_setup.setup_lines()
        if self.sja1000 is not None:
            lines += self.sja1000.setup_lines()
        lines += self.setup
        return "".join(line + "\n" for line in lines)

    def start(self):
        """Prepares the kernel and initramfs (cached), starts QEMU and returns self."""
        if self._process is not None:
            raise RuntimeError("this LabVM was started already")
        if self._early_warning:
            self.log(self._early_warning)
        if self.qemu is None:
            self.qemu = built_qemu_x86_64() if self.sja1000 is not None else DEFAULT_QEMU
        try:
            self.kernel = obtain_kernel(self.cache_dir, log=self.log)
            self._kernel_image = (self.kernel.vmlinux() if self.pvh else None) or self.kernel.vmlinuz
            base = initramfs.build_base(self.kernel, self.cache_dir, self.modules, log=self.log)
        except LabVMSetupError as error:
            raise LabVMError(f"cannot prepare the lab VM: {error}") from None
        self._workdir = tempfile.TemporaryDirectory(prefix="labvm-")
        run_data = initramfs.run_archive(self._config(), self.command_script, self._setup_script(), self.files)
        initrd = initramfs.boot_image(base, run_data, self._workdir.name)
        self.argv = self._qemu_command(initrd)
        self._started_at = time.monotonic()
        try:
            if self.interactive:
                self._process = subprocess.Popen(self.argv)
                return self
            self._stderr = open(os.path.join(self._workdir.name, "qemu.stderr"), "w+b")
            self._process = subprocess.Popen(self.argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                             stderr=self._stderr, start_new_session=True)
        except OSError as error:
            self.close()
            raise LabVMError(f"cannot start {self.qemu}: {error} "
                             "(qemu-system-x86 installs qemu-system-x86_64: mk/install-deps.sh)") from None
        self._reader = threading.Thread(target=self._read_console, name="labvm-console", daemon=True)
        self._reader.start()
        if self.slcan_setup is not None and self.connect_slcan:
            try:
                self.slcan = SlcanPort(self.slcan_socket_path, connect_timeout=30)
            except AssertionError as error:
                self.close_process()
                failure = self._failure(f"cannot connect to the slcan socket: {error}")
                self.close()
                raise failure from None
        return self

    def _qemu_command(self, initrd):
        argv = [
            self.qemu, "-accel", "tcg", "-cpu", self.cpu, "-m", str(self.memory_mib), "-smp", str(self.cpus),
            "-nodefaults", "-nographic", "-no-reboot",
            "-kernel", self._kernel_image, "-initrd", initrd,
            "-append", f"{KERNEL_ARGUMENTS} {self.kernel_arguments}".strip(),
            "-serial", "mon:stdio" if self.interactive else "stdio",
            "-virtfs", "local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap",
        ]
        if self.slcan_setup is not None:
            argv += ["-chardev", f"socket,id=s1,path={self.slcan_socket_path},server=on,wait=off",
                     "-serial", "chardev:s1"]
        if self.sja1000 is not None:
            # QEMU's default x86_64 machine is pc (i440FX with a PIIX3 ISA bridge): an ISA card fits, and a PCI one.
            argv += ["-machine", "pc", *BUILT_QEMU_FIRMWARE, "-device", self.sja1000.device_argument()]
        return argv + self.qemu_args

    def _read_console(self):
        stream = self._process.stdout
        while True:
            data = stream.read1(65536)
            if data and self.console_log is not None:
                try:
                    self.console_log.write(data)
                    self.console_log.flush()
                except (OSError, ValueError):
                    pass
            with self._condition:
                if not data:
                    self._closed = True
                    self._condition.notify_all()
                    return
                self._buffer += data
                if self._begin_at is None and b"@@LABVM-BEGIN " + self.nonce.encode() in self._buffer:
                    self._begin_at = time.monotonic()
                self._condition.notify_all()

    def close(self):
        """Stops QEMU if it still runs and removes the run's files."""
        if self.slcan is not None:
            self.slcan.close()
        if self._process is not None and self._process.poll() is None:
            try:
                os.killpg(self._process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                self._process.kill()
            self._process.wait(timeout=30)
        if self._reader is not None:
            self._reader.join(timeout=5)
        if self._stderr is not None:
            self._stderr.close()
            self._stderr = None
        if self._workdir is not None:
            self._workdir.cleanup()
            self._workdir = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()

    # -- console ------------------------------------------------------------

    @property
    def transcript(self):
        """The console so far (kernel messages, init's messages, the command's output)."""
        with self._condition:
            return self._buffer.decode("latin-1")

    def qemu_messages(self):
        if self._stderr is None:
            return ""
        self._stderr.flush()
        self._stderr.seek(0)
        return self._stderr.read().decode("utf-8", "replace")

    def _failure(self, what):
        messages = self.qemu_messages()
        return LabVMError(
            f"lab VM: {what}\nQEMU: {' '.join(shlex.quote(a) for a in self.argv)}\n"
            f"----- console transcript -----\n{self.transcript}\n----- end of transcript -----"
            + (f"\n----- QEMU said -----\n{messages}" if messages.strip() else "")
        )

    def _setup_failure(self):
        """The reason init gave for a failed setup (once its line is complete), or None; lock held."""
        marker = re.search(rb"@@LABVM-SETUP-FAILED " + self.nonce.encode() + rb"@@ ([^\r\n]*)\r?\n", self._buffer)
        return marker.group(1).decode("latin-1") if marker else None

    def _raise_setup_failure(self, reason):
        """Lets init print the kernel log and power off, then raises; lock not held."""
        try:
            self._process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.close_process()
        if self._reader is not None:
            self._reader.join(timeout=5)
        raise self._failure(f"setup in the VM failed: {reason}")

    def expect(self, pattern, timeout=60.0):
        """Waits for pattern (a regex) on the console after the previous match; returns the match."""
        regex = re.compile(pattern.encode("latin-1") if isinstance(pattern, str) else pattern)
        deadline = time.monotonic() + timeout
        with self._condition:
            while True:
                match = regex.search(self._buffer, self._cursor)
                if match:
                    self._cursor = match.end()
                    return match
                reason = self._setup_failure()
                if reason is not None:
                    break
                if re.search(rb"@@LABVM-END " + self.nonce.encode(), self._buffer):
                    raise self._failure(f"the command ended before {pattern!r} appeared")
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise self._failure(f"timed out after {timeout:.0f} s waiting for {pattern!r}")
                if self._closed:
                    raise self._failure(f"QEMU ended while waiting for {pattern!r}")
                self._condition.wait(min(remaining, 0.5))
        self._raise_setup_failure(reason)

    def wait(self):
        """Waits for the command to end and QEMU to power off; returns its Result.

        Raises LabVMError when the VM does not boot within boot_timeout, its
        setup fails, QEMU ends early, or no result comes (the VM itself kills
        the command after timeout seconds and reports that as a Result with
        timed_out set). Interactive: waits for QEMU and gives its status."""
        if self._result is not None:
            return self._result
        if self.interactive:
            status = self._process.wait()
            self._result = Result(status, b"", "", False, 0.0, time.monotonic() - self._started_at, self.argv)
            return self._result
        end = re.compile(rb"\n@@LABVM-END " + self.nonce.encode() + rb" status=(\d+)( timed-out)?@@")
        boot_deadline = self._started_at + self.boot_timeout
        reason = None
        with self._condition:
            while True:
                match = end.search(self._buffer)
                if match:
                    break
                reason = self._setup_failure()
                if reason is not None:
                    break
                now = time.monotonic()
                if self._begin_at is None and now > boot_deadline:
                    self.close_process()
                    raise self._failure(f"the VM did not boot and start the command within {self.boot_timeout:.0f} s")
                # The VM kills the command at its time-out; this is the backstop.
                if self._begin_at is not None and now > self._begin_at + self.timeout + 30:
                    self.close_process()
                    raise self._failure(f"the command gave no result within {self.timeout:.0f} s")
                if self._closed:
                    status = self._process.wait(timeout=30)
                    raise self._failure(f"QEMU ended (status {status}) before the command finished")
                self._condition.wait(0.5)
            if reason is None:
                begin = re.search(rb"@@LABVM-BEGIN " + self.nonce.encode() + rb"@@\r?\n", self._buffer)
                output = bytes(self._buffer[begin.end():match.start()]) if begin else b""
                finished_at = time.monotonic()
        if reason is not None:
            self._raise_setup_failure(reason)
        try:
            self._process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.close_process()
        if self._reader is not None:
            self._reader.join(timeout=5)
        self._result = Result(int(match.group(1)), output, self.transcript, bool(match.group(2)),
                              (self._begin_at or finished_at) - self._started_at,
                              finished_at - (self._begin_at or finished_at), self.argv)
        return self._result

    def close_process(self):
        if self._process is not None and self._process.poll() is None:
            try:
                os.killpg(self._process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                self._process.kill()
            self._process.wait(timeout=30)


def run(command, **options):
    """Boots the lab VM, runs command in it and returns its Result (see LabVM for the options)."""
    with LabVM(command, **options) as vm:
        return vm.wait()


class CheckResult:
    def __init__(self, name, status, output):
        self.name = name
        self.status = status
        self.output = output

    def __repr__(self):
        return f"CheckResult({self.name!r}, status={self.status}, output={self.output[:200]!r})"


def check_command(checks, timeout_each=60):
    """A command that runs several named shell scripts one after the other, each with its own
    time-out, and marks each one's output and status; parse the result with parse_checks.

    Returns (command, files) to pass to LabVM/run as command= and files=."""
    files = {}
    lines = ["cd /tmp"]
    tag = secrets.token_hex(4)
    for name, script in checks.items():
        if not re.match(r"^[A-Za-z0-9_-]+$", name):
            raise ValueError(f"check name {name!r}: letters, digits, _ and - only")
        files[f"checks/{name}.sh"] = script if script.endswith("\n") else script + "\n"
        lines += [
            f"echo '@@CHECK-BEGIN {tag} {name}@@'",
            f"timeout -k 5 {int(timeout_each)} /bin/sh -e /run/labvm/files/checks/{name}.sh </dev/null 2>&1",
            f"printf '\\n@@CHECK-END {tag} {name} status=%s@@\\n' $?",
        ]
    return "\n".join(lines) + "\n", files


def parse_checks(result, checks):
    """{name: CheckResult} from a Result of check_command's command; a check that did not run gets status None."""
    parsed = {}
    for name in checks:
        match = re.search(r"@@CHECK-BEGIN (\w+) " + re.escape(name) + r"@@\n(.*?)\n@@CHECK-END \1 "
                          + re.escape(name) + r" status=(\d+)@@", result.output, re.S)
        if match:
            parsed[name] = CheckResult(name, int(match.group(3)), match.group(2))
        else:
            parsed[name] = CheckResult(name, None, "(this check did not run to its end)")
    return parsed

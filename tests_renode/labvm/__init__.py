"""The lab VM: Debian's Linux kernel under QEMU, for real SocketCAN on a host kernel without CAN.

See docs/guide/lab-vm.md. The pieces:
- vm.py: LabVM, run() and Result: boot, run one command, collect its output;
- slcan.py: SlcanPort and CanFrame, the host end of the VM's slcan serial port;
- Sja1000Setup (vm.py): our ISA SJA1000 card in the VM on the lab CAN bus hub, for Linux's sja1000_isa;
- KvaserPciSetup (vm.py): our Kvaser PCIcan in the VM on the lab CAN bus hub, for Linux's kvaser_pci;
- kernel.py: fetching and unpacking Debian's kernel package;
- initramfs.py and init.sh: the busybox initramfs and its /init;
- labvm.py (cli.py): the command line, `labvm.py run -- candump ...`.
"""

from .kernel import LabVMSetupError, obtain_kernel
from .slcan import BITRATE_CODES, CanFrame, SlcanError, SlcanPort
from .vm import (DEFAULT_QEMU, CheckResult, KvaserPciSetup, LabVM, LabVMError, Result, SlcanSetup, Sja1000Setup,
                 built_qemu_x86_64, check_command, parse_checks, run)

__all__ = [
    "BITRATE_CODES", "CanFrame", "CheckResult", "DEFAULT_QEMU", "KvaserPciSetup", "LabVM", "LabVMError",
    "LabVMSetupError", "Result", "SlcanError", "SlcanPort", "SlcanSetup", "Sja1000Setup", "built_qemu_x86_64",
    "check_command", "obtain_kernel", "parse_checks", "run",
]

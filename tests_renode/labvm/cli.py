"""The lab VM's command line.

  labvm.py run [options] -- COMMAND [ARG...]   boot, run COMMAND in the VM, print its output,
                                              exit with its status
  labvm.py run [options] --script FILE          the same with a shell script file
  labvm.py shell [options]                      an interactive shell in the VM (leave with exit,
                                              or Ctrl-A X to stop QEMU)
  labvm.py prepare                              fetch the kernel and build the initramfs, print
                                              what is used

Exit status of run: the command's own; 124 when the VM killed it at its
time-out; 125 when the VM itself failed (the console transcript is printed).
"""

import argparse
import os
import sys

from . import initramfs
from .kernel import DEFAULT_CACHE, LabVMSetupError, obtain_kernel
from .slcan import BITRATE_CODES
from .vm import DEFAULT_9P_CACHE, DEFAULT_BOOT_TIMEOUT, DEFAULT_COMMAND_TIMEOUT, DEFAULT_QEMU, KvaserPciSetup, LabVM, \
    LabVMError, SlcanSetup, Sja1000Setup

VM_FAILED = 125


def _add_vm_options(parser):
    parser.add_argument("--vcan", action="append", default=[], metavar="NAME",
                        help="create and bring up a vcan interface (repeatable), e.g. --vcan vcan0")
    parser.add_argument("--slcan", action="store_true",
                        help="join the VM's CAN interface to the host through slcan on ttyS1; the unix socket's "
                             "path is printed on stderr, for a host program speaking Lawicel ASCII")
    parser.add_argument("--slcan-interface", default="can0", metavar="NAME", help="slcan interface name (can0)")
    parser.add_argument("--slcan-bitrate", type=int, default=500000, choices=sorted(BITRATE_CODES),
                        metavar="BIT/S", help="slcan bit rate, sent as the Lawicel S code (500000 -> S6)")
    parser.add_argument("--sja1000-hub", metavar="SOCKET",
                        help="put our ISA SJA1000 card (isa-sja1000) in the VM, joined to the lab CAN bus hub at "
                             "this unix socket, with Linux's sja1000_isa driver loaded for it; runs the VM on the "
                             "QEMU built with the lab's models (tests_renode/qemu/build_qemu.sh)")
    parser.add_argument("--kvaser-hub", metavar="SOCKET",
                        help="put our Kvaser PCIcan (lab-kvaser-pci, one chip) in the VM instead, joined to the "
                             "lab CAN bus hub at this unix socket, with Linux's kvaser_pci driver loaded for it; "
                             "the --sja1000-bus, --sja1000-bitrate and --sja1000-name options apply to it")
    parser.add_argument("--sja1000-bus", default="can0", metavar="BUS",
                        help="the hub's bus channel 0 is wired to (can0); it is can0 in the VM")
    parser.add_argument("--sja1000-bitrate", type=int, default=500000, metavar="BIT/S",
                        help="bit rate the setup gives can0 before bringing it up (500000; 0: leave it down)")
    parser.add_argument("--sja1000-name", default="linux", metavar="NAME",
                        help="the card's participant name at the hub (linux: its port is linux.0)")
    parser.add_argument("--setup", action="append", default=[], metavar="LINE",
                        help="a shell line run in the VM before the command (repeatable)")
    parser.add_argument("--load", action="append", default=[], metavar="'MODULE [OPTIONS]'",
                        help="a kernel module to load at boot, with options (repeatable), "
                             "e.g. --load 'sja1000_isa port=0x2a0 irq=10'")
    parser.add_argument("--module", action="append", default=[], metavar="MODULE",
                        help="one more kernel module in the initramfs, loaded on demand (repeatable)")
    parser.add_argument("--timeout", type=float, default=DEFAULT_COMMAND_TIMEOUT, metavar="S",
                        help=f"seconds the command may run (default {DEFAULT_COMMAND_TIMEOUT:.0f})")
    parser.add_argument("--boot-timeout", type=float, default=DEFAULT_BOOT_TIMEOUT, metavar="S",
                        help=f"seconds the VM may take to boot (default {DEFAULT_BOOT_TIMEOUT:.0f})")
    parser.add_argument("--qemu", default=None,
                        help=f"the QEMU binary (default {DEFAULT_QEMU}, or the built one with --sja1000-hub or "
                             "--kvaser-hub)")
    parser.add_argument("--qemu-arg", action="append", default=[], metavar="ARG",
                        help="one more QEMU argument as it is (repeatable), e.g. --qemu-arg=-device ...")
    parser.add_argument("--memory", type=int, default=1024, metavar="MIB", help="guest memory (1024 MiB)")
    parser.add_argument("--cpus", type=int, default=1, help="guest CPUs (1)")
    parser.add_argument("--cpu", default="max", help="QEMU CPU model (max)")
    parser.add_argument("--no-pvh", dest="pvh", action="store_false",
                        help="boot the compressed vmlinuz instead of the uncompressed kernel's PVH entry (slower)")
    parser.add_argument("--9p-cache", dest="ninep_cache", default=DEFAULT_9P_CACHE,
                        choices=("none", "loose", "mmap", "fscache"), help="9p cache mode for the host's root")
    parser.add_argument("--append", default="", metavar="ARGS", help="more kernel command line arguments")


def _vm(args, command, interactive=False, console_log=None):
    slcan = SlcanSetup(args.slcan_interface, args.slcan_bitrate) if args.slcan else None
    sja1000 = None
    if args.sja1000_hub and args.kvaser_hub:
        raise ValueError("--sja1000-hub and --kvaser-hub would both make can0; give one of them")
    if args.sja1000_hub:
        sja1000 = Sja1000Setup(os.path.abspath(args.sja1000_hub), bus0=args.sja1000_bus, name=args.sja1000_name,
                               bitrate=args.sja1000_bitrate or None)
    elif args.kvaser_hub:
        sja1000 = KvaserPciSetup(os.path.abspath(args.kvaser_hub), buses=(args.sja1000_bus,), name=args.sja1000_name,
                                 bitrate=args.sja1000_bitrate or None)
    return LabVM(command, cwd=os.getcwd(), vcan=args.vcan, slcan=slcan, sja1000=sja1000, setup=args.setup,
                 load=args.load,
                 modules=args.module,
                 timeout=args.timeout, boot_timeout=args.boot_timeout, qemu=args.qemu, qemu_args=args.qemu_arg,
                 memory_mib=args.memory, cpus=args.cpus, cpu=args.cpu, pvh=args.pvh, ninep_cache=args.ninep_cache,
                 kernel_arguments=args.append, connect_slcan=False, interactive=interactive, console_log=console_log)


def _run(args):
    if args.script:
        with open(args.script, encoding="utf-8") as handle:
            command = handle.read()
    elif args.command:
        command = args.command[1:] if args.command[0] == "--" else args.command
    else:
        print("labvm run: give a command after --, or --script FILE", file=sys.stderr)
        return 2
    console = sys.stderr.buffer if args.console else None
    try:
        with _vm(args, command, console_log=console) as vm:
            if vm.slcan_socket_path:
                print(f"labvm: slcan socket (Lawicel ASCII, {args.slcan_interface} in the VM): "
                      f"{vm.slcan_socket_path}", file=sys.stderr, flush=True)
            result = vm.wait()
    except LabVMError as error:
        print(error, file=sys.stderr)
        return VM_FAILED
    sys.stdout.buffer.write(result.output_bytes)
    sys.stdout.flush()
    print(f"labvm: boot {result.boot_seconds:.1f} s, command {result.run_seconds:.1f} s, "
          f"status {result.status}{' (killed at its time-out)' if result.timed_out else ''}", file=sys.stderr)
    if result.timed_out:
        return 124
    return result.status if result.status < 256 else VM_FAILED


def _shell(args):
    command = "if [ -x /bin/bash ]; then exec /bin/bash -i; else exec /bin/sh -i; fi"
    vm = _vm(args, command, interactive=True)
    try:
        vm.start()
        if vm.slcan_socket_path:
            print(f"labvm: slcan socket: {vm.slcan_socket_path}", file=sys.stderr, flush=True)
        return vm.wait().status
    except LabVMError as error:
        print(error, file=sys.stderr)
        return VM_FAILED
    finally:
        vm.close()


def _prepare(args):
    try:
        kernel = obtain_kernel(DEFAULT_CACHE)
        base = initramfs.build_base(kernel, DEFAULT_CACHE, args.module)
    except LabVMSetupError as error:
        print(f"labvm: {error}", file=sys.stderr)
        return VM_FAILED
    print(f"kernel:    {kernel.release} (Debian package version {kernel.package_version})")
    print(f"vmlinuz:   {kernel.vmlinuz}")
    print(f"vmlinux:   {kernel.vmlinux() or '(no PVH entry: the VM boots vmlinuz)'}")
    print(f"initramfs: {base} ({os.path.getsize(base) // 1024} KiB)")
    return 0


def main(argv=None):
    parser = argparse.ArgumentParser(prog="labvm.py", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="action", required=True)
    run = commands.add_parser("run", help="run one command in the VM")
    _add_vm_options(run)
    run.add_argument("--script", metavar="FILE", help="run this shell script instead of a command")
    run.add_argument("--console", action="store_true", help="copy the whole VM console to stderr as it comes")
    run.add_argument("command", nargs=argparse.REMAINDER, help="-- COMMAND [ARG...]")
    shell = commands.add_parser("shell", help="an interactive shell in the VM")
    _add_vm_options(shell)
    prepare = commands.add_parser("prepare", help="fetch the kernel and build the initramfs")
    prepare.add_argument("--module", action="append", default=[], metavar="MODULE")
    args = parser.parse_args(argv)
    if args.action == "run":
        return _run(args)
    if args.action == "shell":
        return _shell(args)
    return _prepare(args)


if __name__ == "__main__":
    sys.exit(main())

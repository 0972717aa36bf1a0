#!/bin/sh
# Installs the Debian packages the build and the tests need, if any are
# missing. Called by 'make run', 'make test' and 'make deps'; does nothing
# when everything is present.
set -eu

# What each package is for, so the message says why it is installed.
packages="
g++:compiles the firmware and the host tools
g++-multilib:gives g++ the 32-bit C++ headers the firmware is compiled against (its 32-bit libgcc is never linked)
binutils:links the firmware and disassembles it for the i486 instruction check
make:runs the build
libgtest-dev:GoogleTest for the host unit tests
libcli11-dev:parses the host tools' command lines (dcos-can)
libfmt-dev:formats the host tools' output
nlohmann-json3-dev:writes the host tools' --json output
libmodbus-dev:the Modbus RTU master and slave of dcos-modbus and dcos-modbus-sim (host_tools/modbus)
libtomlplusplus-dev:toml++, which parses dcos-modbus-sim's configuration files and the node configurations dcos-config saves and restores
libusb-1.0-0-dev:libusb, through which the host tools drive gs_usb CAN adapters (candleLight, CANable) from user space, without the kernel's gs_usb driver or root (-i gsusb, host_tools/can)
libhidapi-dev:hidapi, through which the host tools drive a controller's reset and recovery lines on a USB HID adapter
libcairo2-dev:cairo, with which dcos-mon draws its trend plots (PNG) and its tests read them back (host_tools/mon)
openssl:an ECDSA implementation we did not write, which checks dcos-image's signatures and makes keys it signs with (tests_renode/test_host_tools_image.py)
libmbedtls-dev:mbedTLS, the vetted SHA-256 and ECDSA P-256 with which dcos-image signs controller images and the image verifier checks them
clang:compiles the CAN link layer's fuzz targets (make fuzz, run by make test)
libclang-rt-14-dev:libFuzzer and the address and undefined-behaviour sanitizer runtimes those fuzz targets link (clang only recommends it)
qemu-system-data:option ROMs the emulator loads (multiboot, linuxboot), from the -L path /usr/share/qemu
seabios:the BIOS image the emulated PC boots through
dpkg-dev:unpacks Debian's QEMU source (apt-get source qemu) that the emulator with our board models is built from
meson:configures that QEMU build (the dfsg source carries no meson of its own)
ninja-build:compiles that QEMU build
pkg-config:lets QEMU's configure find its libraries
libglib2.0-dev:GLib, which QEMU is built on
libpixman-1-dev:pixman, which QEMU's display code needs even without a display
zlib1g-dev:zlib, which QEMU needs
libfdt-dev:the device-tree library QEMU links (--enable-fdt=system)
libcap-ng-dev:lets that QEMU build virtfs (9p), through which the lab VM on the built qemu-system-x86_64 mounts the host's root
libattr1-dev:the extended-attribute library QEMU's virtfs needs as well
python3-pytest:runs the emulator regression suite
python3-pytest-xdist:runs emulator tests side by side
python3-pexpect:drives the make-run console in its test
python3-serial:lets the I/O board bring-up tool (host_tools/bringup) talk to a controller's serial console
python3-matplotlib:draws the bring-up tool's transfer-curve pictures (PNG, Agg backend)
python3-hypothesis:fuzzes the host tools' parsers with property-based tests (tests_renode/test_host_tools_fuzz.py)
qemu-system-x86:runs the lab VM, Debian's Linux with real SocketCAN, as this machine's kernel may have no CAN (docs/guide/lab-vm.md)
busybox-static:makes the lab VM's initramfs: its /init, modprobe and depmod
iproute2:creates the lab VM's vcan and slcan interfaces (ip link)
can-utils:candump, cansend, slcand, isotpsend and isotprecv, run in the lab VM against the Linux CAN stack (tests_renode/test_labvm.py)
gpiod:gpioset, gpioget and gpioinfo, run in the lab VM against Linux's hid-mcp2221 gpiochip on the emulated MCP2221A (tests_renode/test_mcp2221_labvm.py)
python3-can:python-can, tested in the lab VM against real SocketCAN (tests_renode/test_labvm.py)
python3-pymodbus:a Modbus implementation we did not write: slave and master against dcos-modbus and dcos-modbus-sim (tests_renode/test_host_tools_modbus.py), and the builder and checker of the RTU frames the emulator tests exchange with the controller's RS-485 line (tests_renode/test_modbus_rs485.py)
python3-serial-asyncio:pymodbus's serial slave is built on it (pymodbus only recommends it)
"

missing=""
reasons=""
old_ifs=$IFS
IFS='
'
for entry in $packages; do
    [ -n "$entry" ] || continue
    name=${entry%%:*}
    why=${entry#*:}
    status=$(dpkg-query -W -f='${Status}' "$name" 2>/dev/null || true)
    case "$status" in
        *"install ok installed"*) ;;
        *) missing="$missing $name"; reasons="$reasons  $name: $why
" ;;
    esac
done
IFS=$old_ifs

[ -n "$missing" ] || exit 0

echo "DCOS needs these Debian packages, which are not installed:"
printf '%s' "$reasons"
if [ "$(id -u)" -eq 0 ]; then
    run=""
elif command -v sudo >/dev/null 2>&1; then
    run="sudo"
    echo "Installing them with sudo."
else
    echo "error: not root and no sudo; install them with: apt-get install$missing" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
# shellcheck disable=SC2086
if ! $run apt-get install -y -q --no-install-recommends $missing; then
    echo "Package lists may be stale; updating them and trying again."
    $run apt-get update -q
    # shellcheck disable=SC2086
    $run apt-get install -y -q --no-install-recommends $missing
fi

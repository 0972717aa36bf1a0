#!/bin/sh
# Installs DCOS for building applications outside the source tree.
#
#   mk/install-sdk.sh <prefix> <emulator> <host tools bin> <board> <library> <minimal library> <image> <board flags file> [<board> ...]
#
# Called by 'make install PREFIX=<prefix>' and, for the tree's own 'make app',
# with the prefix build/sdk; mk/sdk.mk passes the ISA 486 board (486) and
# the dual-Pentium board (p5smp), five arguments each. Lays out:
#
#   include/                     the firmware's public and internal headers
#   lib/dcos/<board>/libdcos<board>.a  the kernel, board support, shell and drivers
#   lib/dcos/<board>/libdcos<board>-minimal.a  the minimal kernel configuration: the system,
#                                scheduler, task and timer agents and board support
#   lib/dcos/<board>/link.ld     the image's memory layout (the same for every board)
#   lib/dcos/<board>/<image>     the plain controller image (no application): dcos486.elf, dcos-p5smp.elf
#   lib/dcos/p5smp/include/      the dual-Pentium board's own headers, found before include/ by
#                                that board's builds only (its bsp/BoardTick.hpp is not the 486's)
#   share/dcos/board-<board>.mk  the compiler and linker flags, checks and emulated board of each board
#   share/dcos/application.mk    the application build (see its header)
#   share/dcos/boards/           the emulated boards, each with its board's plain image
#   share/dcos/python/           the emulator lab (dcoslab), its launcher and the distributed plant (plant.py)
#   share/dcos/pytest.ini        pytest settings for applications' tests
#   share/dcos/tools/            the i486 instruction check, the configuration error summary,
#                                the plant simulator, bringup/ (the I/O board bring-up tool)
#   bin/mfio_bringup.py          the I/O board bring-up tool (a relative link into share/dcos/tools)
#   bin/plant_simulator.py       the plant simulator for the emulated I/O board (likewise)
#   bin/dcos-can                 dump, send and measure CAN traffic (docs/guide/host-can.md)
#   bin/dcos-modbus              read and write a Modbus RTU slave (docs/guide/modbus-host.md)
#   bin/dcos-modbus-sim          a simulated Modbus RTU slave declared in a TOML file (likewise)
#   bin/dcos-image               signing keys, signed controller images (docs/guide/signing-images.md)
#   bin/dcos-card                controller cards: create, write a slot, show (likewise)
#   bin/dcos-flash               flash a controller over its serial line (docs/guide/flashing.md)
#   share/dcos/modbus/           dcos-modbus-sim's example files: a drive, a sensor
#   libexec/dcos/                the emulator built with the DCOS board models
#
# Nothing installed refers back to the source tree, and the paths inside are
# relative, so the prefix can be moved as a whole. Files are replaced only
# when their content changes, so a repeated install is quick and keeps times.
set -eu

usage="usage: $0 <prefix> <emulator> <host tools bin> <board> <library> <minimal library> <image> <board flags file> [<board> ...]"
[ $# -ge 8 ] && [ $(( ($# - 3) % 5 )) -eq 0 ] || { echo "$usage" >&2; exit 2; }
prefix=$1
emulator=$2
host_tools_bin=$3
shift 3

# A board whose headers replace common ones of the same name (bsp/BoardTick.hpp:
# each board inlines its own tick timer) has them installed apart, in
# lib/dcos/<board>/include/, which application.mk puts first for that board.
board_include_target() {
    case "$1" in
        firmware/bsp_p5smp/include) echo p5smp ;;
    esac
}

# Copies a file if it differs, creating directories on the way, with mode
# $3 (default 644: readable by everyone, whatever the source's mode, e.g. a
# private temporary file). The mode is set again on an unchanged file, so an
# earlier install with another mode is corrected.
put() {
    mkdir -p "$(dirname "$2")"
    if ! cmp -s "$1" "$2"; then
        install -m "${3:-644}" "$1" "$2.new"
        mv "$2.new" "$2"
    else
        chmod "${3:-644}" "$2"
    fi
}

# Makes $2 a symbolic link to $1 (relative to $2's directory, so the prefix
# can move), replacing whatever is there in one rename.
link() {
    mkdir -p "$(dirname "$2")"
    if [ ! -L "$2" ] || [ "$(readlink "$2")" != "$1" ]; then
        rm -f "$2.new"
        ln -s "$1" "$2.new"
        mv -fT "$2.new" "$2"
    fi
}

for include_dir in firmware/*/include drivers/*/include fieldbus/*/include; do
    board=$(board_include_target "$include_dir")
    destination="$prefix/include"
    [ -z "$board" ] || destination="$prefix/lib/dcos/$board/include"
    (cd "$include_dir" && find . -name '*.hpp' -type f) | while read -r header; do
        put "$include_dir/$header" "$destination/$header"
    done
done

# Each board: its libraries, linker script, plain image and flags. The
# emulated board each one names (DCOS_BOARD_EMULATED) gets that image as
# its production image below.
emulated_images=$(mktemp)
while [ $# -gt 0 ]; do
    board=$1 library=$2 minimal_library=$3 image=$4 board_flags=$5
    shift 5
    put "$library" "$prefix/lib/dcos/$board/libdcos$board.a"
    put "$minimal_library" "$prefix/lib/dcos/$board/libdcos$board-minimal.a"
    put firmware/boot/link.ld "$prefix/lib/dcos/$board/link.ld"
    put "$image" "$prefix/lib/dcos/$board/$(basename "$image")"
    put "$board_flags" "$prefix/share/dcos/board-$board.mk"
    emulated=$(sed -n 's/^DCOS_BOARD_EMULATED := *//p' "$board_flags")
    [ -n "$emulated" ] || { echo "$0: $board_flags names no DCOS_BOARD_EMULATED" >&2; exit 1; }
    printf '%s lib/dcos/%s/%s\n' "$emulated" "$board" "$(basename "$image")" >> "$emulated_images"
done

put mk/application.mk "$prefix/share/dcos/application.mk"
put host_tools/isa_check/check_i486.py "$prefix/share/dcos/tools/check_i486.py"
put host_tools/app_build/explain_configuration_error.py "$prefix/share/dcos/tools/explain_configuration_error.py"
put tests_renode/pytest.ini "$prefix/share/dcos/pytest.ini"

# The engineers' host tools, started through bin/. The bring-up tool finds
# bringup_report.py beside its real path and the emulator lab (for
# --emulator) in share/dcos/python; the plant simulator needs nothing else.
put host_tools/bringup/mfio_bringup.py "$prefix/share/dcos/tools/bringup/mfio_bringup.py" 755
put host_tools/bringup/bringup_report.py "$prefix/share/dcos/tools/bringup/bringup_report.py"
put host_tools/plant_simulator/plant_simulator.py "$prefix/share/dcos/tools/plant_simulator.py" 755
link ../share/dcos/tools/bringup/mfio_bringup.py "$prefix/bin/mfio_bringup.py"
link ../share/dcos/tools/plant_simulator.py "$prefix/bin/plant_simulator.py"
# The compiled host tools (docs/guide/host-can.md, docs/guide/modbus-host.md),
# and the simulated slaves the Modbus guide starts from.
for tool in "$host_tools_bin"/*; do
    put "$tool" "$prefix/bin/$(basename "$tool")" 755
done
for example in host_tools/modbus/examples/*.toml; do
    put "$example" "$prefix/share/dcos/modbus/$(basename "$example")"
done
put tests_renode/launch.py "$prefix/share/dcos/python/launch.py"
put tests_renode/plant.py "$prefix/share/dcos/python/plant.py"
for module in tests_renode/dcoslab/*.py; do
    put "$module" "$prefix/share/dcos/python/dcoslab/$(basename "$module")"
done

# The boards, with their board's plain controller image as their production
# image (the first board's, for an emulated board no installed board names).
for board in tests_renode/boards/*.json; do
    rewritten=$(mktemp)
    /usr/bin/python3 - "$board" "$rewritten" "$emulated_images" <<'PYTHON'
import json, sys
board = json.load(open(sys.argv[1], encoding="utf-8"))
images = [line.split() for line in open(sys.argv[3], encoding="utf-8") if line.strip()]
production = dict(images).get(board["name"], images[0][1])
board["images"] = {"production": production}
with open(sys.argv[2], "w", encoding="utf-8") as handle:
    json.dump(board, handle, indent=4)
    handle.write("\n")
PYTHON
    put "$rewritten" "$prefix/share/dcos/boards/$(basename "$board")"
    rm -f "$rewritten"
done
rm -f "$emulated_images"

# Tells dcoslab it runs from an installation (tests_renode/dcoslab/layout.py).
layout=$(mktemp)
printf '{"root": "../../../..", "boards": "share/dcos/boards", "emulator_dir": "libexec/dcos"}\n' > "$layout"
put "$layout" "$prefix/share/dcos/python/dcoslab/installed_layout.json"
rm -f "$layout"

# The emulator, stripped of its debug information (about a quarter of the size).
mkdir -p "$prefix/libexec/dcos"
stripped=$(mktemp)
strip -o "$stripped" "$emulator"
put "$stripped" "$prefix/libexec/dcos/qemu-system-i386" 755
rm -f "$stripped"

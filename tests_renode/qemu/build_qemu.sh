#!/bin/sh
# Builds the emulator the lab runs every board on: Debian's own QEMU 7.2
# source (apt-get source qemu) with our device models from tests_renode/models/
# compiled in: qemu-system-i386, which runs every board, and
# qemu-system-x86_64, which runs the lab VM (Debian's 64-bit Linux) when it
# carries one of our cards, e.g. the ISA SJA1000 for Linux's sja1000_isa or
# the Kvaser PCIcan for its kvaser_pci.
#
#   tests_renode/qemu/build_qemu.sh               build if needed, print the path
#   tests_renode/qemu/build_qemu.sh --print-path  print where qemu-system-i386 for
#                                                 the current sources is (built or
#                                                 not); qemu-system-x86_64 is beside it
#
# The result is cached in build/qemu-<key>/, where <key> is a
# hash of this script and of every file under tests_renode/models/. While the
# key is unchanged a run only computes the hash (well under a second). When a
# model changes, the source tree and ninja build folder in build/qemu-src/ are
# kept, so only the changed model is recompiled (about 10 s); a fresh clone
# fetches the source and builds QEMU once: about 12 CPU-minutes, so about
# 6-7 minutes on 2 idle cores (measured 2026-11-25: 10.6 min user + 1.7 min
# system; 23 minutes of wall time while another full 'make test' ran). The
# x86_64 target adds its own copy of the CPU emulation and machine code,
# about a quarter of the compile time; the device models and the rest are
# compiled once for both.
#
# Needs root or sudo only to enable deb-src in the machine's existing apt
# sources, to refresh the package lists and to install the build packages.
set -eu

LC_ALL=C
export LC_ALL

script_dir=$(cd "$(dirname "$0")" && pwd)
repository=$(cd "$script_dir/../.." && pwd)
models_dir="$repository/tests_renode/models"
build_root="$repository/build"
source_root="$build_root/qemu-src"
ninja_dir="$source_root/build"
apt_sources=/etc/apt/sources.list.d/debian.sources

# Only what the lab uses: TCG (with -icount for exact time), KVM for
# benchmarks on real cycles, the system libfdt; virtfs (9p, with libattr and
# libcap-ng) because the lab VM mounts the host's root over 9p; no UI, audio,
# network back ends or documentation. Changing this line changes the cache
# key.
configure_options="--target-list=i386-softmmu,x86_64-softmmu --without-default-features --enable-tcg --enable-kvm \
--enable-fdt=system --enable-virtfs --enable-attr --enable-cap-ng --disable-docs --disable-werror"
programs="qemu-system-i386 qemu-system-x86_64"

say() {
    echo "build_qemu: $*" >&2
}

fail() {
    echo "build_qemu: error: $*" >&2
    exit 1
}

# The cache key: this script and the models, by name and content.
cache_key() {
    (
        cd "$repository"
        find tests_renode/qemu/build_qemu.sh tests_renode/models -type f | sort | while read -r file; do
            sha256sum "$file"
        done
    ) | sha256sum | cut -c1-16
}

key=$(cache_key)
cache_dir="$build_root/qemu-$key"
binary="$cache_dir/qemu-system-i386"

if [ "${1:-}" = "--print-path" ]; then
    echo "$binary"
    exit 0
fi
[ $# -eq 0 ] || fail "unknown argument '$1' (the only option is --print-path)"

# Both programs, or the build is not complete (a cache folder from an
# interrupted copy has only the first).
built() {
    for program in $programs; do
        [ -x "$cache_dir/$program" ] || return 1
    done
}

if built; then
    say "up to date: $binary"
    exit 0
fi

mkdir -p "$source_root"
# One build at a time: parallel 'make' runs in the same tree wait here.
exec 9>"$source_root/.lock"
if ! flock -w 1800 9; then
    fail "another build of QEMU held $source_root/.lock for 30 minutes"
fi
if built; then
    say "up to date (built by a parallel run): $binary"
    exit 0
fi

as_root() {
    if [ "$(id -u)" -eq 0 ]; then
        "$@"
    elif command -v sudo >/dev/null 2>&1; then
        sudo "$@"
    else
        fail "this step needs root and there is no sudo: $*"
    fi
}

# -- build packages -----------------------------------------------------------
"$repository/mk/install-deps.sh"

# -- the source ---------------------------------------------------------------
# apt-get source leaves qemu-<upstream version>/ next to the .dsc.
find_tree() {
    for candidate in "$source_root"/qemu-7.2*; do
        if [ -f "$candidate/VERSION" ] && [ -f "$candidate/configure" ]; then
            echo "$candidate"
            return 0
        fi
    done
    return 1
}

if ! tree=$(find_tree); then
    if [ -z "$(apt-cache showsrc qemu 2>/dev/null | head -n 1)" ]; then
        [ -f "$apt_sources" ] || fail "no source package index and no $apt_sources to enable deb-src in; \
add 'deb-src' to your apt sources, run 'apt-get update' and try again"
        if ! grep -q '^Types:.*deb-src' "$apt_sources"; then
            say "enabling source packages (deb-src) in $apt_sources"
            as_root sed -i 's/^Types: *deb *$/Types: deb deb-src/' "$apt_sources"
        fi
        say "refreshing the package lists for the source index"
        as_root apt-get update -q
    fi
    say "fetching Debian's QEMU source (apt-get source qemu, about 23 MB) into $source_root"
    rm -rf "$source_root"/qemu-7.2* "$source_root"/qemu_*
    (cd "$source_root" && apt-get source -q qemu) >"$source_root/apt-get-source.log" 2>&1 || {
        tail -n 20 "$source_root/apt-get-source.log" >&2
        fail "apt-get source qemu failed (log: $source_root/apt-get-source.log)"
    }
    tree=$(find_tree) || fail "apt-get source qemu left no QEMU 7.2 tree in $source_root"
fi
say "source: $tree (QEMU $(cat "$tree/VERSION"), Debian $(head -n 1 "$tree/debian/changelog" | sed 's/.*(\(.*\)).*/\1/'))"

# -- our models ---------------------------------------------------------------
# Every C file and header in tests_renode/models/ goes to hw/misc/dcos/
# (the models include their shared headers, e.g. labbus_link.h, from their
# own folder), and every C file is listed in hw/misc/meson.build: a PCI
# card's front end (pci_*.c) when the target has PCI (CONFIG_PCI), every
# other file, the shared ones (the SJA1000 chip core, the link) included,
# when it has an ISA bus (CONFIG_ISA_BUS). Both targets built here, i386
# and x86_64, have both. Stale copies are removed, and files are only
# rewritten when they change, so ninja recompiles only what changed.
model_tree="$tree/hw/misc/dcos"
mkdir -p "$model_tree"
for copied in "$model_tree"/*.c "$model_tree"/*.h; do
    [ -e "$copied" ] || continue
    [ -e "$models_dir/$(basename "$copied")" ] || rm -f "$copied"
done
meson_lines=""
for model in "$models_dir"/*.c "$models_dir"/*.h; do
    [ -e "$model" ] || continue
    name=$(basename "$model")
    cmp -s "$model" "$model_tree/$name" || cp "$model" "$model_tree/$name"
    case "$name" in
    pci_*.c)
        meson_lines="${meson_lines}softmmu_ss.add(when: 'CONFIG_PCI', if_true: files('dcos/$name')) # dcos model
"
        ;;
    *.c)
        meson_lines="${meson_lines}softmmu_ss.add(when: 'CONFIG_ISA_BUS', if_true: files('dcos/$name')) # dcos model
"
        ;;
    esac
done
misc_meson="$tree/hw/misc/meson.build"
grep -v '# dcos model$' "$misc_meson" >"$misc_meson.new" || true
printf '%s' "$meson_lines" >>"$misc_meson.new"
if cmp -s "$misc_meson.new" "$misc_meson"; then
    rm -f "$misc_meson.new"
else
    mv "$misc_meson.new" "$misc_meson"
fi

# -- configure ----------------------------------------------------------------
# The ninja folder is reused while the options are the same.
if [ ! -f "$ninja_dir/build.ninja" ] || [ "$(cat "$ninja_dir/dcos-configure-options" 2>/dev/null)" != "$configure_options" ]; then
    say "configuring: $configure_options"
    rm -rf "$ninja_dir"
    mkdir -p "$ninja_dir"
    # shellcheck disable=SC2086
    (cd "$ninja_dir" && "$tree/configure" --meson=meson $configure_options) >"$source_root/configure.log" 2>&1 || {
        tail -n 30 "$source_root/configure.log" >&2
        fail "configure failed (log: $source_root/configure.log)"
    }
    echo "$configure_options" >"$ninja_dir/dcos-configure-options"
fi

# -- build --------------------------------------------------------------------
jobs=$(nproc 2>/dev/null || echo 2)
started=$(date +%s)
say "building $programs with $jobs jobs (a first build takes about 7 minutes on 2 idle cores; log: $source_root/ninja.log)"
# shellcheck disable=SC2086 # two program names
ninja -C "$ninja_dir" -j "$jobs" $programs >"$source_root/ninja.log" 2>&1 || {
    grep -B 2 -A 12 -E 'error|FAILED' "$source_root/ninja.log" | head -n 60 >&2 || tail -n 40 "$source_root/ninja.log" >&2
    fail "building $programs failed (log: $source_root/ninja.log)"
}
say "built in $(($(date +%s) - started)) s"

# -- cache ------------------------------------------------------------------
mkdir -p "$cache_dir"
# qemu-system-i386 goes last: the other scripts take its presence (and
# built() here both) as "this folder is complete".
for program in qemu-system-x86_64 qemu-system-i386; do
    cp "$ninja_dir/$program" "$cache_dir/$program.new"
    mv "$cache_dir/$program.new" "$cache_dir/$program"
done
# Binaries built for earlier sources: the three newest stay, for a run that
# started before this build and for switching back and forth between
# branches; older ones go.
# shellcheck disable=SC2012 # the names are our own hex keys
ls -dt "$build_root"/qemu-???????????????? 2>/dev/null | tail -n +4 | while read -r old; do
    rm -rf "$old"
done
say "ready: $binary"

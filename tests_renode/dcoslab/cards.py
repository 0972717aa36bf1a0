"""Controllers' cards for the lab's tests (docs/boot.md): signed images and
cards made with the built host tools (dcos-image, dcos-card), the boot
sector, the stage loader and the development key (mk/card.mk)."""
import json
import os
import shutil
import subprocess

from .board import REPOSITORY

BIN = os.path.join(REPOSITORY, "build", "host_tools", "bin")
BUILT = os.path.join(REPOSITORY, "build", "486")
DEVELOPMENT_KEY = os.path.join(REPOSITORY, "build", "keys", "development.pem")

SLOT_LBA = {"A": 2048, "B": 6144}
SECTOR = 512


def tool(name, *arguments, code=0, timeout=120):
    """Runs a built host tool; fails the test unless it exits with @p code."""
    result = subprocess.run([os.path.join(BIN, name), *arguments], capture_output=True, text=True, timeout=timeout)
    assert result.returncode == code, (
        f"{name} {' '.join(arguments)}: exit {result.returncode}, expected {code}\n{result.stdout}{result.stderr}")
    return result


def signed(directory, version, firmware="dcos486.elf", key=DEVELOPMENT_KEY):
    """The firmware build/486/@p firmware signed as @p version, in @p directory."""
    path = os.path.join(str(directory), f"{os.path.splitext(firmware)[0]}-{version}.dcos")
    tool("dcos-image", "sign", "-k", key, "--board", "isa486", "--version", version, "-o", path,
         os.path.join(BUILT, firmware))
    return path


def signed_loop(directory, name, version, data_bytes=0):
    """A signed isa486 image whose code is one jump to itself, linked at 1 MiB, with data_bytes of 0x5a after it:
    an image that never answers and never confirms, of a chosen size. Its path, directory/name.dcos."""
    source, obj, elf = (os.path.join(str(directory), f"{name}.{suffix}") for suffix in ("S", "o", "elf"))
    with open(source, "w", encoding="ascii") as handle:
        handle.write(".globl _start\n.text\n_start: jmp _start\n")
        if data_bytes:
            handle.write(f".data\n.fill {data_bytes},1,0x5a\n")
    subprocess.run(["gcc", "-m32", "-c", source, "-o", obj], check=True)
    subprocess.run(["ld", "-m", "elf_i386", "-nostdlib", "-static", "-N", "-Ttext=0x100000", "-o", elf, obj],
                   check=True, capture_output=True)
    image = os.path.join(str(directory), f"{name}.dcos")
    tool("dcos-image", "sign", "-k", DEVELOPMENT_KEY, "--board", "isa486", "--version", version, "-o", image, elf)
    return image


def signed_application(directory, source, version="1.0.0"):
    """The application in the folder @p source (one of the repository's, e.g.
    tests_renode/monitor/ramp_app) built against the staged SDK in
    @p directory and signed with the development key as @p version."""
    folder = os.path.join(str(directory), os.path.basename(source))
    shutil.copytree(os.path.join(REPOSITORY, source), folder)
    makefile = os.path.join(REPOSITORY, "build", "sdk", "share", "dcos", "application.mk")
    result = subprocess.run(["make", "--no-print-directory", "-f", makefile, f"APP={folder}", "app"],
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    name = os.path.basename(source)
    image = os.path.join(folder, f"{name}-{version}.dcos")
    tool("dcos-image", "sign", "-k", DEVELOPMENT_KEY, "--board", "isa486", "--version", version, "-o", image,
         os.path.join(folder, "build", f"{name}-486.elf"))
    return image


def config_key(directory, name):
    """A new configuration key file made by dcos-config keygen."""
    path = os.path.join(str(directory), f"{name}.key")
    tool("dcos-config", "keygen", "-o", path)
    return path


def dcos_config(lab, *arguments, code=0, probe_ms="500", timeout=900):
    """dcos-config on the lab's bus can0 with --json: (its parsed output, or
    None unless it exits 0, and its standard error). The probe wait is wall
    time on the host, so it is long enough for a busy machine."""
    result = subprocess.run([os.path.join(BIN, "dcos-config"), "-i", f"lab:{lab.socket_path}:can0", "--json",
                             "--probe-ms", probe_ms, *arguments], capture_output=True, text=True, timeout=timeout)
    assert result.returncode == code, (result.returncode, result.stdout, result.stderr, lab.hub.log_text()[-4000:])
    return (json.loads(result.stdout) if code == 0 else None), result.stderr


def new_card(directory, *slots, append="node=3", options=()):
    """A card trusting the development key, with (slot, image, pending) written in order;
    options go to dcos-card create (e.g. ("--bitrate", "1000000"))."""
    path = os.path.join(str(directory), "card.img")
    tool("dcos-card", "create", "-o", path, "--boot-sector", os.path.join(BUILT, "boot-sector.bin"),
         "--stage", os.path.join(BUILT, "stage-loader.bin"), "-p", DEVELOPMENT_KEY + ".pub", "--append", append,
         *options)
    for slot, image, pending in slots:
        tool("dcos-card", "write", path, "--slot", slot, image, *(["--pending"] if pending else []))
    return path


def card_state(path):
    """dcos-card show's JSON for the card at @p path."""
    return json.loads(tool("dcos-card", "--json", "show", path).stdout)


def put_in_slot(card, slot, image):
    """Writes the image file @p image into @p slot of @p card byte for byte, as
    a card reader would, without dcos-card's checks or a boot state change."""
    with open(image, "rb") as handle:
        data = handle.read()
    with open(card, "r+b") as handle:
        handle.seek(SLOT_LBA[slot] * SECTOR)
        handle.write(data[:256] + bytes(256) + data[256:])

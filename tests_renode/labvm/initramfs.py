"""The lab VM's initramfs: busybox, /init and the kernel modules the VM needs.

The boot image QEMU gets is two cpio archives one after the other, which the
kernel unpacks in turn:
- the base archive (cached, gzip): Debian's static busybox with its applet
  links, /init (init.sh beside this file) and the modules with their
  modules.dep and modules.alias, built once per kernel, module set, busybox
  and init.sh, in build/labvm/initramfs-<key>.cpio.gz;
- the run archive (a few KiB, uncompressed): /labvm/config.sh, setup.sh,
  command.sh and lib.sh for this one run, plus any files the caller passes.
"""

import gzip
import hashlib
import io
import os
import shutil
import stat
import tempfile

from .kernel import BUSYBOX, CacheLock, _run

HERE = os.path.dirname(os.path.abspath(__file__))
INIT_SCRIPT = os.path.join(HERE, "init.sh")
SHELL_LIBRARY = os.path.join(HERE, "lib.sh")

# 9p over virtio, for the host's root.
BOOT_MODULES = ("virtio_pci", "9pnet_virtio", "9p")
# In every image, so the kernel can also load them on demand (its modprobe
# helper runs busybox's modprobe in the initramfs).
CAN_MODULES = ("can", "can-raw", "can-bcm", "can-gw", "can-isotp", "can-j1939", "can-dev", "vcan", "vxcan",
               "slcan", "sja1000", "sja1000_isa")
# Loaded at every boot; sja1000_isa is not: it needs port= and irq=.
DEFAULT_LOAD = ("can", "can-raw", "can-bcm", "can-gw", "can-isotp", "can-dev", "vcan", "vxcan", "slcan")


class CpioWriter:
    """Writes a cpio archive in the kernel's "newc" format."""

    def __init__(self):
        self._out = io.BytesIO()
        self._inode = 1000

    def _entry(self, name, mode, data=b"", rdev=(0, 0)):
        name = name.lstrip("/")
        encoded = name.encode() + b"\0"
        self._inode += 1
        fields = (self._inode, mode, 0, 0, 1, 0, len(data), 0, 0, rdev[0], rdev[1], len(encoded), 0)
        header = b"070701" + b"".join(b"%08X" % value for value in fields)
        self._out.write(header + encoded)
        self._pad()
        self._out.write(data)
        self._pad()

    def _pad(self):
        self._out.write(b"\0" * (-self._out.tell() % 4))

    def directory(self, name, mode=0o755):
        self._entry(name, stat.S_IFDIR | mode)

    def file(self, name, data, mode=0o644):
        self._entry(name, stat.S_IFREG | mode, data)

    def symlink(self, name, target):
        self._entry(name, stat.S_IFLNK | 0o777, target.encode())

    def char_device(self, name, major, minor, mode=0o600):
        self._entry(name, stat.S_IFCHR | mode, rdev=(major, minor))

    def finish(self):
        self._entry("TRAILER!!!", 0)
        # A following archive must start 4-byte aligned; pad to 512 like cpio(1).
        self._out.write(b"\0" * (-self._out.tell() % 512))
        return self._out.getvalue()


def _busybox_applets():
    """Applet paths busybox installs, e.g. 'sbin/modprobe', 'usr/bin/timeout'."""
    listing = _run([BUSYBOX, "--list-full"], "listing busybox applets")
    return [line.strip() for line in listing.splitlines() if line.strip()]


def base_key(kernel, modules):
    """The cache key of a base archive: kernel, module set, busybox and init.sh."""
    digest = hashlib.sha256()
    digest.update(kernel.release.encode() + b"\0" + kernel.package_version.encode() + b"\0")
    digest.update("\0".join(modules).encode() + b"\0")
    for path in (BUSYBOX, INIT_SCRIPT, __file__):
        with open(path, "rb") as handle:
            digest.update(hashlib.sha256(handle.read()).digest())
    return digest.hexdigest()[:16]


def build_base(kernel, cache_dir, extra_modules=(), log=print):
    """Path of the cached gzip base archive with busybox, /init and the modules."""
    wanted = list(BOOT_MODULES) + list(CAN_MODULES) + [m for m in extra_modules if m not in CAN_MODULES]
    modules = kernel.module_closure(wanted)
    key = base_key(kernel, modules)
    path = os.path.join(cache_dir, f"initramfs-{key}.cpio.gz")
    if os.path.exists(path):
        return path
    with CacheLock(cache_dir):
        if os.path.exists(path):
            return path
        log(f"labvm: building the initramfs ({len(modules)} modules of {kernel.release}) -> {path}")
        archive = CpioWriter()
        for directory in ("bin", "sbin", "usr", "usr/bin", "usr/sbin", "dev", "proc", "sys", "tmp", "run",
                          "host", "labvm", "lib", "lib/modules", f"lib/modules/{kernel.release}"):
            archive.directory(directory)
        archive.char_device("dev/console", 5, 1)
        archive.char_device("dev/null", 1, 3, 0o666)
        archive.char_device("dev/ttyS0", 4, 64)
        with open(BUSYBOX, "rb") as handle:
            archive.file("bin/busybox", handle.read(), 0o755)
        for applet in _busybox_applets():
            if applet != "bin/busybox":
                archive.symlink(applet, "/bin/busybox")
        with open(INIT_SCRIPT, "rb") as handle:
            archive.file("init", handle.read(), 0o755)
        archive.file("labvm-release", (kernel.release + "\n").encode())
        # The modules, then their index, which busybox's depmod writes for
        # exactly this subset (it is quick on a few dozen files).
        with tempfile.TemporaryDirectory(prefix="labvm-modules-") as staging:
            base = os.path.join(staging, "lib", "modules", kernel.release)
            for relative in modules:
                target = os.path.join(base, relative)
                os.makedirs(os.path.dirname(target), exist_ok=True)
                shutil.copyfile(os.path.join(kernel.modules_dir, relative), target)
            for name in ("modules.builtin", "modules.order"):
                shutil.copyfile(os.path.join(kernel.modules_dir, name), os.path.join(base, name))
            _run([BUSYBOX, "depmod", "-b", staging, kernel.release], "indexing the initramfs modules")
            for root, directories, files in os.walk(base):
                directories.sort()
                relative_root = os.path.relpath(root, staging)
                if relative_root != os.path.join("lib", "modules", kernel.release):
                    archive.directory(relative_root)
                for name in sorted(files):
                    with open(os.path.join(root, name), "rb") as handle:
                        archive.file(os.path.join(relative_root, name), handle.read())
        data = gzip.compress(archive.finish(), compresslevel=6, mtime=0)
        data += b"\0" * (-len(data) % 512)
        with open(path + ".new", "wb") as handle:
            handle.write(data)
        os.replace(path + ".new", path)
        # Archives for other kernels or module sets: keep the five newest.
        old = sorted((p for p in _glob_archives(cache_dir) if p != path), key=os.path.getmtime, reverse=True)
        for stale in old[4:]:
            os.unlink(stale)
    return path


def _glob_archives(cache_dir):
    return [os.path.join(cache_dir, name) for name in os.listdir(cache_dir)
            if name.startswith("initramfs-") and name.endswith(".cpio.gz")]


def run_archive(config, command, setup="", files=None):
    """The small uncompressed archive for one run: /labvm/config.sh, /labvm/command.sh,
    /labvm/setup.sh (init runs it before the command, if not empty), /labvm/lib.sh (shell
    helpers for commands) and /labvm/files/*."""
    archive = CpioWriter()
    archive.file("labvm/config.sh", config.encode())
    archive.file("labvm/command.sh", command.encode(), 0o755)
    archive.file("labvm/setup.sh", setup.encode(), 0o755)
    with open(SHELL_LIBRARY, "rb") as handle:
        archive.file("labvm/lib.sh", handle.read())
    if files:
        archive.directory("labvm/files")
        made = set()
        for name, content in sorted(files.items()):
            name = name.strip("/")
            if not name or ".." in name.split("/"):
                raise ValueError(f"file name {name!r} must be a relative path inside /run/labvm/files")
            parts = name.split("/")
            for depth in range(1, len(parts)):
                directory = "labvm/files/" + "/".join(parts[:depth])
                if directory not in made:
                    made.add(directory)
                    archive.directory(directory)
            data = content.encode() if isinstance(content, str) else bytes(content)
            mode = 0o755 if data.startswith(b"#!") else 0o644
            archive.file("labvm/files/" + name, data, mode)
    return archive.finish()


def boot_image(base_path, run_data, directory):
    """Writes base archive + run archive into one initrd file in directory; returns its path."""
    path = os.path.join(directory, "initrd.img")
    with open(path, "wb") as out, open(base_path, "rb") as base:
        shutil.copyfileobj(base, out)
        out.write(run_data)
    return path

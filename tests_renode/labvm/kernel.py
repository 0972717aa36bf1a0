"""The lab VM's Linux kernel: Debian's linux-image-6.1.0-<abi>-amd64 package.

The package is fetched with `apt-get download` (no installation, the host's
/boot is never touched), unpacked once into build/labvm/kernel-<release>/ and
indexed with busybox's depmod, so that modules.dep and modules.alias exist for
the whole module tree. An initramfs then takes just the modules it needs and
their dependencies (`module_closure`).

Booting: the package's vmlinuz is an xz-compressed bzImage, and decompressing
it under QEMU's TCG takes about 4 s. The kernel is also built with PVH entry
(CONFIG_PVH), so its uncompressed ELF image boots directly with `-kernel
vmlinux`; `Kernel.vmlinux()` unpacks that once (about a second, 66 MB) and
the VM boots it, in about 3 s instead of 7.

Which kernel: the newest `linux-image-6.1.0-<abi>-amd64` apt-cache knows,
looked up at most once a day; a kernel already unpacked is used when apt
cannot be asked or the download fails. DCOS_LABVM_KERNEL=<release> (e.g.
6.1.0-56-amd64) pins one.
"""

import fcntl
import glob
import lzma
import os
import re
import shutil
import struct
import subprocess
import time

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_CACHE = os.path.join(REPOSITORY, "build", "labvm")

PACKAGE_PATTERN = re.compile(r"^linux-image-(6\.1\.0-(\d+)-amd64)$")
BUSYBOX = "/bin/busybox"  # Debian's busybox-static
# Look apt-cache up again after this long; a fresh lookup is about a second.
LOOKUP_INTERVAL = 24 * 3600
COMMAND_TIMEOUT = 600
KEEP_KERNELS = 2


class LabVMSetupError(RuntimeError):
    """The kernel or the initramfs could not be prepared."""


def _run(argv, what, cwd=None, timeout=COMMAND_TIMEOUT):
    try:
        result = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    except FileNotFoundError:
        raise LabVMSetupError(f"{what}: {argv[0]} is not installed (run mk/install-deps.sh)") from None
    except subprocess.TimeoutExpired:
        raise LabVMSetupError(f"{what}: {' '.join(argv)} did not finish in {timeout} s") from None
    if result.returncode != 0:
        raise LabVMSetupError(f"{what}: {' '.join(argv)} failed with status {result.returncode}:\n"
                              f"{result.stdout}{result.stderr}")
    return result.stdout


class CacheLock:
    """An exclusive lock on the cache folder: parallel test runs prepare it once."""

    def __init__(self, cache_dir):
        os.makedirs(cache_dir, exist_ok=True)
        self.path = os.path.join(cache_dir, ".lock")
        self._handle = None

    def __enter__(self):
        self._handle = open(self.path, "w")
        deadline = time.monotonic() + COMMAND_TIMEOUT
        while True:
            try:
                fcntl.flock(self._handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return self
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise LabVMSetupError(f"{self.path} stayed locked for {COMMAND_TIMEOUT} s") from None
                time.sleep(0.2)

    def __exit__(self, *exc):
        fcntl.flock(self._handle, fcntl.LOCK_UN)
        self._handle.close()


def newest_available_release():
    """The newest linux-image-6.1.0-<abi>-amd64 in apt's package lists, e.g. '6.1.0-56-amd64'."""
    names = _run(["apt-cache", "pkgnames", "linux-image-6.1.0-"], "listing Debian's kernel packages")
    best = None
    for name in names.split():
        match = PACKAGE_PATTERN.match(name)
        if match and (best is None or int(match.group(2)) > best[0]):
            best = (int(match.group(2)), match.group(1))
    if best is None:
        raise LabVMSetupError("apt-cache knows no linux-image-6.1.0-*-amd64 package; run 'apt-get update'")
    return best[1]


def _unpacked_releases(cache_dir):
    """Releases already unpacked in the cache, newest first."""
    found = []
    for directory in glob.glob(os.path.join(cache_dir, "kernel-6.1.0-*-amd64")):
        release = os.path.basename(directory)[len("kernel-"):]
        if os.path.exists(os.path.join(directory, ".complete")):
            found.append((int(release.split("-")[1]), release))
    return [release for _, release in sorted(found, reverse=True)]


class Kernel:
    """An unpacked kernel package: vmlinuz and the whole module tree."""

    def __init__(self, directory, release):
        self.directory = directory
        self.release = release
        self.vmlinuz = os.path.join(directory, "boot", f"vmlinuz-{release}")
        self.modules_dir = os.path.join(directory, "lib", "modules", release)
        self._dep = None
        self._alias = None

    def __repr__(self):
        return f"Kernel({self.release!r} in {self.directory})"

    def vmlinux(self):
        """Path of the uncompressed ELF kernel with a PVH entry, unpacked from vmlinuz on first use;
        None if this kernel has no PVH entry (then boot vmlinuz)."""
        path = os.path.join(self.directory, "vmlinux")
        if os.path.exists(path):
            return path
        with CacheLock(os.path.dirname(self.directory)):
            if os.path.exists(path):
                return path
            image = extract_vmlinux(self.vmlinuz)
            if image is None or not has_pvh_entry(image):
                return None
            with open(path + ".new", "wb") as handle:
                handle.write(image)
            os.replace(path + ".new", path)
        return path

    @property
    def package_version(self):
        path = os.path.join(self.directory, "package-version")
        try:
            with open(path, encoding="utf-8") as handle:
                return handle.read().strip()
        except FileNotFoundError:
            return "?"

    def _dependencies(self):
        """modules.dep as {module name: (path, [dependency paths])}; names use '_'."""
        if self._dep is None:
            self._dep = {}
            with open(os.path.join(self.modules_dir, "modules.dep"), encoding="utf-8") as handle:
                for line in handle:
                    if ":" not in line:
                        continue
                    path, deps = line.split(":", 1)
                    self._dep[module_name(path)] = (path.strip(), deps.split())
        return self._dep

    def _aliases(self):
        if self._alias is None:
            self._alias = {}
            with open(os.path.join(self.modules_dir, "modules.alias"), encoding="utf-8") as handle:
                for line in handle:
                    parts = line.split()
                    if len(parts) == 3 and parts[0] == "alias":
                        self._alias.setdefault(parts[1], parts[2])
        return self._alias

    def builtin(self, name):
        """True when the module is compiled into the kernel (no file to load)."""
        path = os.path.join(self.modules_dir, "modules.builtin")
        with open(path, encoding="utf-8") as handle:
            return any(module_name(line) == module_name(name) for line in handle if line.strip())

    def module_closure(self, names):
        """Paths (relative to the module folder) of the named modules and everything they need,
        dependencies first. Names may be aliases (e.g. 'can-proto-6'); built-in modules are skipped."""
        dep = self._dependencies()
        ordered = []
        seen = set()

        def add(path):
            if path in seen:
                return
            seen.add(path)
            for needed in dep.get(module_name(path), (path, []))[1]:
                add(needed)
            ordered.append(path)

        for name in names:
            key = module_name(name)
            if key not in dep:
                key = module_name(self._aliases().get(name, name))
            if key in dep:
                add(dep[key][0])
            elif not self.builtin(name):
                raise LabVMSetupError(f"kernel {self.release} has no module '{name}'")
        return ordered


def extract_vmlinux(vmlinuz):
    """The ELF image inside an xz-compressed bzImage, or None if it is not one."""
    with open(vmlinuz, "rb") as handle:
        image = handle.read()
    if len(image) < 0x250 or image[0x202:0x206] != b"HdrS":
        return None
    setup_sectors = image[0x1F1] or 4
    payload_offset, payload_length = struct.unpack_from("<II", image, 0x248)
    start = (setup_sectors + 1) * 512 + payload_offset
    payload = image[start:start + payload_length]
    if not payload.startswith(b"\xfd7zXZ\x00"):
        return None
    try:
        elf = lzma.LZMADecompressor(format=lzma.FORMAT_XZ).decompress(payload)
    except lzma.LZMAError:
        return None
    return elf if elf.startswith(b"\x7fELF\x02") else None


def has_pvh_entry(elf):
    """True if a 64-bit ELF kernel carries the Xen PVH entry note (XEN_ELFNOTE_PHYS32_ENTRY, 18)."""
    program_headers, = struct.unpack_from("<Q", elf, 0x20)
    entry_size, count = struct.unpack_from("<HH", elf, 0x36)
    for index in range(count):
        header = program_headers + index * entry_size
        kind, = struct.unpack_from("<I", elf, header)
        if kind != 4:  # PT_NOTE
            continue
        offset, = struct.unpack_from("<Q", elf, header + 0x08)
        size, = struct.unpack_from("<Q", elf, header + 0x20)
        position = offset
        while position + 12 <= offset + size:
            name_size, desc_size, note_type = struct.unpack_from("<III", elf, position)
            name = elf[position + 12:position + 12 + name_size].rstrip(b"\0")
            if name == b"Xen" and note_type == 18:
                return True
            position += 12 + (name_size + 3) // 4 * 4 + (desc_size + 3) // 4 * 4
    return False


def module_name(path):
    """'kernel/net/can/can-raw.ko' or 'can-raw' -> 'can_raw'."""
    base = os.path.basename(path.strip())
    for suffix in (".ko", ".ko.xz", ".ko.zst"):
        if base.endswith(suffix):
            base = base[: -len(suffix)]
    return base.replace("-", "_")


def _pinned_release():
    release = os.environ.get("DCOS_LABVM_KERNEL", "").strip()
    if release and not re.match(r"^6\.1\.0-\d+-amd64$", release):
        raise LabVMSetupError(f"DCOS_LABVM_KERNEL={release!r} is not a release like 6.1.0-56-amd64")
    return release or None


def _wanted_release(cache_dir, log):
    """The release to use, asking apt-cache at most once per LOOKUP_INTERVAL."""
    pinned = _pinned_release()
    if pinned:
        return pinned
    stamp = os.path.join(cache_dir, "newest-kernel")
    unpacked = _unpacked_releases(cache_dir)
    try:
        fresh = time.time() - os.path.getmtime(stamp) < LOOKUP_INTERVAL
        with open(stamp, encoding="utf-8") as handle:
            remembered = handle.read().strip()
    except OSError:
        fresh, remembered = False, ""
    if fresh and remembered:
        return remembered
    try:
        release = newest_available_release()
    except LabVMSetupError as error:
        if unpacked:
            log(f"labvm: cannot ask apt for the newest kernel ({error}); using {unpacked[0]}")
            return unpacked[0]
        raise
    with open(stamp + ".new", "w", encoding="utf-8") as handle:
        handle.write(release + "\n")
    os.replace(stamp + ".new", stamp)
    return release


def _download_and_unpack(cache_dir, release, log):
    directory = os.path.join(cache_dir, f"kernel-{release}")
    package = f"linux-image-{release}"
    download_dir = os.path.join(cache_dir, "download")
    shutil.rmtree(download_dir, ignore_errors=True)
    os.makedirs(download_dir)
    log(f"labvm: downloading {package} (about 70 MB) with apt-get download")
    # apt's sandbox user cannot write into root's build folder; -o lets apt
    # fetch as the calling user without the warning about it.
    _run(["apt-get", "download", "-q", "-o", "APT::Sandbox::User=root", package], f"downloading {package}",
         cwd=download_dir)
    debs = glob.glob(os.path.join(download_dir, f"{package}_*.deb"))
    if len(debs) != 1:
        raise LabVMSetupError(f"apt-get download {package} left {debs or 'no .deb'} in {download_dir}")
    version = os.path.basename(debs[0]).split("_")[1]
    staging = directory + ".partial"
    shutil.rmtree(staging, ignore_errors=True)
    log(f"labvm: unpacking {os.path.basename(debs[0])} into {directory}")
    _run(["dpkg-deb", "-x", debs[0], staging], f"unpacking {debs[0]}")
    kernel = Kernel(staging, release)
    if not os.path.exists(kernel.vmlinuz) or not os.path.isdir(kernel.modules_dir):
        raise LabVMSetupError(f"{debs[0]} holds no boot/vmlinuz-{release} or lib/modules/{release}")
    # The package ships no modules.dep (its postinst runs depmod); busybox's
    # depmod writes modules.dep and modules.alias for the unpacked tree.
    _run([BUSYBOX, "depmod", "-b", staging, release], f"indexing the modules of {release}")
    with open(os.path.join(staging, "package-version"), "w", encoding="utf-8") as handle:
        handle.write(version + "\n")
    open(os.path.join(staging, ".complete"), "w").close()
    shutil.rmtree(directory, ignore_errors=True)
    os.rename(staging, directory)
    shutil.rmtree(download_dir, ignore_errors=True)
    return directory


def _prune(cache_dir, keep_release):
    for release in _unpacked_releases(cache_dir)[KEEP_KERNELS:]:
        if release != keep_release:
            shutil.rmtree(os.path.join(cache_dir, f"kernel-{release}"), ignore_errors=True)


def obtain_kernel(cache_dir=DEFAULT_CACHE, log=print):
    """The newest Debian 6.1 amd64 kernel, downloaded and unpacked into cache_dir if needed."""
    os.makedirs(cache_dir, exist_ok=True)
    with CacheLock(cache_dir):
        release = _wanted_release(cache_dir, log)
        directory = os.path.join(cache_dir, f"kernel-{release}")
        if not os.path.exists(os.path.join(directory, ".complete")):
            try:
                _download_and_unpack(cache_dir, release, log)
            except LabVMSetupError as error:
                unpacked = _unpacked_releases(cache_dir)
                if not unpacked or _pinned_release():
                    raise
                log(f"labvm: {error}\nlabvm: using the kernel already unpacked, {unpacked[0]}")
                release = unpacked[0]
                directory = os.path.join(cache_dir, f"kernel-{release}")
        _prune(cache_dir, release)
        return Kernel(directory, release)

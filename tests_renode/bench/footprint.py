#!/usr/bin/python3
"""Reports each kernel configuration's image footprint by component: what `make bench` calls.

For every image a footprint budget names (tests_renode/bench/budgets.toml:
the full production image build/486/dcos486.elf and the minimal one
build/486/dcos486-minimal.elf), reads its linker map (build/bench/<image>.map,
linked by mk/bench.mk from the same objects and linker script as the
image), adds up every input section by the source file its object came
from, and prints code (.text), read-only data (.rodata, .multiboot),
data (.data, .init_array) and bss per component:

  dcos/<agent>     the kernel's agents, firmware/dcos/src/<agent>/
  dcos/shared      firmware/dcos/src/*.cpp (recovery, stack arena, message buffers, calendar)
  dcos/commands    the kernel's console commands (firmware/dcos/src/**/*Commands.cpp)
  boot, arch_x86, bsp_486, runtime (the freestanding libc-ish support), shell
  drivers/<name>, fieldbus/<name>
  selfcheck        the minimal image's built-in self-check application
  build revision   the generated revision stamp
  alignment        padding that no input section follows (the padding before
                   an input section counts for its object: see parse_map)

A map rather than the objects' own sizes: the map holds only what was
linked, each inline function or template instance once. The "kernel" of a
footprint budget is every object under the budget's `kernel` folders
(tests_renode/bench/budgets.toml); its code is checked against
`text_budget`. A budget marked `measured = false` is reported as not
measured yet; a measured one whose image or map is missing is an error.
Ends with one line per image comparing the kernels. Writes
build/bench/footprint.json.

The sums are checked against the image's own section sizes (`size -A`), so a
stale or misread map is an error rather than a wrong report.
"""

import argparse
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import budgets as budget_file  # noqa: E402

REPOSITORY = budget_file.REPOSITORY

# Output section -> the column it is reported in. The debug sections are
# not loaded and are left out.
SECTION_KIND = {".text": "text", ".multiboot": "rodata", ".rodata": "rodata", ".init_array": "data",
                ".data": "data", ".bss": "bss"}
KINDS = ("text", "rodata", "data", "bss")

_OUTPUT_SECTION = re.compile(r"^(\.[\w.]+)(?:\s+0x[0-9a-f]+\s+0x[0-9a-f]+)?\s*$")
_INPUT_SECTION = re.compile(r"^ (\S+)\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)(?:\s+(\S.*?))?\s*$")
_INPUT_NAME_ONLY = re.compile(r"^ (\S+)$")
_INPUT_CONTINUED = re.compile(r"^\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)(?:\s+(\S.*?))?\s*$")


class FootprintError(Exception):
    pass


def parse_map(text):
    """[(output section, input section, size, object file or None)] of a GNU ld map.

    An input section's line names the section, its address, its size and
    the object; a long section name stands alone on its line and the rest
    follows on the next. "*fill*" lines are padding: the linker puts it
    before an input section to give that section the alignment its object
    asks for (16-byte function starts at -O2, each function a section of
    its own with -ffunction-sections), so the padding counts for the object
    of the input section that follows it, and only padding that nothing
    follows in its output section is left without an object. Symbol lines
    (address and name only) and the linker script's own lines are skipped.

    Merged string sections (.rodata.str1.1 and the like) are listed once per
    object at overlapping addresses, each with the size it had before the
    strings were merged, so each entry is clipped to the bytes no earlier
    entry covers: a string shared by several objects counts once, for the
    first of them, and the sums equal the image's sections.
    """
    marker = text.find("Linker script and memory map")
    if marker < 0:
        raise FootprintError("not a GNU ld map: no 'Linker script and memory map'")
    entries = []
    output = None
    pending = None
    for line in text[marker:].splitlines():
        match = _OUTPUT_SECTION.match(line)
        if match:
            output, pending = match.group(1), None
            continue
        if line.startswith("/DISCARD/"):
            output, pending = None, None
            continue
        match = _INPUT_SECTION.match(line)
        if match:
            section, address, size, origin = match.groups()
            pending = None
        else:
            match = _INPUT_NAME_ONLY.match(line)
            if match and not match.group(1).startswith("*("):
                pending = match.group(1)
                continue
            match = _INPUT_CONTINUED.match(line)
            if not (match and pending):
                pending = None
                continue
            section, (address, size, origin) = pending, match.groups()
            pending = None
        if output is None or output not in SECTION_KIND:
            continue
        if section == "*fill*":
            origin = None
        entries.append((output, section, int(address, 16), int(size, 16), origin))
    clipped = []
    for name in dict.fromkeys(entry[0] for entry in entries):
        covered = 0
        in_section = []
        # sorted() is stable: at one address the map's order decides.
        for output, section, address, size, origin in sorted((entry for entry in entries if entry[0] == name),
                                                             key=lambda entry: entry[2]):
            start = max(address, covered)
            covered = max(covered, address + size)
            in_section.append((output, section, max(0, address + size - start), origin))
        following = None
        for index in reversed(range(len(in_section))):
            output, section, size, origin = in_section[index]
            if section == "*fill*":
                in_section[index] = (output, section, size, following)
            else:
                following = origin
        clipped += in_section
    return clipped


def source_of(origin, build_directory):
    """The repository path of the source an object was compiled from ('build/fw486/x/y.cpp.o' -> 'x/y.cpp')."""
    if origin is None:
        return None
    path = os.path.relpath(os.path.normpath(origin), build_directory) if os.path.isabs(origin) else origin
    prefix = build_directory.rstrip("/") + "/"
    if path.startswith(prefix):
        path = path[len(prefix):]
    return path[:-2] if path.endswith(".o") else path


def component_of(source):
    """The component a source file belongs to (see the module's description)."""
    if source is None:
        return "alignment"
    parts = source.split("/")
    if parts[0] == "generated":
        return "build revision"
    if parts[:2] == ["firmware", "dcos"]:
        if parts[-1].endswith("Commands.cpp"):
            return "dcos/commands"
        if len(parts) >= 5 and parts[2] == "src":
            return f"dcos/{parts[3]}"
        return "dcos/shared"
    if parts[0] == "firmware" and len(parts) > 1:
        return parts[1]
    if parts[0] in ("drivers", "fieldbus") and len(parts) > 1:
        return f"{parts[0]}/{parts[1]}"
    return parts[0]


def footprint(entries, build_directory, kernel_folders):
    """Sums the map's entries by component and the kernel's total.

    Returns {"components": {name: {kind: bytes}}, "kernel": {kind: bytes},
    "total": {kind: bytes}, "shell_and_commands": {kind: bytes}}.
    """
    zero = dict.fromkeys(KINDS, 0)
    components, kernel, total, commands = {}, dict(zero), dict(zero), dict(zero)
    for output, _, size, origin in entries:
        kind = SECTION_KIND[output]
        source = source_of(origin, build_directory)
        component = component_of(source)
        components.setdefault(component, dict(zero))[kind] += size
        total[kind] += size
        if source is not None and any(source.startswith(folder) for folder in kernel_folders):
            kernel[kind] += size
        if component == "shell" or (source is not None and source.endswith("Commands.cpp")):
            commands[kind] += size
    return {"components": dict(sorted(components.items())), "kernel": kernel, "total": total,
            "shell_and_commands": commands}


def image_sections(image):
    """{kind: bytes} of the image by `size -A`, for the cross-check."""
    output = subprocess.run(["size", "-A", image], check=True, capture_output=True, text=True).stdout
    sizes = dict.fromkeys(KINDS, 0)
    for line in output.splitlines():
        fields = line.split()
        if len(fields) >= 2 and fields[0] in SECTION_KIND and fields[1].isdigit():
            sizes[SECTION_KIND[fields[0]]] += int(fields[1])
    return sizes


def print_footprint(name, image, report, budget):
    kib = 1024
    print(f"Footprint of {image} ({name}): bytes by component, from its linker map "
          "(text = code; rodata = read-only data; the kernel is "
          f"{', '.join(budget['kernel'])})")
    rows = [(component, *(str(sizes[kind]) for kind in KINDS))
            for component, sizes in report["components"].items()]
    rows.append(("kernel", *(str(report["kernel"][kind]) for kind in KINDS)))
    rows.append(("shell and console commands", *(str(report["shell_and_commands"][kind]) for kind in KINDS)))
    rows.append(("image", *(str(report["total"][kind]) for kind in KINDS)))
    for line in budget_file._table(("component", "text", "rodata", "data", "bss"), rows,
                                   ("<", ">", ">", ">", ">")):
        print(line)
    text = report["kernel"]["text"]
    verdict = "OVER" if text > budget["text_budget"] else "within"
    print(f"  kernel code {text} bytes ({text / kib:.1f} KiB) against its budget of {budget['text_budget']} "
          f"({budget['text_budget'] / kib:g} KiB): {verdict}"
          + (f"; the issue's figure: {budget['now'] / kib:g} KiB" if "now" in budget else ""))


def map_of(image, maps):
    """The linker map of an image: build/486/dcos486-minimal.elf -> <maps>/dcos486-minimal.map."""
    return os.path.join(maps, os.path.splitext(os.path.basename(image))[0] + ".map")


def print_comparison(images, budgets):
    """One line per image: its kernel's sizes and its budget, side by side."""
    print("Kernel footprint by configuration (bytes of the objects under each budget's kernel folders)")
    rows = []
    for name, image in images.items():
        kernel, budget = image["kernel"], budgets["footprint"][name]["text_budget"]
        rows.append((name, image["image"], *(str(kernel[kind]) for kind in KINDS), str(budget),
                     "OVER" if kernel["text"] > budget else "within"))
    for line in budget_file._table(("configuration", "image", "text", "rodata", "data", "bss", "text budget",
                                    "verdict"), rows, ("<", "<", ">", ">", ">", ">", ">", "<")):
        print(line)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--budgets", default=budget_file.DEFAULT_BUDGETS)
    parser.add_argument("--maps", default=os.path.join(REPOSITORY, "build", "bench"),
                        help="the folder of the images' linker maps, <image name>.map")
    parser.add_argument("--build-directory", default="build/fw486",
                        help="where the image's objects were compiled, as the map names them")
    parser.add_argument("--output", default=os.path.join(REPOSITORY, "build", "bench", "footprint.json"))
    parser.add_argument("--strict", action="store_true", help="exit 1 when a kernel is over its budget")
    arguments = parser.parse_args()

    budgets = budget_file.load_budgets_for_command(arguments.budgets)
    if budgets is None:
        return 2
    maps = {name: map_of(budget["image"], arguments.maps) for name, budget in budgets["footprint"].items()
            if budget["measured"]}
    images = {}
    for name, budget in budgets["footprint"].items():
        if name not in maps:
            continue
        image = os.path.join(REPOSITORY, budget["image"])
        try:
            with open(maps[name], encoding="utf-8") as handle:
                report = footprint(parse_map(handle.read()), arguments.build_directory, budget["kernel"])
            linked = image_sections(image)
        except (OSError, FootprintError, subprocess.CalledProcessError) as error:
            print(f"make bench: footprint of {budget['image']}: {error}", file=sys.stderr)
            return 1
        if linked != report["total"]:
            print(f"make bench: the map {maps[name]} does not describe {budget['image']}: sections "
                  f"{report['total']} by the map, {linked} by size -A", file=sys.stderr)
            return 1
        images[name] = dict(report, image=budget["image"], map=os.path.relpath(maps[name], REPOSITORY))
        print_footprint(name, budget["image"], report, budget)
        print()

    if images:
        print_comparison(images, budgets)
    rows = budget_file.check_footprint(budgets, {name: image["kernel"]["text"] for name, image in images.items()})
    for row in rows:
        if row["verdict"] == budget_file.NOT_MEASURED_YET:
            print(f"  {row['name']}: not built yet: {row['note']} (budget {row['text_budget']} bytes)")
    os.makedirs(os.path.dirname(os.path.abspath(arguments.output)), exist_ok=True)
    with open(arguments.output, "w", encoding="utf-8") as handle:
        json.dump({"images": images, "budgets": rows}, handle, indent=2)
        handle.write("\n")
    print(f"wrote {arguments.output}")
    return 1 if arguments.strict and budget_file.offenders(rows) else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Checks that an ELF image holds no instruction its board's processor lacks.

The 486 board's firmware is compiled with -march=i486, but one stray object
(a library built for i686, an inline asm, a multi-byte NOP from the
assembler) is enough to fault on a real 486DX. This tool disassembles every
executable section with objdump and rejects:

- P6 and later additions: CMOVcc, FCMOVcc, FCOMI/FUCOMI(P), long NOP (0F 1F),
  UD2, SYSENTER/SYSEXIT, SYSCALL/SYSRET, RDPMC;
- Pentium additions: RDTSC(P), RDMSR/WRMSR, CMPXCHG8B, CPUID (absent on the
  486DX-33 of the seed's controller node), RSM;
- every MMX, SSE and AVX instruction, recognised by its mnemonic or by an
  MMX/XMM/YMM register operand.

With --cpu pentium (the dual-Pentium board's images) the Pentium additions
are allowed and everything else above is still rejected.

It prints each offending instruction with its address and function, and
exits 1 if there is any, 2 if the image cannot be read, 0 if it is clean.
"""

import argparse
import re
import subprocess
import sys

FORBIDDEN_MNEMONICS = re.compile(
    r"^(cmov\w+|fcmov\w+|fu?comip?|ud2|ud1|sysenter|sysexit|syscall|sysret\w*|rdpmc|rdtscp?|rdmsr|wrmsr"
    r"|cmpxchg8b|cmpxchg16b|cpuid|rsm|emms|femms|fxsave\w*|fxrstor\w*|ldmxcsr|stmxcsr|[slm]fence|clflush\w*"
    r"|prefetch\w*|movnti|xsave\w*|xrstor\w*|popcnt|lzcnt|tzcnt|movbe|crc32\w*|v\w+)$"
)
# What the Pentium (P54C) adds to the i486: allowed with --cpu pentium.
PENTIUM_ADDITIONS = re.compile(r"^(rdtsc|rdmsr|wrmsr|cmpxchg8b|cpuid|rsm)$")
# Long NOPs (0F 1F /0) appear as "nopl"/"nopw" with a memory operand.
LONG_NOP = re.compile(r"^nop[lwq]?$")
SIMD_REGISTER = re.compile(r"%(x|y|z)mm\d+|%mm\d")

INSTRUCTION = re.compile(r"^\s*([0-9a-f]+):\s+(?:[0-9a-f]{2} )+\s*(\S.*)$")
FUNCTION = re.compile(r"^[0-9a-f]+ <(.+)>:$")


def violations(path, objdump="objdump", cpu="i486"):
    """Yields (address, function, instruction text) for each instruction @p cpu lacks (i486 or pentium)."""
    try:
        listing = subprocess.run(
            [objdump, "-d", "-w", path],
            check=True, capture_output=True, text=True,
        ).stdout
    except FileNotFoundError:
        raise SystemExit(f"error: {objdump} not found (install binutils)") from None
    except subprocess.CalledProcessError as error:
        print(f"error: cannot disassemble {path}: {error.stderr.strip()}", file=sys.stderr)
        sys.exit(2)
    function = "?"
    for line in listing.splitlines():
        named = FUNCTION.match(line)
        if named:
            function = named.group(1)
            continue
        instruction = INSTRUCTION.match(line)
        if not instruction:
            continue
        address, text = instruction.groups()
        mnemonic, _, operands = text.partition(" ")
        # Prefixes such as "lock" or "rep" come first; judge the instruction.
        while mnemonic in ("lock", "rep", "repz", "repnz", "repe", "repne", "data16", "addr16", "cs", "ds", "es",
                           "ss", "fs", "gs", "notrack", "bnd") and operands:
            mnemonic, _, operands = operands.strip().partition(" ")
        if mnemonic == "(bad)":
            yield address, function, "undecodable bytes in an executable section"
        elif FORBIDDEN_MNEMONICS.match(mnemonic) and not (cpu == "pentium" and PENTIUM_ADDITIONS.match(mnemonic)):
            yield address, function, text.strip()
        elif LONG_NOP.match(mnemonic) and operands.strip():
            yield address, function, text.strip() + " (long NOP, 0F 1F)"
        elif SIMD_REGISTER.search(operands):
            yield address, function, text.strip() + " (MMX/SSE register)"


def main():
    parser = argparse.ArgumentParser(description="Reject instructions the board's processor does not have.")
    parser.add_argument("images", nargs="+", help="ELF images or object files")
    parser.add_argument("--objdump", default="objdump")
    parser.add_argument("--cpu", choices=("i486", "pentium"), default="i486",
                        help="the processor the images run on (default i486)")
    arguments = parser.parse_args()
    failed = False
    for image in arguments.images:
        found = list(violations(image, arguments.objdump, arguments.cpu))
        for address, function, text in found:
            print(f"{image}: 0x{address} in {function}: {text}")
        if found:
            print(f"{image}: {len(found)} instruction(s) an {arguments.cpu} does not have", file=sys.stderr)
            failed = True
        else:
            print(f"{image}: {arguments.cpu} clean")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()

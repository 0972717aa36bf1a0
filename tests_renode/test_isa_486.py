"""The i486 instruction check: the 486 images pass it, and it catches what it must."""

import os
import subprocess
import sys

import pytest

from dcoslab.board import REPOSITORY, load_board

CHECKER = os.path.join(REPOSITORY, "host_tools", "isa_check", "check_i486.py")


def run_checker(*paths):
    return subprocess.run([sys.executable, CHECKER, *paths], capture_output=True, text=True, timeout=120)


def assemble(tmp_path, name, source):
    """Assembles a 32-bit object file from AT&T assembly."""
    source_path = tmp_path / f"{name}.s"
    object_path = tmp_path / f"{name}.o"
    source_path.write_text(".text\n.globl crafted\ncrafted:\n" + source + "\n    ret\n")
    subprocess.run(["as", "--32", str(source_path), "-o", str(object_path)], check=True, timeout=60)
    return str(object_path)


@pytest.mark.parametrize("kind", ["production", "test", "minimal", "minimal-test"])
def test_486_images_hold_only_i486_instructions(kind):
    board = load_board("isa486")
    result = run_checker(board.image(kind))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "i486 clean" in result.stdout


def test_the_stage_loader_holds_only_i486_instructions():
    # The card's stage loader (docs/boot.md) runs on the same processor
    # before any kernel, with mbedTLS compiled in.
    result = run_checker(os.path.join(REPOSITORY, "build", "486", "stage-loader.elf"))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "i486 clean" in result.stdout


def test_clean_object_passes(tmp_path):
    obj = assemble(tmp_path, "clean", "    movl %eax, %ebx\n    bswap %ecx\n    cmpxchg %edx, (%esi)\n    xadd %eax, (%edi)\n    invlpg (%eax)\n    nop\n    fsqrt")
    result = run_checker(obj)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize(
    "instruction, reported",
    [
        ("cmovne %eax, %ebx", "cmovne"),
        ("fcmovb %st(1), %st", "fcmovb"),
        ("fcomi %st(1), %st", "fcomi"),
        ("rdtsc", "rdtsc"),
        ("rdpmc", "rdpmc"),
        ("sysenter", "sysenter"),
        ("cpuid", "cpuid"),
        ("cmpxchg8b (%esi)", "cmpxchg8b"),
        ("ud2", "ud2"),
        ("nopl 0x0(%eax)", "long NOP"),
        ("emms", "emms"),
        ("movq %mm0, %mm1", "MMX/SSE register"),
        ("movd %eax, %mm0", "MMX/SSE register"),
        ("addps %xmm1, %xmm0", "MMX/SSE register"),
        ("movaps (%eax), %xmm0", "MMX/SSE register"),
        ("ldmxcsr (%eax)", "ldmxcsr"),
        ("lfence", "lfence"),
    ],
)
def test_post_486_instruction_is_rejected(tmp_path, instruction, reported):
    obj = assemble(tmp_path, "crafted", f"    movl %eax, %ebx\n    {instruction}")
    result = run_checker(obj)
    assert result.returncode == 1, result.stdout + result.stderr
    assert "in crafted" in result.stdout
    assert reported in result.stdout


def test_unreadable_image_is_an_error_not_a_pass(tmp_path):
    bogus = tmp_path / "not-an-elf"
    bogus.write_text("hello")
    result = run_checker(str(bogus))
    assert result.returncode == 2
    assert "cannot disassemble" in result.stderr


@pytest.mark.parametrize("kind", ["production", "test", "node3", "node3-test"])
def test_the_dual_pentium_images_hold_only_pentium_instructions(kind):
    """The p5smp images may use what the Pentium adds (CPUID for its APIC), nothing later.

    Node 2's images carry node 3's as data, which a disassembly of their
    code does not read: node 3's images are checked as they are linked."""
    result = subprocess.run([sys.executable, CHECKER, "--cpu", "pentium", load_board("p5smp").image(kind)],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "pentium clean" in result.stdout


@pytest.mark.parametrize("instruction, allowed", [("cpuid", True), ("rdtsc", True), ("cmpxchg8b (%esi)", True),
                                                  ("wrmsr", True), ("cmovne %eax, %ebx", False),
                                                  ("rdtscp", False), ("nopl 0x0(%eax)", False),
                                                  ("movq %mm0, %mm1", False), ("sysenter", False)])
def test_the_pentium_check_allows_exactly_the_pentium_additions(tmp_path, instruction, allowed):
    obj = assemble(tmp_path, "crafted", f"    movl %eax, %ebx\n    {instruction}")
    pentium = subprocess.run([sys.executable, CHECKER, "--cpu", "pentium", obj], capture_output=True, text=True,
                             timeout=120)
    assert pentium.returncode == (0 if allowed else 1), pentium.stdout + pentium.stderr
    # The same instruction is never one the i486 check lets through.
    assert run_checker(obj).returncode == 1

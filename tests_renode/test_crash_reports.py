"""Crash reports name code, not only addresses.

The lab turns every EIP and back-trace address in a failed test's console
transcript into a function and a source line with addr2line on the image
that ran; `make run` does the same live (test_make_run.py).
"""

from dcoslab.emulator import EmulatorError
from dcoslab.symbolize import code_addresses, explain


def test_addresses_are_found_in_reports_and_back_traces():
    text = ("task t (0x00011003) terminated: fatal exception, vector 14 (#PF page fault) at EIP=0012f3a4\r\n"
            "EIP=00101000 CS=0008 EFLAGS=00000002 ESP=0024efcc\r\n"
            "back trace: 00101010 0012f3a4 00102020\r\n")
    assert code_addresses(text) == [0x12F3A4, 0x101000, 0x101010, 0x102020]


def test_no_image_or_no_address_gives_nothing():
    assert explain("EIP=00101000", None) == ""
    assert explain("no addresses here", "/nonexistent.elf") == ""


def test_a_failed_expectation_names_the_faulting_function(boot, isa486):
    emulator = boot(isa486, "test", icount=True)
    emulator.expect(r"dcos> ")
    emulator.send("test nullwrite\r")
    emulator.expect(r"TEST nullwrite: PASS")
    try:
        emulator.expect(r"this never appears", timeout=1)
    except EmulatorError as error:
        message = str(error)
    else:
        raise AssertionError("the expectation should have failed")
    assert "code addresses in the transcript" in message
    assert "nullWrite(unsigned int) at tests_renode/target/MemoryProtectionTest.cpp:" in message

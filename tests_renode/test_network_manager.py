"""The network interfaces manager on the emulated 486 board (seed 7.13).

The board is node 1. The on-target test builds its tables as the sender of
the seed's Fig. 7.15, with node 3 behind gateway node 2, through the
services; the console test does the same with the "net" command, as a
control engineer would, and checks its listing and its errors. The tables'
rules and resolution are tested on the host (AddressMapTest).
"""

from dcoslab.target import run_target_test

NETWORK_TARGET_TESTS = [
    "nettables",  # the services, resolution through a gateway, the super-user rule
]

PROMPT = r"dcos> "


def test_network_tables_on_target(boot, isa486):
    run_target_test(boot(isa486, "test", icount=True), "nettables")


def test_the_net_command_builds_and_lists_the_tables(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    assert emulator.command("net interface can 0 130.2.0.3/16 3").strip().endswith("interface 0")
    for line in ("net map 3 130.1.0.3", "net map 2 130.2.0.2", "net route 130.1.0.0/16 130.2.0.2",
                 "net neighbour 130.2.0.2 2"):
        output = emulator.command(line)
        assert "net:" not in output, f"{line}: {output}"
    assert "node 3: 130.1.0.3 via 130.2.0.2, interface 0, physical 2" in emulator.command("net resolve 3")
    assert "node 2: 130.2.0.2 via 130.2.0.2, interface 0, physical 2" in emulator.command("net resolve 2")
    listing = emulator.command("net")
    for expected in ("  0  can    0  130.2.0.3/16  physical 3", "  node 3  130.1.0.3", "  node 2  130.2.0.2",
                     "  130.2.0.2  physical 2", "  130.1.0.0/16  via 130.2.0.2"):
        assert expected in listing, listing


def test_the_net_command_reports_each_error(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    assert "net: invalid argument" in emulator.command("net map 3 224.0.0.1")
    assert "net: invalid argument" in emulator.command("net resolve 1")  # The board itself.
    assert "net: not found" in emulator.command("net resolve 77")
    assert "net: invalid argument" in emulator.command("net neighbour 131.0.0.9 9")  # On no local subnet.
    assert "net: invalid argument" in emulator.command("net interface can 0 130.2.0.3/16 200")
    assert "usage: net" in emulator.command("net route 130.1.0.0 130.2.0.2")  # No prefix length.
    assert "usage: net" in emulator.command("net map one 130.1.0.1")
    emulator.command("net map 3 130.1.0.3")
    assert "net: already exists" in emulator.command("net map 4 130.1.0.3")
    assert "net: node unreachable" in emulator.command("net resolve 3")

"""Turns the code addresses a controller reports into functions and lines.

A panic report, a task's termination report and a back trace name code by
address (EIP=0012f3a4). With the image that ran, binutils' addr2line turns
each into the function and the source line, which is what an engineer
reading a crash wants first. Used by the lab (failed tests print it after
the console transcript) and by `make run` (tests_renode/launch.py), which
prints it right below the report on the console.
"""

import re
import shutil
import subprocess

# "EIP=0012f3a4" in panic and termination reports; "back trace: 0012.. 0013.."
_EIP = re.compile(r"EIP=([0-9a-f]{8})")
_BACK_TRACE = re.compile(r"back trace:((?: [0-9a-f]{8})+)")
_ADDR2LINE_TIMEOUT = 20.0


def code_addresses(text):
    """The code addresses a console text reports, in order, each once."""
    found = []
    for line in text.splitlines():
        for match in _EIP.finditer(line):
            found.append(int(match.group(1), 16))
        trace = _BACK_TRACE.search(line)
        if trace:
            found.extend(int(word, 16) for word in trace.group(1).split())
    unique = []
    for address in found:
        if address not in unique:
            unique.append(address)
    return unique


def symbolize(image, addresses):
    """Maps each address to 'function at file:line' with addr2line.

    Addresses addr2line cannot place (not in the image's code) are left out.
    A missing addr2line or image yields an empty map rather than an error:
    a crash report must never fail for want of its decoration.
    """
    tool = shutil.which("addr2line")
    if not addresses or tool is None or image is None:
        return {}
    command = [tool, "-f", "-C", "-e", image] + [f"0x{address:08x}" for address in addresses]
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=_ADDR2LINE_TIMEOUT, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return {}
    lines = result.stdout.splitlines()
    names = {}
    for index, address in enumerate(addresses):
        if 2 * index + 1 >= len(lines):
            break
        function, place = lines[2 * index], lines[2 * index + 1]
        if function == "??" and place.startswith("??"):
            continue
        names[address] = f"{function} at {_shorten(place)}"
    return names


def _shorten(place):
    # addr2line prints absolute paths; the part from the repository's top
    # folders on is what a reader looks up.
    for top in ("/firmware/", "/drivers/", "/fieldbus/", "/tests_renode/", "/docs/"):
        position = place.find(top)
        if position >= 0:
            return place[position + 1:]
    return place


def explain(text, image):
    """A block of lines naming every code address in text, or ''."""
    addresses = code_addresses(text)
    names = symbolize(image, addresses)
    if not names:
        return ""
    return "\n".join(f"  {address:08x} is {names[address]}" for address in addresses if address in names) + "\n"

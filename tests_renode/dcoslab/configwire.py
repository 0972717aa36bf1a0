"""The configuration protocol read off the lab bus's log by an observer
written from docs/protocols/config.md alone, not from the firmware's or
dcos-config's code: every frame of message type 0x40 is put back together
by its ISO 15765-2 framing (single, first and consecutive frames; flow
controls passed over) and each whole message decoded by the page's tables.
A frame or message the page does not allow raises WireError, so a test
that reads the wire proves both ends keep to the page.
"""
import struct

CONFIGURATION = 0x40
BROADCAST = 255

STATUSES = {0: "Ok", 1: "Malformed", 2: "UnknownCommand", 3: "NoChallenge", 4: "StaleChallenge", 5: "BadMac",
            6: "LockedOut", 7: "NoKey", 8: "InvalidArgument", 9: "CardError", 10: "NotPermitted",
            11: "KernelRefused"}
COMMANDS = {0x01: "Identify", 0x02: "Challenge", 0x03: "GetConfiguration", 0x04: "ListObjects",
            0x05: "FindObject", 0x06: "ObjectInfo", 0x07: "NodeStatistics", 0x08: "Monitor", 0x10: "SetNodeId",
            0x11: "SetBitRate", 0x12: "Restart", 0x13: "SetConfiguration", 0x20: "ProbeSerial", 0x21: "Select",
            0x22: "Deselect", 0x23: "ActivateBitRate", 0x30: "CreateTask", 0x31: "StartTask", 0x32: "StopTask",
            0x33: "KillTask", 0x34: "CreateObject", 0x35: "DeleteObject", 0x36: "AddObjects"}
# The commands that never carry a MAC, those that always do, and the
# queries, which may (the page's "Messages" and "Objects and tasks").
QUERIES = {"GetConfiguration", "ListObjects", "FindObject", "ObjectInfo", "NodeStatistics", "Monitor"}
MAC = 16
NAME = 15


class WireError(AssertionError):
    pass


def _name(body, at):
    """An object's name at @p at: (name, the offset after it), or WireError."""
    if at >= len(body) or body[at] > NAME or at + 1 + body[at] > len(body):
        raise WireError(f"a name that does not fit at {at} of {body.hex()}")
    return body[at + 1:at + 1 + body[at]].decode("ascii"), at + 1 + body[at]


def _requests(code, body):
    """The fields of a request, or WireError."""
    name = COMMANDS.get(code)
    if name is None:
        raise WireError(f"request {code:#04x}")
    fields = {"command": name}
    fixed = {"Identify": 0, "Challenge": 0, "GetConfiguration": 0, "NodeStatistics": 0, "SetNodeId": 2 + MAC,
             "SetBitRate": 4 + MAC, "Restart": MAC, "ProbeSerial": 5, "Select": 4, "Deselect": 0,
             "ActivateBitRate": 2, "ListObjects": 3, "ObjectInfo": 4, "StartTask": 4 + MAC, "StopTask": 4 + MAC,
             "KillTask": 4 + MAC, "DeleteObject": 4 + MAC, "AddObjects": 3 + MAC}
    # The variable layouts: where their fields end (before an optional or
    # required MAC).
    if name == "FindObject":
        fields["type"] = body[0] if body else None
        fields["name"], end = _name(body, 1)
    elif name == "Monitor":
        if len(body) < 6:
            raise WireError(f"Monitor of {len(body)} bytes")
        fields["lease"], fields["period_ms"], fields["flags"], count = struct.unpack_from("<HHBB", body)
        if count > 8 or fields["flags"] & ~1:
            raise WireError(f"Monitor with {count} channels, flags {fields['flags']:#x}")
        end = 6 + 6 * count
        fields["channels"] = [struct.unpack_from("<IBB", body, 6 + 6 * i) for i in range(count)
                              if 6 + 6 * i + 6 <= len(body)]
    elif name == "SetConfiguration":
        if len(body) < 10:
            raise WireError(f"SetConfiguration of {len(body)} bytes")
        (fields["node_id"], fields["bit_rate"], fields["flags"], fields["lockout_seconds"],
         length) = struct.unpack_from("<HIBHB", body)
        fields["command_line"] = body[10:10 + length].decode("ascii")
        end = 10 + length + MAC
    elif name == "CreateTask":
        fields["entry"], at = _name(body, 0)
        fields["name"], at = _name(body, at)
        if at + 9 > len(body):
            raise WireError(f"CreateTask of {len(body)} bytes")
        fields["priority"], fields["stack_size"], fields["argument"] = struct.unpack_from("<BII", body, at)
        end = at + 9 + MAC
    elif name == "CreateObject":
        fields["type"] = body[0] if body else None
        fields["name"], at = _name(body, 1)
        if at + 9 > len(body):
            raise WireError(f"CreateObject of {len(body)} bytes")
        fields["visibility"], fields["p0"], fields["p1"] = struct.unpack_from("<BII", body, at)
        end = at + 9 + MAC
    else:
        end = fixed[name]
    allowed = (end, end + MAC) if name in QUERIES else (end,)
    if len(body) not in allowed:
        raise WireError(f"{name} of {len(body)} bytes after its code, not {allowed}")
    if name in QUERIES:
        fields["mac"] = len(body) == end + MAC
    if name == "SetNodeId":
        fields["node_id"] = struct.unpack_from("<H", body)[0]
    elif name == "SetBitRate":
        fields["bit_rate"] = struct.unpack_from("<I", body)[0]
    elif name == "ProbeSerial":
        fields["bits"], fields["value"] = struct.unpack_from("<BI", body)
        if fields["bits"] > 32:
            raise WireError(f"ProbeSerial of {fields['bits']} bits")
    elif name == "Select":
        fields["serial"] = struct.unpack_from("<I", body)[0]
    elif name == "ActivateBitRate":
        fields["delay_ms"] = struct.unpack_from("<H", body)[0]
    elif name == "ListObjects":
        fields["type"], fields["first"] = struct.unpack_from("<BH", body)
    elif name in ("ObjectInfo", "StartTask", "StopTask", "KillTask", "DeleteObject"):
        fields["id"] = struct.unpack_from("<I", body)[0]
    elif name == "AddObjects":
        fields["type"], fields["count"] = struct.unpack_from("<BH", body)
    return fields


def _text(body, at):
    if at >= len(body) or at + 1 + body[at] != len(body):
        raise WireError(f"a text that does not end the message ({body.hex()})")
    return body[at + 1:].decode("ascii")


def _reply(code, body):
    name = COMMANDS.get(code & 0x7F)
    if code == 0xFF:
        name = "Unreadable"
    elif name is None:
        raise WireError(f"reply code {code:#04x}")
    if not body or body[0] not in STATUSES:
        raise WireError(f"reply {code:#04x} without a known status ({body.hex()})")
    status, rest = STATUSES[body[0]], body[1:]
    fields = {"command": name, "status": status}
    if name == "ProbeSerial":
        if rest or status != "Ok":
            raise WireError(f"a probe's answer is [0xA0][0x00], not {body.hex()}")
        return fields
    if status == "LockedOut":
        if len(rest) != 2:
            raise WireError("LockedOut without its seconds")
        fields["seconds_left"] = struct.unpack("<H", rest)[0]
        return fields
    if status == "KernelRefused":
        if len(rest) != 1 or name == "Unreadable":
            raise WireError(f"KernelRefused without the kernel's status: {body.hex()}")
        fields["kernel_status"] = rest[0]
        return fields
    if status != "Ok" or name in ("Restart", "Unreadable", "StartTask", "StopTask", "KillTask", "DeleteObject",
                                  "AddObjects", "Monitor"):
        if rest:
            raise WireError(f"{name} {status} with {len(rest)} bytes more")
        return fields
    if name == "Identify":
        (fields["node"], fields["can_node"], fields["board"], fields["serial"], fields["protocol"], fields["flags"],
         fields["bit_rate"], fields["configured_node"]) = struct.unpack_from("<HBBIBBIH", rest)
        fields["version"] = _text(rest, 16)
    elif name == "Challenge":
        if len(rest) != 16:
            raise WireError(f"a challenge of {len(rest)} bytes")
        fields["challenge"] = rest
    elif name == "GetConfiguration":
        (fields["sequence"], fields["node"], fields["bit_rate"], fields["flags"],
         fields["lockout_seconds"]) = struct.unpack_from("<IHIBH", rest)
        fields["command_line"] = _text(rest, 13)
    elif name == "ListObjects":
        fields["next"], count = struct.unpack_from("<HB", rest)
        at, entries = 3, []
        for _ in range(count):
            if at + 8 > len(rest):
                raise WireError(f"ListObjects' reply cut short: {rest.hex()}")
            identifier, owner = struct.unpack_from("<II", rest, at)
            entry_name, at = _name(rest, at + 8)
            entries.append((identifier, owner, entry_name))
        if count > 8 or at != len(rest):
            raise WireError(f"ListObjects' reply of {count} entries and {len(rest) - at} bytes more")
        fields["entries"] = entries
    elif name in ("FindObject", "CreateTask", "CreateObject"):
        if len(rest) != 4:
            raise WireError(f"{name}'s reply of {len(rest)} bytes")
        fields["id"] = struct.unpack("<I", rest)[0]
    elif name == "ObjectInfo":
        fields["type"], fields["state"], fields["visibility"], fields["owner"] = struct.unpack_from("<BBBI", rest)
        fields["name"], at = _name(rest, 7)
        count = rest[at] if at < len(rest) else 99
        if count > 10 or at + 1 + 8 * count != len(rest):
            raise WireError(f"ObjectInfo's figures do not end the reply: {rest.hex()}")
        fields["values"] = list(struct.unpack_from(f"<{count}Q", rest, at + 1))
    elif name == "NodeStatistics":
        fields["uptime_ns"], fields["task_switches"], fields["stack_free"], count = struct.unpack_from("<QIIB", rest)
        if count > 8 or 17 + 5 * count != len(rest):
            raise WireError(f"NodeStatistics' tables do not end the reply: {rest.hex()}")
        fields["tables"] = [struct.unpack_from("<BHH", rest, 17 + 5 * i) for i in range(count)]
    elif name in ("SetNodeId", "SetBitRate", "SetConfiguration"):
        if len(rest) != 4:
            raise WireError(f"{name}'s reply of {len(rest)} bytes")
        fields["sequence"] = struct.unpack("<I", rest)[0]
    elif name == "Select":
        if len(rest) != 3:
            raise WireError(f"Select's reply of {len(rest)} bytes")
        fields["node"], fields["can_node"] = struct.unpack("<HB", rest)
    else:
        raise WireError(f"{name} has no reply")
    return fields


def read_wire(records, host=254):
    """Every configuration message on the bus, in order, as dicts with
    direction ("request" from the host, "reply" to it), source, destination
    and the decoded fields."""
    partial = {}
    messages = []
    for record in records:
        frame = record.frame
        if record.outcome != "ok" or not frame.extended or (frame.id >> 16) & 0xFF != CONFIGURATION:
            continue
        destination, source = (frame.id >> 8) & 0xFF, frame.id & 0xFF
        data = bytes(frame.data)
        if not data:
            raise WireError(f"an empty frame {frame.id:#010x}")
        key = (frame.id >> 24, destination, source)
        kind = data[0] >> 4
        if kind == 0:
            length = data[0] & 0x0F
            if not 1 <= length <= len(data) - 1:
                raise WireError(f"a single frame of length {length} in {data.hex()}")
            whole = data[1:1 + length]
        elif kind == 1:
            length = ((data[0] & 0x0F) << 8) | data[1]
            if length < 8 or len(data) != 8:
                raise WireError(f"a first frame of {length} bytes in {data.hex()}")
            partial[key] = [length, bytearray(data[2:]), 1]
            continue
        elif kind == 2:
            if key not in partial or data[0] & 0x0F != partial[key][2] % 16:
                raise WireError(f"a consecutive frame out of turn: {frame.id:#010x} {data.hex()}")
            partial[key][1] += data[1:]
            partial[key][2] += 1
            if len(partial[key][1]) < partial[key][0]:
                continue
            whole = bytes(partial[key][1][:partial[key][0]])
            del partial[key]
        elif kind == 3:
            continue  # A flow control.
        else:
            raise WireError(f"no ISO-TP frame: {data.hex()}")
        request = source == host
        if request and destination != BROADCAST and not 1 <= destination <= 254:
            raise WireError(f"a request to {destination}")
        fields = _requests(whole[0], whole[1:]) if request else _reply(whole[0], whole[1:])
        fields.update(direction="request" if request else "reply", source=source, destination=destination)
        messages.append(fields)
    return messages

"""The monitoring stream read off the lab bus's log by an observer written
from docs/protocols/monitor.md alone, not from the firmware's or dcos-mon's
code: every frame of message type 0x41 is one classic frame, decoded by
the page's table of layouts. A frame the page does not allow raises
WireError, so a test that reads the wire proves the node keeps to the page.
"""
import struct

MONITORING = 0x41
END_REASONS = {1: "lease expired", 2: "stopped", 3: "replaced"}


class WireError(AssertionError):
    pass


def decode(data):
    """The fields of one stream frame's data bytes, or WireError."""
    data = bytes(data)
    if not data:
        raise WireError("an empty stream frame")
    kind = data[0]
    if kind == 0x01:
        if len(data) != 8:
            raise WireError(f"a sample of {len(data)} bytes: {data.hex()}")
        channel, time_ms, value = struct.unpack_from("<BHi", data, 1)
        if channel > 7:
            raise WireError(f"a sample of channel {channel}")
        return {"kind": "sample", "channel": channel, "time_ms": time_ms, "value": value}
    if kind == 0x02:
        if not 3 <= len(data) <= 8:
            raise WireError(f"a log frame of {len(data)} bytes: {data.hex()}")
        return {"kind": "log", "sequence": data[1], "text": data[2:]}
    if kind == 0x03:
        if len(data) != 3:
            raise WireError(f"a lost frame of {len(data)} bytes: {data.hex()}")
        lost = struct.unpack_from("<H", data, 1)[0]
        if lost == 0:
            raise WireError("a lost frame reporting nothing")
        return {"kind": "lost", "bytes": lost}
    if kind == 0x04:
        if len(data) != 2 or data[1] not in END_REASONS:
            raise WireError(f"an end frame {data.hex()}")
        return {"kind": "end", "reason": END_REASONS[data[1]]}
    raise WireError(f"a stream frame of kind {kind:#04x}: {data.hex()}")


def read_stream(records):
    """Every stream frame the bus carried, in order, as dicts with the
    identifier's fields (priority, destination, source), the frame's end in
    emulated nanoseconds and the decoded fields."""
    frames = []
    for record in records:
        frame = record.frame
        if record.outcome != "ok" or not frame.extended or (frame.id >> 16) & 0xFF != MONITORING:
            continue
        if frame.remote:
            raise WireError(f"a remote frame {frame.id:#010x} of the stream")
        fields = decode(frame.data)
        fields.update(priority=frame.id >> 24, destination=(frame.id >> 8) & 0xFF, source=frame.id & 0xFF,
                      end_ns=record.end)
        frames.append(fields)
    return frames

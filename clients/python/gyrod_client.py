"""A client for gyrod's Unix socket protocol (docs/protocol.md), standard library only.

    import gyrod_client
    with gyrod_client.Client() as gyro:          # or Client("/tmp/gyrod.sock")
        print(gyro.status()["device_state"])
        for item in gyro.watch(decimate=50):
            if isinstance(item, gyrod_client.Rate):
                print(item.seq, item.t, item.rate)

`watch()` yields `Rate` and `Gap` objects; `status()`, `allan()` and `effects()` return the reply
as a dict.
Fields this module does not name are kept in `.fields` and classes it does not know are
skipped, as the protocol asks of clients (a minor version may add them); a field gyrod left
out (it never sends null) is None here.
"""

import json
import os
import socket
import sys
from dataclasses import dataclass, field
from typing import Iterator, List, Optional, Union

# protocol/socket_path.hpp kDefaultSocketPath; GYROD_SOCKET overrides it, as for gyroctl.
DEFAULT_SOCKET_PATH = "/run/gyrod/gyrod.sock"
SUPPORTED_PROTO_MAJOR = 1

Vector = Optional[List[float]]


class ProtocolError(Exception):
    """The server sent something this client cannot use, or an ERROR reply."""


@dataclass
class Rate:
    """One RATE line: angular rates in deg/s per axis [x, y, z]; `t` is the sample's data-ready
    edge on CLOCK_MONOTONIC (s, for intervals), `time` the same instant in UTC epoch seconds
    (us resolution, for lining up with other machines); `accel` in g, `accel_ms2` in m/s^2;
    `quat` the orientation [w, x, y, z] (sensor -> world, z up), `roll`, `pitch`, `heading` its
    Z-Y-X angles in degrees and `inclination_std`, `heading_std` their 1 sigma (with a sensor
    model and the accelerometer; docs/attitude.md)."""

    seq: int
    t: float
    temp: Optional[float] = None
    raw: Vector = None
    mean: Vector = None
    kalman: Vector = None
    rate: Vector = None
    bias: Vector = None
    still: Optional[bool] = None
    time: Optional[float] = None
    accel: Vector = None
    accel_ms2: Vector = None
    quat: Vector = None
    roll: Optional[float] = None
    pitch: Optional[float] = None
    heading: Optional[float] = None
    inclination_std: Optional[float] = None
    heading_std: Optional[float] = None
    # Every field of the line, including those added by later protocol minor versions.
    fields: dict = field(default_factory=dict, repr=False)


@dataclass
class Gap:
    """One GAP line: samples seq .. seq + count - 1 will never come."""

    seq: int
    count: int
    reason: str
    fields: dict = field(default_factory=dict, repr=False)


_REAL_FIELDS = ("t", "temp", "time", "roll", "pitch", "heading", "inclination_std", "heading_std")
_VECTOR_FIELDS = ("raw", "mean", "kalman", "rate", "bias", "accel", "accel_ms2")


def _as_real(value):
    # gyrod writes a whole-valued double as an integer ("1"): a float here, whatever its digits.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ProtocolError("not a number: %.80r" % (value,))
    return float(value)


def _known(cls, obj: dict) -> dict:
    names = {f for f in cls.__dataclass_fields__ if f != "fields"}
    known = {k: v for k, v in obj.items() if k in names}
    if cls is Rate:
        for k in _REAL_FIELDS:
            if k in known:
                known[k] = _as_real(known[k])
        for k in _VECTOR_FIELDS:
            if k in known:
                if not isinstance(known[k], list) or len(known[k]) != 3:
                    raise ProtocolError("RATE %s is not [x, y, z]: %.80r" % (k, known[k]))
                known[k] = [_as_real(x) for x in known[k]]
        if "quat" in known:
            if not isinstance(known["quat"], list) or len(known["quat"]) != 4:
                raise ProtocolError("RATE quat is not [w, x, y, z]: %.80r" % (known["quat"],))
            known["quat"] = [_as_real(x) for x in known["quat"]]
    return known


def parse_line(line: str) -> Union[Rate, Gap, dict]:
    """A Rate or Gap for those classes, else the object as a dict (VERSION, WATCH, STATUS, ...)."""
    obj = json.loads(line)
    if not isinstance(obj, dict) or not isinstance(obj.get("class"), str):
        raise ProtocolError("not a protocol object: %.80r" % line)
    try:
        if obj["class"] == "RATE":
            return Rate(**_known(Rate, obj), fields=obj)
        if obj["class"] == "GAP":
            return Gap(**_known(Gap, obj), fields=obj)
    except TypeError as e:  # a required field missing
        raise ProtocolError("%s line without a required field: %.80r" % (obj["class"], line)) from e
    return obj


class Client:
    """One connection to gyrod. The VERSION line is read on connect (`self.version`)."""

    def __init__(self, path: Optional[str] = None, timeout: Optional[float] = 10.0):
        self.path = path or os.environ.get("GYROD_SOCKET") or DEFAULT_SOCKET_PATH
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._sock.settimeout(timeout)
        try:
            self._sock.connect(self.path)
        except OSError as e:
            self._sock.close()
            raise OSError(e.errno, e.strerror, self.path) from e
        self._buffer = b""
        self.version = self._next_object()
        if self.version.get("class") != "VERSION":
            raise ProtocolError("expected VERSION first, got %r" % self.version.get("class"))
        if self.version.get("proto_major") != SUPPORTED_PROTO_MAJOR:
            raise ProtocolError("protocol major %r, this client speaks %d"
                                % (self.version.get("proto_major"), SUPPORTED_PROTO_MAJOR))

    def close(self) -> None:
        self._sock.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _read_line(self) -> str:
        while b"\n" not in self._buffer:
            chunk = self._sock.recv(65536)
            if not chunk:  # a final line without its newline is incomplete: dropped
                raise ConnectionError("gyrod closed the connection")
            self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        return line.decode("utf-8")

    def _next_object(self):
        while True:
            line = self._read_line()
            if line.strip():
                return parse_line(line)

    def _send(self, request: dict) -> None:
        self._sock.sendall((json.dumps(request, separators=(",", ":")) + "\n").encode("utf-8"))

    def _reply(self, cls: str) -> dict:
        """The next object of class `cls`; RATE/GAP lines of an active watch are skipped."""
        while True:
            obj = self._next_object()
            if isinstance(obj, dict):
                if obj["class"] == "ERROR":
                    raise ProtocolError("gyrod: %s: %s" % (obj.get("code"), obj.get("message")))
                if obj["class"] == cls:
                    return obj

    def status(self) -> dict:
        self._send({"cmd": "status"})
        return self._reply("STATUS")

    def allan(self) -> dict:
        self._send({"cmd": "allan"})
        return self._reply("ALLAN")

    def effects(self) -> dict:
        """The EFFECTS reply: "live_check" ("on" or "off", with "reason") and "effects", each effect
        the live check names now as its EFFECT object (protocol 1.8; an older gyrod answers with
        an ERROR, raised as ProtocolError)."""
        self._send({"cmd": "effects"})
        return self._reply("EFFECTS")

    def watch(self, decimate: int = 1) -> Iterator[Union[Rate, Gap]]:
        """Turns watching on and yields every RATE and GAP line, until the connection ends."""
        self._send({"cmd": "watch", "enable": True, "decimate": decimate})
        self._reply("WATCH")
        while True:
            obj = self._next_object()
            if isinstance(obj, (Rate, Gap)):
                yield obj
            elif obj["class"] == "ERROR":
                raise ProtocolError("gyrod: %s: %s" % (obj.get("code"), obj.get("message")))


def _format_vector(v: Vector) -> str:
    return " ".join("%9.4f" % x for x in v) if v else "%29s" % "-"


def _format_time(time: Optional[float]) -> str:
    if time is None:
        return "%27s" % "-"
    import datetime

    utc = datetime.datetime.fromtimestamp(time, tz=datetime.timezone.utc)
    return utc.strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def main(argv: Optional[List[str]] = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python3 -m gyrod_client",
                                     description="Print gyrod's rates (deg/s), like a small gyroctl watch.")
    parser.add_argument("--socket", help="socket path (default: $GYROD_SOCKET or %s)" % DEFAULT_SOCKET_PATH)
    parser.add_argument("--decimate", type=int, default=50, help="every N-th sample (default 50)")
    parser.add_argument("--count", type=int, default=0, help="stop after N samples (default: never)")
    args = parser.parse_args(argv)
    try:
        with Client(args.socket, timeout=None) as gyro:
            print("# t: CLOCK_MONOTONIC s of the data-ready edge; time: UTC; rate = raw - bias, deg/s x y z",
                  flush=True)
            printed = 0
            for item in gyro.watch(args.decimate):
                if isinstance(item, Gap):
                    print("# GAP seq %d count %d %s" % (item.seq, item.count, item.reason), flush=True)
                    continue
                print("%8d %14.6f %s %s" % (item.seq, item.t, _format_time(item.time), _format_vector(item.rate)),
                      flush=True)
                printed += 1
                if args.count and printed >= args.count:
                    return 0
    except OSError as e:
        print("gyrod_client: %s: %s" % (e.filename or args.socket or DEFAULT_SOCKET_PATH, e.strerror or e),
              file=sys.stderr)
        return 1
    except ProtocolError as e:
        print("gyrod_client: %s" % e, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0
    return 0


if __name__ == "__main__":
    sys.exit(main())

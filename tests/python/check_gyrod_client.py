"""clients/python/gyrod_client.py against a running gyrod (started by
tests/integration/test_python_client.cpp on the mock). Usage: check_gyrod_client.py SOCKET
Exit 0 when every check holds; otherwise the failed check on stderr and exit 1."""

import dataclasses
import io
import math
import os
import re
import sys
from contextlib import redirect_stdout

import gyrod_client


def check(condition, what):
    if not condition:
        print("FAILED: " + what, file=sys.stderr)
        sys.exit(1)


def is_vector(v):
    return isinstance(v, list) and len(v) == 3 and all(isinstance(x, float) and math.isfinite(x) for x in v)


def check_parse_tolerates_unknown_fields():
    line = ('{"class":"RATE","seq":7,"t":1.5,"temp":30,"raw":[1,2.0,3.0],"time":1795000000.123456,'
            '"accel":[0,0.0,1.0],"accel_ms2":[0,0,9.80665],"future_field":{"a":1}}')
    r = gyrod_client.parse_line(line)
    check(isinstance(r, gyrod_client.Rate) and r.seq == 7 and r.raw == [1.0, 2.0, 3.0], "parse a RATE line")
    check(isinstance(r.temp, float) and all(isinstance(x, float) for x in r.raw), "whole numbers become floats")
    check(r.time == 1795000000.123456 and r.accel == [0.0, 0.0, 1.0] and r.accel_ms2 == [0.0, 0.0, 9.80665],
          "time, accel and accel_ms2: %r" % r)
    check(r.kalman is None and r.fields["future_field"] == {"a": 1}, "an unknown RATE field is kept in .fields")
    oriented = gyrod_client.parse_line(
        '{"class":"RATE","seq":8,"t":1.52,"quat":[1,0,0.0,-0.0],"roll":0,"pitch":-1.5,"heading":179.9,'
        '"inclination_std":0.2,"heading_std":3}')
    check(oriented.quat == [1.0, 0.0, 0.0, -0.0] and all(isinstance(x, float) for x in oriented.quat)
          and oriented.roll == 0.0 and isinstance(oriented.roll, float) and oriented.heading == 179.9
          and oriented.heading_std == 3.0, "the orientation: %r" % oriented)
    g = gyrod_client.parse_line('{"class":"GAP","seq":9,"count":2,"reason":"some_new_reason","extra":1}')
    check(isinstance(g, gyrod_client.Gap) and g.count == 2 and g.reason == "some_new_reason", "parse a GAP line")
    check(gyrod_client.parse_line('{"class":"NEWCLASS","x":1}') == {"class": "NEWCLASS", "x": 1},
          "an unknown class is returned as a dict")
    for bad in ('[1,2]', '{"seq":1}', '{"class":"RATE","t":1.0}', '{"class":"RATE","seq":1,"t":1,"raw":[1,2]}',
                '{"class":"RATE","seq":1,"t":"now"}', '{"class":"RATE","seq":1,"t":1,"time":"today"}',
                '{"class":"RATE","seq":1,"t":1,"accel":[0,1]}', '{"class":"RATE","seq":1,"t":1,"quat":[1,0,0]}',
                '{"class":"RATE","seq":1,"t":1,"heading":"north"}'):
        try:
            gyrod_client.parse_line(bad)
            check(False, "refuse %s" % bad)
        except gyrod_client.ProtocolError:
            pass


def rate_table_fields():
    """The field names of docs/protocol.md's RATE table, in order."""
    doc = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "protocol.md")
    with open(doc, encoding="utf-8") as f:
        text = f.read()
    table = text.split("### RATE", 1)[1].split("\n\n", 2)[1]
    return [m.group(1) for m in re.finditer(r"^\| `([a-z0-9_]+)` \|", table, re.MULTILINE) if m.group(1) != "class"]


def check_rate_fields_are_the_documented_ones():
    documented = rate_table_fields()
    ours = [f.name for f in dataclasses.fields(gyrod_client.Rate) if f.name != "fields"]
    # A subset: a field the table gains later (a protocol minor version) is in Rate.fields until Rate names it.
    check(ours and set(ours) <= set(documented),
          "Rate's fields %r are in docs/protocol.md's RATE table %r" % (ours, documented))


def check_against_gyrod(path):
    with gyrod_client.Client(path) as gyro:
        check(gyro.version["class"] == "VERSION" and gyro.version["proto_major"] == 1, "VERSION line")
        status = gyro.status()
        check(isinstance(status, dict) and status["class"] == "STATUS", "status() returns the STATUS dict")
        check(status["nominal_rate"] == 50 and status["clients"] >= 1, "STATUS fields: %r" % status)
        # Every RATE line until 60 carry `rate` (it is left out during the start-up still period).
        rates = []
        for item in gyro.watch():
            if isinstance(item, gyrod_client.Rate):
                rates.append(item)
            if sum(r.rate is not None for r in rates) == 60 or len(rates) == 5000:
                break
        for prev, cur in zip(rates, rates[1:]):
            check(cur.seq > prev.seq and cur.t > prev.t, "seq and t increase: %r then %r" % (prev, cur))
            # One offset per FIFO burst: within a burst time - t is constant (to the double's rounding);
            # across bursts it moves only as the system clock does, far less than a sample period.
            check(abs((cur.time - cur.t) - (prev.time - prev.t)) < 0.005, "time follows t: %r then %r" % (prev, cur))
            check(prev.rate is None or cur.rate is not None, "rate stays once it is there: %r" % cur)
        check(rates[-1].rate is not None, "rate appears within %d samples" % len(rates))
        for r in rates:
            check(is_vector(r.raw), "raw vector: %r" % r)
            # The mock runs on a virtual clock whose wall time began when gyrod started (this decade).
            check(isinstance(r.time, float) and 1.6e9 < r.time < 2.6e9, "time is UTC epoch seconds: %r" % r)
            check(r.accel is None or (is_vector(r.accel) and is_vector(r.accel_ms2)), "accel vectors: %r" % r)
            if r.rate is None:
                continue
            check(is_vector(r.rate) and is_vector(r.bias), "rate and bias vectors: %r" % r)
            check(-40.0 < r.temp < 85.0, "temperature in the chip's range: %r" % r.temp)
            check(all(abs(x) < 250.0 for x in r.raw), "raw within the full scale: %r" % r.raw)
            check(r.bias == [-3.34, 1.09, -0.5], "bias is the configured one: %r" % r.bias)
            check(all(abs(r.raw[i] - r.bias[i] - r.rate[i]) < 1e-9 for i in range(3)), "rate = raw - bias: %r" % r)
        check(any(r.kalman is not None for r in rates), "kalman appears after the still period")
        # ALLAN while RATE lines keep coming: allan() skips them to its reply.
        allan = gyro.allan()
        check(allan["class"] == "ALLAN" and allan["samples"] > 0, "allan() returns the ALLAN dict")
        # Without filter.model gyrod does not run the live check, and says so.
        effects = gyro.effects()
        check(effects["class"] == "EFFECTS" and effects["live_check"] == "off" and effects["effects"] == []
              and "filter.model" in effects["reason"], "effects() returns the EFFECTS dict: %r" % effects)

    out = io.StringIO()
    with redirect_stdout(out):
        code = gyrod_client.main(["--socket", path, "--decimate", "5", "--count", "3"])
    lines = out.getvalue().splitlines()
    check(code == 0 and len(lines) == 4 and lines[0].startswith("# t:"), "the __main__ watch: %r" % lines)
    check(gyrod_client.main(["--socket", path + ".missing", "--count", "1"]) == 1, "a missing socket exits 1")


def main():
    check(len(sys.argv) == 2, "usage: check_gyrod_client.py SOCKET")
    check_parse_tolerates_unknown_fields()
    check_rate_fields_are_the_documented_ones()
    check_against_gyrod(sys.argv[1])
    print("ok")


if __name__ == "__main__":
    main()

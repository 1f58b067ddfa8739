"""A recording gyrod's recorder wrote (with GAP, DROPPED and page-padding lines) read by the tools
its users read CSV with: numpy's genfromtxt(names=True, comments='#'), pandas' read_csv(comment='#')
and allantools on a column (docs/recording-format.md). Started by
tests/daemon_config/test_recording_readers.cpp.

Usage: check_recording_readers.py RECORDING EXPECTED
EXPECTED is a plain CSV (no comments): the column names, then the value of every sample line in
%.17g ("nan" for an empty field). Exit 0 when every check holds, 77 when numpy is missing, else 1
with the failed check on stderr. A reader that is not importable is reported as skipped, by name."""

import csv
import sys


def check(condition, what):
    if not condition:
        print("FAILED: " + what, file=sys.stderr)
        sys.exit(1)


def main():
    check(len(sys.argv) == 3, "usage: check_recording_readers.py RECORDING EXPECTED")
    recording, expected_path = sys.argv[1], sys.argv[2]
    try:
        import numpy as np
    except ImportError:
        print("SKIP: numpy is not importable (Debian package python3-numpy)")
        sys.exit(77)
    with open(expected_path, newline="") as f:
        rows = list(csv.reader(f))
    names = rows[0]
    expected = np.array([[float(x) for x in row] for row in rows[1:]])
    check(expected.shape[0] > 0, "expected rows")

    # numpy: the names from the first line; '#' lines (comments, GAP, DROPPED, padding) skipped.
    a = np.genfromtxt(recording, delimiter=",", names=True, comments="#")
    check(a.dtype.names == tuple(names), "genfromtxt names %r, expected %r" % (a.dtype.names, names))
    check(a.shape == (expected.shape[0],), "genfromtxt rows %r, expected %d" % (a.shape, expected.shape[0]))
    for j, name in enumerate(names):
        check(np.array_equal(a[name], expected[:, j], equal_nan=True),
              "genfromtxt column %s differs: %r vs %r" % (name, a[name][:5], expected[:5, j]))
    print("numpy %s genfromtxt: %d rows, columns %s, every value exact" % (np.__version__, a.shape[0], ",".join(names)))

    try:
        import pandas as pd
    except ImportError:
        print("pandas: skipped: not importable (Debian package python3-pandas)")
    else:
        for precision in (None, "round_trip"):
            df = pd.read_csv(recording, comment="#", float_precision=precision)
            check(list(df.columns) == names, "read_csv columns %r, expected %r" % (list(df.columns), names))
            check(len(df) == expected.shape[0], "read_csv rows %d, expected %d" % (len(df), expected.shape[0]))
            for j, name in enumerate(names):
                got = df[name].to_numpy(dtype=float)
                if precision == "round_trip":
                    ok = np.array_equal(got, expected[:, j], equal_nan=True)
                else:  # pandas' default parser (xstrtod) is not correctly rounded: 4.5e-13 seen
                    ok = np.allclose(got, expected[:, j], rtol=1e-12, atol=0.0, equal_nan=True)
                finite = np.isfinite(expected[:, j])
                worst = np.max(np.abs(got[finite] / expected[finite, j] - 1.0), initial=0.0)
                check(ok, "read_csv(float_precision=%r) column %s differs (worst relative error %.3g)"
                      % (precision, name, worst))
        print("pandas %s read_csv: %d rows; exact with float_precision='round_trip'" % (pd.__version__, len(df)))

    try:
        import allantools
    except ImportError:
        print("allantools: skipped: not importable (not packaged in Debian bookworm; pip install allantools)")
    else:
        rate_hz = 1.0 / np.median(np.diff(a["t"]))
        taus, adev, _, _ = allantools.oadev(a["gx"], rate=rate_hz, data_type="freq", taus="octave")
        check(len(taus) > 0 and np.all(np.isfinite(adev)), "allantools.oadev on column gx")
        print("allantools %s oadev on gx: %d taus" % (allantools.__version__, len(taus)))
    print("ok")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""A BROAD trial's gyro calibrated against its optical truth alone (no accelerometer).

Over windows of the movement phases (0.5 s by default) the gyro's integrated rotation is
compared with the truth's, q_gyro ⊗ q_truth⁻¹ (both relative to the window's start, in its
frame); to first order that error's rotation vector is Σ R_k·(M·ω_k + b)·Δt, with R_k the
rotation from the window's start to sample k, so a least-squares fit over all windows gives
the gyro's 3×3 error matrix M (it reads (I + M)·ω + b) and its bias b in motion. M's
symmetric part is the scale errors and the cross-axis coupling; its antisymmetric part is a
rotation of the gyro's axes against the truth's body frame (the marker mount's alignment as
much as the gyro's). Windows whose residual exceeds 3× the median are dropped (marker swaps).

Usage: broad_gyro_against_truth.py DIRECTORY TRIAL [--lag SAMPLES] [--window SAMPLES]
                                   [--write-corrected OUT_DIRECTORY]
  --lag: the truth's sample i + lag is compared with the IMU's sample i (default: the best of
         −3 … 0 in half samples, each printed);
  --write-corrected: OUT_DIRECTORY/TRIAL.csv.gz with the gyro corrected by M's symmetric part,
         (I + S)⁻¹·ω, and the truth copied beside it, for bench/attitude_broad.
docs/attitude.md cites its figures.
"""
import argparse
import gzip
import os
import shutil

import numpy as np


def qmul(a, b):
    w1, x1, y1, z1 = a.T
    w2, x2, y2, z2 = b.T
    return np.column_stack((w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2))


def conj(q):
    c = q.copy()
    c[:, 1:] *= -1.0
    return c


def rotation_vector(q):
    q = q * np.sign(q[:, :1])
    v = q[:, 1:]
    n = np.linalg.norm(v, axis=1)
    angle = 2.0 * np.arctan2(n, q[:, 0])
    return v * np.where(n > 1e-12, angle / np.maximum(n, 1e-12), 2.0)[:, None]


def rotation_matrix(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def shifted_truth(q, lag):
    """The truth at sample i + lag, linear between neighbours (signs made continuous first)."""
    q = q.copy()
    for i in range(1, len(q)):
        if np.dot(q[i], q[i - 1]) < 0:
            q[i] = -q[i]
    whole = int(np.floor(lag))
    frac = lag - whole
    idx = np.clip(np.arange(len(q)) + whole, 0, len(q) - 2)
    out = (1 - frac) * q[idx] + frac * q[idx + 1]
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def window_equations(rate, truth, moving, dt, window):
    """Per window: the 3×12 regressor (M row-major, then b) and the error's rotation vector."""
    angle = np.linalg.norm(rate, axis=1) * dt
    axis = rate / np.maximum(np.linalg.norm(rate, axis=1), 1e-15)[:, None]
    steps = np.column_stack([np.cos(angle / 2), np.sin(angle / 2)[:, None] * axis])
    rows, errors = [], []
    for start in range(10, len(rate) - window - 10, window):
        end = start + window
        if not (moving[start:end].all() and np.isfinite(truth[start - 3:end + 3]).all()):
            continue
        q = np.array([1.0, 0.0, 0.0, 0.0])
        a = np.zeros((3, 12))
        for k in range(start, end):
            r = rotation_matrix(q)
            a[:, :9] += np.kron(r, rate[k][None, :]) * dt
            a[:, 9:] += r * dt
            q = qmul(q[None, :], steps[k:k + 1])[0]
        truth_step = qmul(conj(truth[start:start + 1]), truth[end:end + 1])
        rows.append(a)
        errors.append(rotation_vector(qmul(q[None, :], conj(truth_step)))[0])
    return np.array(rows), np.array(errors)


def robust_fit(a, y):
    keep = np.ones(len(a), bool)
    for _ in range(5):
        theta = np.linalg.lstsq(a[keep].reshape(-1, 12), y[keep].ravel(), rcond=None)[0]
        residual = np.linalg.norm(y - np.einsum('wij,j->wi', a, theta), axis=1)
        keep = residual < 3.0 * np.median(residual)
    rms = np.sqrt((residual[keep] ** 2).mean())
    return theta, keep, rms


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('directory')
    parser.add_argument('trial')
    parser.add_argument('--lag', type=float)
    parser.add_argument('--window', type=int, default=143)
    parser.add_argument('--write-corrected')
    args = parser.parse_args()
    base = os.path.join(args.directory, args.trial)
    imu = np.loadtxt(gzip.open(base + '.csv.gz', 'rt'), delimiter=',', skiprows=1)
    truth = np.genfromtxt(gzip.open(base + '.truth.csv.gz', 'rt'), delimiter=',', skip_header=1)
    dt = (imu[-1, 0] - imu[0, 0]) / (len(imu) - 1)
    rate = np.radians(imu[:, 1:4])
    moving = truth[:, 5] > 0
    lags = [args.lag] if args.lag is not None else [-3.0, -2.5, -2.0, -1.5, -1.0, -0.5, 0.0]
    best = None
    for lag in lags:
        a, y = window_equations(rate, shifted_truth(truth[:, 1:5], lag), moving, dt, args.window)
        theta, keep, rms = robust_fit(a, y)
        print('lag %+.1f samples: %d of %d windows, residual %.3f deg rms' % (lag, keep.sum(), len(a), np.degrees(rms)))
        if best is None or rms < best[0]:
            best = (rms, lag, theta)
    _, lag, theta = best
    m = theta[:9].reshape(3, 3)
    sym, anti = (m + m.T) / 2, (m - m.T) / 2
    print('%s, lag %+.1f samples' % (args.trial, lag))
    print('  scale x %+.3f y %+.3f z %+.3f %%' % tuple(100 * np.diag(m)))
    print('  cross-axis (symmetric) xy %+.3f xz %+.3f yz %+.3f %%' % (100 * sym[0, 1], 100 * sym[0, 2], 100 * sym[1, 2]))
    print('  axes rotated against the truth\'s x %+.3f y %+.3f z %+.3f deg' %
          tuple(np.degrees([anti[2, 1], anti[0, 2], anti[1, 0]])))
    print('  bias in motion x %+.3f y %+.3f z %+.3f deg/s' % tuple(np.degrees(theta[9:])))
    if args.write_corrected:
        os.makedirs(args.write_corrected, exist_ok=True)
        corrected = imu.copy()
        corrected[:, 1:4] = np.linalg.solve(np.eye(3) + sym, imu[:, 1:4].T).T
        out = os.path.join(args.write_corrected, args.trial)
        with gzip.open(out + '.csv.gz', 'wt') as f:
            f.write('t,gx,gy,gz,ax,ay,az\n')
            np.savetxt(f, corrected, delimiter=',', fmt='%.9g')
        shutil.copy(base + '.truth.csv.gz', out + '.truth.csv.gz')
        print('  wrote %s.csv.gz (gyro corrected by the symmetric part)' % out)


if __name__ == '__main__':
    main()

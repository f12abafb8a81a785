"""Synthetic test data from a truth model's modes: modal data with stated noise, and time recordings.

Recordings are computed by modal superposition with each mode's ODE q'' + 2 zeta w q' + w^2 q = p(t)
discretised exactly for a force that is linear between samples (first-order hold), so the only errors are the
ones a real test has: sensor noise, finite records, modes above the Nyquist frequency left out (an ideal
anti-alias filter).
"""
import json

import numpy as np
from scipy import signal

import uff


def noisy_modes(freqs, shapes, sigma_f, sigma_s, rng):
    """Frequencies with relative noise sigma_f; shapes (DOFs x modes) scaled to a largest entry of +1, plus noise
    of sigma_s (relative to that largest entry)."""
    f = freqs * (1 + sigma_f * rng.standard_normal(len(freqs)))
    S = shapes / shapes[np.abs(shapes).argmax(axis=0), np.arange(shapes.shape[1])]
    return f, S + sigma_s * rng.standard_normal(S.shape)


def write_modal(path, fmt, labels, freqs, damping, shapes, case):
    """Modal data as UFF 55 (one dataset per mode) or dynid's modal-data JSON."""
    if fmt == "uff":
        text = ""
        nodes = list(dict.fromkeys(n for n, _ in labels))
        for k, f in enumerate(freqs):
            sh = {n: [0.0, 0.0, 0.0] for n in nodes}
            for (n, d), v in zip(labels, shapes[:, k]):
                sh[n][uff.DIRECTIONS[d] - 1] = v
            text += uff.dataset55(k + 1, f, damping[k], sh, case)
        path.write_text(text)
    else:
        modes = [{"frequency_hz": float(f), "damping_ratio": float(damping[k]),
                  "shape": {f"{n}{d}": float(v) for (n, d), v in zip(labels, shapes[:, k])}}
                 for k, f in enumerate(freqs)]
        path.write_text(json.dumps({"modes": modes}, indent=1) + "\n")


def modal_response(freqs, zetas, phi_out, phi_in, forces, fs):
    """Accelerations (outputs x samples) of a structure at rest under forces (inputs x samples, linear between
    samples): modal superposition, each mode discretised exactly (first-order hold)."""
    P = phi_in.T @ forces
    acc = np.zeros((len(freqs), forces.shape[1]))
    for r, (f, z) in enumerate(zip(freqs, zetas)):
        w = 2 * np.pi * f
        A = np.array([[0.0, 1.0], [-w * w, -2 * z * w]])
        B = np.array([[0.0], [1.0]])
        C = np.array([[-w * w, -2 * z * w]])
        D = np.array([[1.0]])
        Ad, Bd, Cd, Dd, _ = signal.cont2discrete((A, B, C, D), 1.0 / fs, method="foh")
        b, a = signal.ss2tf(Ad, Bd, Cd, Dd)
        acc[r] = signal.lfilter(b[0], a, P[r])
    return phi_out @ acc


def band_limited_noise(rng, n, fs, f_hi, count=1):
    """Gaussian noise with a flat spectrum up to f_hi, unit RMS (count independent signals)."""
    spec = np.fft.rfft(rng.standard_normal((count, n)), axis=1)
    spec[:, np.fft.rfftfreq(n, 1 / fs) > f_hi] = 0.0
    x = np.fft.irfft(spec, n, axis=1)
    return x / x.std(axis=1, keepdims=True)


def half_sine(n, fs, start, width, peak):
    """A hammer pulse: half a sine of duration `width` (s) from sample `start`."""
    t = np.arange(n) / fs - start / fs
    return np.where((t >= 0) & (t <= width), peak * np.sin(np.pi * np.clip(t / width, 0, 1)), 0.0)


def write_recordings(folder, layout, fmt, channels, records, force_dofs, fs, prefix=""):
    """Writes one test set-up's records. channels: [(node, dof, kind)] (kind 'force' or 'acceleration');
    records: list of arrays (channels x samples). layout 'single': one file with every channel and record;
    'per_channel': one file per channel holding that channel's records. Returns the file names."""
    binary, single = fmt != "ascii", fmt != "binary64"
    ref = (force_dofs[0][0], uff.DIRECTIONS[force_dofs[0][1]]) if force_dofs else (0, 0)
    dt = 1.0 / fs

    def ds(c, k):
        node, dof, kind = channels[c]
        name = f"{'Force' if kind == 'force' else 'Acc'} {node}{dof}"
        return uff.dataset58(records[k][c], dt, node, dof, kind, k + 1, name, ref=ref, binary=binary,
                             single=single)
    files = []
    if layout == "single":
        name = f"{prefix or 'test'}.uff"
        (folder / name).write_bytes(b"".join(ds(c, k) for k in range(len(records)) for c in range(len(channels))))
        files.append(name)
    else:
        for c, (node, dof, kind) in enumerate(channels):
            name = f"{prefix + '_' if prefix else ''}{'force' if kind == 'force' else 'acc'}_{node}{dof}.uff"
            (folder / name).write_bytes(b"".join(ds(c, k) for k in range(len(records))))
            files.append(name)
    return files

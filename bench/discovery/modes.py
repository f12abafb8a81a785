"""Modes of a built model as a test sees them, and pairing of modes between models."""
import math

import numpy as np

import fe

VISIBLE_SHARE = 0.15      # a mode is seen if the sensors' RMS is >= this share of the structure's RMS ...
TRANSLATIONAL = 0.5       # ... and translations carry at least half of its kinetic energy


class Modes:
    """Modes of a built model: frequencies, shapes at the analysis model's measurable DOFs (X) and at the
    sensors (Y), and which modes the sensors see."""

    def __init__(self, model, axial, n, labels, sensor_labels):
        asm = model.assemble(axial=axial)
        self.f, phi = fe.modal(asm, min(n, asm.K.shape[0] - 1))
        self.unstable = bool((self.f < -1e-3 * np.abs(self.f).max()).any())
        tr = np.array([i for d, i in asm.full_index.items() if d[1] < 3])
        Md = asm.Mfull.diagonal()
        share = (Md[tr, None] * phi[tr] ** 2).sum(0) / (Md[:, None] * phi**2).sum(0)
        self.X = phi[asm.rows(labels)]
        self.Y = phi[asm.rows(sensor_labels)]
        rms_all = np.sqrt((phi[tr] ** 2).mean(0))
        rms_s = np.sqrt((self.Y**2).mean(0))
        self.visible = (share >= TRANSLATIONAL) & (rms_s >= VISIBLE_SHARE * rms_all)
        self.asm, self.phi, self.model, self.axial = asm, phi, model, axial

    def elastic(self, f_min):
        """Visible modes at or above f_min (below it: rigid-body and suspension modes of free-free tests)."""
        return [k for k in range(len(self.f)) if self.visible[k] and self.f[k] >= f_min]

    def suspension(self, f_min):
        return [k for k in range(len(self.f)) if 0 < self.f[k] < f_min]

    def rows(self, labels):
        return self.phi[self.asm.rows(labels)]


def mac(a, b):
    return (a.T @ b) ** 2 / np.outer((a * a).sum(0), (b * b).sum(0))


def _paired_shifts(modes, ref, idx, A, B, min_mac):
    """Per mode k of idx, |f_k / f_ref - 1| to its best-MAC mode of `ref` (shapes A of `modes`, B of `ref`), or
    None where that MAC is below min_mac."""
    M = mac(A[:, idx], B)
    out = []
    for j, k in enumerate(idx):
        r = int(M[j].argmax())
        out.append(abs(modes.f[k] / ref.f[r] - 1) if M[j, r] >= min_mac else None)
    return out


def max_shift(modes, ref, idx, min_mac=0.5):
    """Largest |f / f_ref - 1| over the modes idx of `modes`, each paired with its best-MAC mode of `ref`."""
    if modes.unstable:
        return math.inf
    return max((s for s in _paired_shifts(modes, ref, idx, modes.X, ref.X, min_mac) if s is not None), default=0.0)


def seen_shift(modes, ref, idx, min_mac=0.5, sensor_mac=0.9):
    """The shift a test can see: as max_shift, but each mode's shift is the smaller of its shift to the best-MAC
    mode of `ref` over the measurable DOFs and to the best-MAC mode at the sensors (if that MAC is >= sensor_mac).
    The two differ where the effect changes the motion of unmeasured parts: a tie rod's tension changes its own
    wobble (most of X) but hardly the frame's modes at the sensors, and the X pairing then matches another mode."""
    if modes.unstable:
        return math.inf
    over_x = _paired_shifts(modes, ref, idx, modes.X, ref.X, min_mac)
    at_sensors = _paired_shifts(modes, ref, idx, modes.Y, ref.Y, sensor_mac)
    return max((min(s for s in pair if s is not None) for pair in zip(over_x, at_sensors) if pair != (None, None)),
               default=0.0)

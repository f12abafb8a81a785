#!/usr/bin/python3
"""Checks of the benchmark's FE code (fe.py) against closed-form results. Run: python3 test_fe.py

Each check states its tolerance; the meshes are fine enough that the discretisation error is far below it
(cubic Hermite beams converge as h^4 in frequency).
"""
import math
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fe  # noqa: E402
import testdata  # noqa: E402

E, RHO, NU = 2.1e11, 7850.0, 0.3
G = E / (2 * (1 + NU))
B, H = 0.04, 0.01
A, I = B * H, B * H**3 / 12
L = 1.0


def beam(n, supports, kappa=None, rotary=False, ndim=2, axial=False, length=L, height=H):
    """A straight beam along x of n elements; beam model (no axial DOFs) unless axial."""
    area, inertia = B * height, B * height**3 / 12
    m = fe.Model(ndim)
    for i in range(n + 1):
        m.node(i + 1, length * i / n, 0.0)
    for i in range(n):
        m.frame(i + 1, i + 2, E, G, area, inertia, RHO, Iy=inertia, J=inertia, kappa=kappa, rotary=rotary)
    if not axial:
        m.restrain_everywhere(["ux"])
    for node, dofs in supports:
        m.support(node if node > 0 else n + 1, dofs)
    return m


def rel(a, b):
    return abs(a / b - 1)


def eb_freq(beta_l, length=L):
    return beta_l**2 / (2 * math.pi * length**2) * math.sqrt(E * I / (RHO * A))


def check(name, got, want, tol):
    err = max(rel(g, w) for g, w in zip(got, want))
    print("       per mode:", " ".join(f"{rel(g, w):.1e}" for g, w in zip(got, want)))
    status = "ok" if err <= tol else "FAILED"
    print(f"{status:6s} {name}: max relative error {err:.2e} (tolerance {tol:.0e})")
    assert err <= tol, name


def test_euler_bernoulli():
    cant = [1.875104069, 4.694091133, 7.854757438, 10.99554073, 14.13716839]
    f, _ = fe.modal(beam(80, [(1, ["uy", "rz"])]).assemble(), 5)
    check("cantilever, 5 modes (80 elements)", f, [eb_freq(b) for b in cant], 3e-6)
    f, _ = fe.modal(beam(80, [(1, ["uy"]), (-1, ["uy"])]).assemble(), 5)
    check("simply supported, 5 modes", f, [eb_freq(n * math.pi) for n in range(1, 6)], 3e-6)
    ff = [4.730040745, 7.853204624, 10.99560784, 14.13716549, 17.27875966]
    f, _ = fe.modal(beam(80, []).assemble(), 7)
    assert f[0] < 1e-3 * f[2] and f[1] < 1e-3 * f[2], "free-free: two rigid-body modes first"
    check("free-free, 5 elastic modes", f[2:], [eb_freq(b) for b in ff], 3e-6)


def test_timoshenko():
    # Simply supported Timoshenko beam, L/h = 5 (h = 0.2 m): for w = W sin(kx), psi = P cos(kx) the equations
    # of motion give det [[rhoA w^2 - kGA k^2, kGA k], [kGA k, rhoI w^2 - EI k^2 - kGA]] = 0.
    h = 0.2
    area, inertia = B * h, B * h**3 / 12
    kappa = 10 * (1 + NU) / (12 + 11 * NU)
    kga = kappa * G * area
    want = []
    for n in range(1, 5):
        k = n * math.pi / L
        a2 = RHO * area * RHO * inertia
        a1 = -(RHO * area * (E * inertia * k**2 + kga) + kga * k**2 * RHO * inertia)
        a0 = kga * k**2 * (E * inertia * k**2 + kga) - (kga * k) ** 2
        w2 = min(np.roots([a2, a1, a0]).real)
        want.append(math.sqrt(w2) / (2 * math.pi))
    # The element's shear strain is constant, so its frequencies converge as h^2 (not h^4 as Euler-Bernoulli):
    # check the error at 200 elements and the convergence rate from 100 to 200.
    err = []
    for n in (100, 200):
        m = beam(n, [(1, ["uy"]), (-1, ["uy"])], kappa=kappa, rotary=True, height=h)
        f, _ = fe.modal(m.assemble(), 4)
        err.append(max(rel(a, b) for a, b in zip(f, want)))
    check("Timoshenko simply supported L/h = 5, 4 modes (200 elements)", f, want, 1e-4)
    check("Timoshenko convergence rate h^2 (error ratio 100 -> 200 elements)", [err[0] / err[1]], [4.0], 0.05)
    # Static: tip deflection of a Timoshenko cantilever under a tip load is exact for any mesh.
    m = beam(3, [(1, ["uy", "rz"])], kappa=kappa, height=h)
    asm = m.assemble()
    f = np.zeros(asm.K.shape[0])
    f[asm.dofs.index((4, 1))] = 1000.0
    u = np.linalg.solve(asm.K.toarray(), f)
    want = 1000.0 * L**3 / (3 * E * inertia) + 1000.0 * L / kga
    check("Timoshenko cantilever tip deflection (3 elements, exact)", [u[asm.dofs.index((4, 1))]], [want], 1e-10)


def test_geometric_and_static():
    # Pinned-pinned member (axial DOFs restrained at both ends) with an imposed shortening: the static analysis
    # gives N = -EA eps0, and with that tension the simply supported frequencies are exact:
    # w_n^2 = (EI k^4 + N k^2) / (rho A), k = n pi / L.
    m = beam(80, [(1, ["ux", "uy"]), (-1, ["ux", "uy"])], axial=True)
    for mb in m.members:
        mb.props["eps0"] = -2e-5
    N = m.static_axial_forces()
    check("imposed strain: axial force of a restrained member", [N[0], N[79]], [E * A * 2e-5] * 2, 1e-9)
    # Only bending modes: restrain ux everywhere (the axial force is fixed by the static analysis above).
    m2 = beam(80, [(1, ["uy"]), (-1, ["uy"])])
    f, _ = fe.modal(m2.assemble(axial=N), 4)
    want = [math.sqrt((E * I * (n * math.pi) ** 4 + N[0] * (n * math.pi) ** 2) / (RHO * A)) / (2 * math.pi)
            for n in range(1, 5)]
    check("simply supported beam in tension (geometric stiffness), 4 modes", f, want, 3e-6)
    # A clamped vertical column under its own weight: the axial force at the base is minus the weight.
    m = fe.Model(2)
    for i in range(11):
        m.node(i + 1, 0.0, 0.3 * i)
    for i in range(10):
        m.frame(i + 1, i + 2, E, G, A, I, RHO)
    m.support(1)
    N = m.gravity_axial_forces()
    check("self-weight: axial force in the base element", [N[0]], [-RHO * A * 3.0 * fe.GRAVITY * 0.95], 1e-9)


def test_space_frame():
    # A space cantilever along an oblique axis, with Iy != Iz: bending about each local axis and torsion.
    Iy, Iz, J = 3e-6, 1e-6, 5e-7
    axis = np.array([1.0, 2.0, 0.5]) / np.linalg.norm([1.0, 2.0, 0.5])
    orient = np.array([0.0, 0.3, 1.0])
    m = fe.Model(3)
    n = 30
    for i in range(n + 1):
        m.node(i + 1, *(axis * L * i / n))
    for i in range(n):
        m.frame(i + 1, i + 2, E, G, A, Iz, RHO, Iy=Iy, J=J, orientation=orient)
    m.support(1)
    f, _ = fe.modal(m.assemble(), 30)
    c = math.sqrt(1.0 / (RHO * A)) / (2 * math.pi * L**2)
    want = sorted([1.875104069**2 * c * math.sqrt(E * Iz), 1.875104069**2 * c * math.sqrt(E * Iy),
                   4.694091133**2 * c * math.sqrt(E * Iz), 4.694091133**2 * c * math.sqrt(E * Iy)])
    got = [min(f, key=lambda x: rel(x, w)) for w in want]  # torsion and axial modes lie in between
    check("space cantilever, first two bending modes about each axis", got, want, 1e-6)
    torsion = math.sqrt(G * J / (RHO * (Iy + Iz))) / (4 * L)
    check("space cantilever, first torsion mode", [min(f, key=lambda x: rel(x, torsion))], [torsion], 1e-3)


def test_offsets_and_solvers():
    # An eccentric point mass equals the same mass on a rigidly linked node; a bar with a rigid offset equals
    # the bar on a rigidly linked node; dense and sparse eigen-solvers agree.
    def base():
        m = beam(12, [(1, ["ux", "uy", "rz"])], axial=True)
        m.node(100, L + 0.1, 0.05)
        m.node(101, 0.5, -0.3)
        return m
    a = base()
    a.point_mass(13, 0.5, inertia=(0, 0, 1e-3), offset=(0.1, 0.05, 0.0))
    a.bar(101, 7, 1e6, offsets=(None, (0.0, -0.02, 0.0)))
    a.support(101)
    b = base()
    b.rigid_link(100, 13)
    b.point_mass(100, 0.5, inertia=(0, 0, 1e-3))
    b.node(102, 0.5, -0.02)
    b.rigid_link(102, 7)
    b.bar(101, 102, 1e6)
    b.support(101)
    fa, _ = fe.modal(a.assemble(), 8)
    fb, _ = fe.modal(b.assemble(), 8)
    check("eccentric mass and offset bar = rigid links", fa, fb, 1e-10)
    # Rounding limits the lowest eigenvalue to a relative accuracy of about eps * lambda_max / lambda_1
    # (1e-16 * 1e8 here, 100 elements); the truth models of the benchmark are no worse conditioned.
    asm = beam(100, [(1, ["uy", "rz"])]).assemble()
    fd, _ = fe.modal(asm, 10, dense=True)
    fs, _ = fe.modal(asm, 10, dense=False)
    check("dense and sparse eigen-solvers (200 DOFs)", fs, fd, 1e-8)


def test_plane_stress():
    # A deep simply supported beam (L/h = 5) as a plane-stress Q9 continuum, its end faces held vertically
    # (uy = 0 over the face, free to rotate: w = 0, M = 0; a point support would be singular in 2D elasticity),
    # against the Timoshenko beam with Cowper's kappa = 10 (1 + nu) / (12 + 11 nu): beam theory, not an exact
    # solution, so the tolerance is 1 % (first four bending modes).
    h, nx, ny = 0.2, 40, 4
    m = fe.Model(2)
    ids = {}
    for j in range(2 * ny + 1):
        for i in range(2 * nx + 1):
            ids[i, j] = len(ids) + 1
            m.node(ids[i, j], L * i / (2 * nx), h * j / (2 * ny) - h / 2)
    for ex in range(nx):
        for ey in range(ny):
            m.quad9([ids[2 * ex + i, 2 * ey + j] for j in range(3) for i in range(3)], L / nx, h / ny, E, NU, B,
                    RHO)
    for j in range(2 * ny + 1):
        m.support(ids[0, j], ["uy"])
        m.support(ids[2 * nx, j], ["uy"])
    m.support(ids[0, ny], ["ux"])
    f, phi = fe.modal(m.assemble(), 12)
    kappa = 10 * (1 + NU) / (12 + 11 * NU)
    t = beam(200, [(1, ["uy"]), (-1, ["uy"])], kappa=kappa, rotary=True, height=h)
    ft, _ = fe.modal(t.assemble(), 4)
    # Pick the continuum's bending modes (vertical motion of the mid-height line dominates).
    asm = m.assemble()
    mid = asm.rows([(ids[i, ny], 1) for i in range(2 * nx + 1)])
    ax = asm.rows([(ids[i, ny], 0) for i in range(2 * nx + 1)])
    bend = [f[k] for k in range(len(f)) if np.abs(phi[mid, k]).max() > 3 * np.abs(phi[ax, k]).max()][:4]
    check("plane-stress deep beam vs Timoshenko (Cowper kappa)", bend, ft, 1e-2)
    # The kappa that makes the Timoshenko beam match the continuum's first mode.
    def err(k):
        tb = beam(200, [(1, ["uy"]), (-1, ["uy"])], kappa=k, rotary=True, height=h)
        return fe.modal(tb.assemble(), 1)[0][0] - bend[0]
    k_fit = brentq(err, 0.5, 1.2, xtol=1e-4)
    print(f"       kappa fitted to the continuum's first mode: {k_fit:.4f} (Cowper {kappa:.4f})")


def test_modal_response():
    # The recordings' modal superposition is exact for a force linear between samples: the acceleration of a
    # single mode under a unit step, x'' = exp(-s t) (cos wd t - (s / wd) sin wd t), s = zeta w, wd = w sqrt(1 - zeta^2).
    f, zeta, fs, n = 7.3, 0.03, 50.0, 400
    force = np.ones((1, n))
    force[0, 0] = 0.0          # the step rises linearly over the first sample interval
    acc = testdata.modal_response(np.array([f]), np.array([zeta]), np.ones((1, 1)), np.ones((1, 1)), force, fs)[0]
    w = 2 * math.pi * f
    s, wd = zeta * w, w * math.sqrt(1 - zeta**2)
    t = np.arange(n) / fs
    # Ramp over [0, dt] then constant: superpose (1/dt) x (integral of the step response) shifted by 0 and dt.
    def ramp_acc(tt):     # acceleration under a unit-slope ramp force: the velocity response to a unit step
        return np.where(tt > 0, np.exp(-s * tt) * np.sin(wd * tt) / wd, 0.0)
    dt = 1 / fs
    want = (ramp_acc(t) - ramp_acc(t - dt)) / dt
    err = np.abs(acc - want).max() / np.abs(want).max()
    print(f"{'ok' if err <= 1e-9 else 'FAILED':6s} modal superposition, one mode under a ramped step: error {err:.1e} of the "
          f"peak (tolerance 1e-09)")
    assert err <= 1e-9


if __name__ == "__main__":
    test_euler_bernoulli()
    test_timoshenko()
    test_geometric_and_static()
    test_space_frame()
    test_offsets_and_solvers()
    test_plane_stress()
    test_modal_response()
    print("all FE checks passed")

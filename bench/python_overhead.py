#!/usr/bin/python3
"""Calling dynid from Python against the command line (issue 18's targets; results in bench/README.md):

  1. modal() on a ~50,000-DOF 3D frame (a generated case, 20 lowest modes): the same work as `dynid modal CASE`,
     timed as whole processes (start, read the case, solve) and, inside Python, the modal() call alone against the
     solver's own timings; target: Python within 5 % of the command line.
  2. A Python loop of 1,000 residual-force evaluations (eq. 6) on the paper frame: target under 1 s.

  PYTHONPATH=build/python python3 bench/python_overhead.py [--cli build/cli/dynid] [--runs 5] [--quick]
--quick uses a 6,000-DOF frame and 100 evaluations (the ctest smoke run).
"""
import argparse
import json
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import dynid

ROOT = pathlib.Path(__file__).resolve().parents[1]


def cpu():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip() + f", {os.cpu_count()} cores"
    except OSError:
        pass
    return platform.processor()


def frame_case(path, quick):
    # 3D frame 20x20x20 (52,920 DOF) as in bench/README.md's scaling table; --quick: 8x8x5 (2,880 DOF... times 2).
    bays, stories = (6, 6) if quick else (20, 20)
    path.write_text(f"""name: frame3d-{bays}x{bays}x{stories}
model:
  element: frame3d
  materials: {{steel: {{E: 2.1e11, rho: 7850, nu: 0.3}}}}
  sections:
    column: {{A: 1.49e-2, Iy: 2.52e-4, Iz: 8.56e-5, J: 1.85e-6}}
    beam: {{A: 8.45e-3, Iy: 2.31e-4, Iz: 1.32e-5, J: 5.1e-7}}
  generate:
    frame3d: {{bays_x: {bays}, bays_y: {bays}, stories: {stories}, divisions: 1, span_x: 6, span_y: 6, height: 3.5,
              material: steel, column: column, beam: beam}}
analysis: {{modes: 20}}
""")


def timed(cmd, env):
    t = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default=str(ROOT / "build" / "cli" / "dynid"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    env = dict(os.environ)
    print(f"machine: {cpu()}; Python {platform.python_version()}, NumPy {np.__version__}; dynid {dynid.__version__}")
    with tempfile.TemporaryDirectory() as d:
        case = pathlib.Path(d) / "frame.yaml"
        frame_case(case, a.quick)
        c = dynid.load_case(case)
        print(f"model: {c.name}, {c.model.num_dofs} DOFs, 20 lowest modes")
        cli, py = [], []
        code = f"import dynid; dynid.modal(dynid.load_case({str(case)!r}))"
        for _ in range(a.runs):  # interleaved, so that load on the machine affects both alike
            cli.append(timed([a.cli, "--quiet", "modal", str(case)], env))
            py.append(timed([sys.executable, "-c", code], env))
        calls, solver = [], []
        for _ in range(a.runs):
            t = time.perf_counter()
            r = dynid.modal(c)
            calls.append(time.perf_counter() - t)
            s = r["solver"]
            solver.append(s["time_assembly_s"] + s["time_factorize_s"] + s["time_lanczos_s"])
        mc, mp = statistics.median(cli), statistics.median(py)
        # Each Python run against the command-line run just before it: the machine's drift cancels in the pair.
        pairs = sorted(100 * (p / c - 1) for c, p in zip(cli, py))
        q = statistics.quantiles(pairs, n=4) if len(pairs) > 1 else [pairs[0]] * 3
        print(f"1. modal, whole process (start, read case, solve), median of {a.runs}: command line {mc:.3f} s, "
              f"Python {mp:.3f} s: {100 * (mp / mc - 1):+.1f} % (target within 5 %); paired runs: median "
              f"{q[1]:+.1f} %, quartiles {q[0]:+.1f} to {q[2]:+.1f} %, {sum(x <= 5 for x in pairs)} of {len(pairs)} within 5 %")
        print(f"   modal() call in Python {statistics.median(calls):.3f} s; of which the engine's assembly + factorization "
              f"+ Lanczos {statistics.median(solver):.3f} s; results moved to NumPy without copying")
    # 2. Residual forces on the paper frame, the SHM loop's inner step.
    frame = dynid.load_case(ROOT / "cases" / "paper-frame")
    changed = frame.model.changed({9: (-0.15, 0.0)})
    m = dynid.modal(changed, modes=4)
    lam, phi = m["eigenvalues"], m["shapes"]
    n = 100 if a.quick else 1000
    op = dynid.ResidualForces(frame.model)
    t = time.perf_counter()
    for _ in range(n):
        R = op(lam, phi)
    t_op = time.perf_counter() - t
    K, M = frame.model.matrices()
    t = time.perf_counter()
    for _ in range(n):
        R2 = dynid.residual_forces(K, M, lam, phi)
    t_fn = time.perf_counter() - t
    assert np.array_equal(R, R2)
    print(f"2. {n} residual-force evaluations on the paper frame (60 DOFs, 4 modes): ResidualForces operator "
          f"{t_op:.3f} s ({1e6 * t_op / n:.1f} us each); residual_forces(K, M, ...) from SciPy matrices {t_fn:.3f} s "
          f"({1e6 * t_fn / n:.1f} us each, converting K and M every call) (target: 1,000 under 1 s)")
    ok = statistics.median(pairs) <= 5 and t_op * 1000 / n < 1.0
    print("targets met" if ok else "a target is NOT met")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The GIL is released during long solves (other Python threads run), and results do not depend on threads."""
import threading
import time

import numpy as np

import dynid


def big_frame():
    """A 3D space frame of about 20 000 DOFs, built from arrays."""
    nx, ny, nz = 12, 12, 24
    idx = lambda i, j, k: 1 + i + (nx + 1) * (j + (ny + 1) * k)
    xyz = np.array([[i, j, k] for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)], dtype=float)
    el = []
    for k in range(nz + 1):
        for j in range(ny + 1):
            for i in range(nx + 1):
                if i < nx: el.append([idx(i, j, k), idx(i + 1, j, k)])
                if j < ny: el.append([idx(i, j, k), idx(i, j + 1, k)])
                if k < nz: el.append([idx(i, j, k), idx(i, j, k + 1)])
    base = [idx(i, j, 0) for j in range(ny + 1) for i in range(nx + 1)]
    return dynid.Model.from_arrays(xyz, np.array(el, dtype=float), element="frame3d",
                                   materials={"steel": {"E": 2.1e11, "rho": 7850, "nu": 0.3}},
                                   sections={"s": {"A": 1e-2, "Iy": 1e-4, "Iz": 1e-4, "J": 2e-4}},
                                   supports=[{"nodes": base, "fix": "all"}])


def test_gil_released_during_modal():
    model = big_frame()
    assert model.num_dofs > 15000
    counter = [0]
    done = threading.Event()

    def spin():
        while not done.is_set():
            counter[0] += 1
            time.sleep(0.001)

    t = threading.Thread(target=spin)
    t.start()
    t0 = time.perf_counter()
    r = dynid.modal(model, modes=10)
    elapsed = time.perf_counter() - t0
    done.set()
    t.join()
    assert r["ok"]
    # With the GIL held the spinning thread would not run at all during the solve; released, it ticks about
    # once per millisecond.
    assert counter[0] >= 0.2 * elapsed / 0.001, (counter[0], elapsed)


def test_same_results_whatever_the_thread_count(paper_frame):
    res = []
    for n in (1, 2):
        dynid.set_threads(n)
        res.append((dynid.modal(paper_frame, modes=6)["eigenvalues"],))
    # Eigenvalues to rounding (the dense LAPACK path's BLAS blocks by thread); residual forces exactly (each entry
    # one sum in a fixed order, solvers/sparse.hpp) for the same input.
    np.testing.assert_allclose(res[0][0], res[1][0], rtol=1e-9)
    r = dynid.modal(paper_frame, modes=6)
    op = dynid.ResidualForces(paper_frame.changed({9: (-0.1, 0.0)}))
    dynid.set_threads(1)
    R1 = op(r["eigenvalues"], r["shapes"])
    dynid.set_threads(2)
    R2 = op(r["eigenvalues"], r["shapes"])
    np.testing.assert_array_equal(R1, R2)

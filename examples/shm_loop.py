"""An SHM-style loop over many measurements (docs/python.md): one identified modal data set per "day", the
residual-force index of each against the baseline model, an alarm when it leaves its healthy band, then
localization of what changed.

The measurements are simulated: the paper frame's first four modes at the horizontal sensors, with 0.1 %
frequency noise and 0.5 % shape noise; from day 60 the third-story outer column (element 9) loses stiffness
slowly (0.4 % a day). One ResidualForces operator serves every evaluation (assembled once).

Run:  PYTHONPATH=build/python python3 examples/shm_loop.py
"""
import numpy as np

import dynid

rng = np.random.default_rng(7)
xy = np.array([[x, y] for y in range(6) for x in range(4)], dtype=float)
columns = [[1 + 4 * s + line, 5 + 4 * s + line] for s in range(5) for line in range(4)]
beams = [[5 + 4 * f + 2 * side, 6 + 4 * f + 2 * side] for f in range(5) for side in range(2)]
model = dynid.Model.from_arrays(xy, np.array(columns + beams + [[22, 23]], dtype=float),
                                materials={"steel": {"E": 210.0e9, "rho": 7800}},
                                sections={"member": {"A": 9.0e-5, "I": 2.0e-10}},
                                supports=[{"nodes": [1, 2, 3, 4], "fix": "all"}])
sensors = [f"{n}ux" for n in range(5, 25)]
baseline = dynid.modal(model, modes=4)
R_op = dynid.ResidualForces(model)
masters = model.equations(sensors)


def measure(day):
    """The modes of the day's structure at the sensors, with measurement noise."""
    loss = max(0.0, 0.004 * (day - 60))
    m = model.changed({9: (-loss, 0.0)}) if loss > 0 else model
    r = dynid.modal(m, modes=4)
    data = dynid.sample_modes(m, r, sensors)
    data["frequency_hz"] = data["frequency_hz"] * (1 + 1e-3 * rng.standard_normal(4))
    data["shapes"] = data["shapes"] + 5e-3 * np.abs(data["shapes"]).max(axis=0) * rng.standard_normal(data["shapes"].shape)
    return data, loss


def index(data):
    """Residual-force index: the measured modes expanded to all DOFs by SEREP of the baseline, eq. (6) on the model,
    relative to the modal forces."""
    s = dynid.serep(baseline["shapes"], baseline["eigenvalues"], masters)
    full = s["T"] @ data["shapes"]
    lam = (2 * np.pi * data["frequency_hz"]) ** 2
    R = R_op(lam, full)
    return np.linalg.norm(R) / np.linalg.norm(R_op.M @ full * lam)


healthy = [index(measure(day)[0]) for day in range(30)]
limit = np.mean(healthy) + 4 * np.std(healthy)
print(f"healthy band: index {np.mean(healthy):.3e} +- {np.std(healthy):.1e}; alarm above {limit:.3e}")
alarm_day = None
for day in range(30, 160):
    data, loss = measure(day)
    if index(data) > limit:
        alarm_day = day
        print(f"day {day}: alarm (true stiffness loss of element 9: {100 * loss:.1f} %)")
        break
assert alarm_day is not None and alarm_day > 60, alarm_day
d = dynid.detect(model, data, modes=4, noise={"frequency": 1e-3, "shape": 5e-3})
top = d["localization"]["elements"][0]
print(f"detect: most likely element {top['id']} (probability {top['score']:.2f}); confidence set {d['localization']['confidence_set']}")
assert 9 in d["localization"]["confidence_set"]

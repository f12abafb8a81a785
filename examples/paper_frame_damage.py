"""The paper frame's damage from Python, step by step (docs/python.md, "A complete example").

The frame is built from NumPy arrays, element 28 loses 15 % of its stiffness and mass (Table 3, case 3), its
exact modes are "measured" at every DOF, and the damage is located (residual forces, eqs. 6-8), quantified (the
paper's first-order estimate and dynid's refinement) and confirmed by updating two parameters.

Run:  PYTHONPATH=build/python python3 examples/paper_frame_damage.py
"""
import numpy as np

import dynid

# 1. The model: 24 nodes on a 1 m grid (4 x 6), 20 columns, 10 beams and a connector at the roof.
xy = np.array([[x, y] for y in range(6) for x in range(4)], dtype=float)
columns = [[1 + 4 * s + line, 5 + 4 * s + line] for s in range(5) for line in range(4)]
beams = [[5 + 4 * f + 2 * side, 6 + 4 * f + 2 * side] for f in range(5) for side in range(2)]
elements = np.array(columns + beams + [[22, 23]], dtype=float)
model = dynid.Model.from_arrays(xy, elements, element="frame2d",
                                materials={"steel": {"E": 210.0e9, "rho": 7800}},
                                sections={"member": {"A": 9.0e-5, "I": 2.0e-10}},
                                supports=[{"nodes": [1, 2, 3, 4], "fix": "all"}])
print(model)
modes = dynid.modal(model, modes=8)
print("frequencies (Hz):", np.round(modes["frequency_hz"][:4], 4))

# 2. The damaged structure and its "measured" modes: the first four, at every DOF.
damaged = model.changed({28: (-0.15, -0.15)})
measured = dynid.sample_modes(damaged, dynid.modal(damaged, modes=4), "all")
print("measured (Hz):   ", np.round(measured["frequency_hz"], 4))

# 3. Residual forces of the measured modes on the model (eq. 6) and the pseudo residual force (eqs. 7-8).
R = dynid.ResidualForces(model)((2 * np.pi * measured["frequency_hz"]) ** 2, measured["shapes"])
pseudo = dynid.pseudo_residual_force(R)
top = np.argsort(pseudo)[::-1][:6]
print("largest pseudo residual forces at:", [model.dofs[i] for i in top])

# 4. Detection: located and quantified (the paper's Table 3 and dynid's refinement).
d = dynid.detect(model, measured, modes=4, simulated_changed=damaged)
q = d["quantification"][0]
print(f"detect: element {q['element']} flagged; dk {q['dk']:+.4f} (first order {q['dk_first_order']:+.4f}), "
      f"dm {q['dm']:+.4f} (first order {q['dm_first_order']:+.4f})")
assert q["element"] == 28 and abs(q["dk"] + 0.15) < 1e-4 and abs(q["dm"] + 0.15) < 1e-4

# 5. Updating: E and rho of element 28, fitted to the measured modes.
u = dynid.update(model, measured, objective="combined",
                 parameters=[{"name": "E28", "factor": "E", "elements": [28]},
                             {"name": "rho28", "factor": "rho", "elements": [28]}])
for p in u["parameters"]:
    print(f"update: {p['name']} = {p['value']:.5f}")
assert all(abs(p["value"] - 0.85) < 1e-4 for p in u["parameters"])

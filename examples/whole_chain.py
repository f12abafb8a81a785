"""The whole chain in one script, nothing written to disk: a model from arrays, a virtual impact test of a
damaged copy, identification of its recordings (LSCF), then detection, updating and discovery on the model
(docs/python.md). python/tests/test_chain.py runs the same chain against the command line.

Run:  PYTHONPATH=build/python python3 examples/whole_chain.py
"""
import numpy as np

import dynid

xy = np.array([[x, y] for y in range(6) for x in range(4)], dtype=float)
columns = [[1 + 4 * s + line, 5 + 4 * s + line] for s in range(5) for line in range(4)]
beams = [[5 + 4 * f + 2 * side, 6 + 4 * f + 2 * side] for f in range(5) for side in range(2)]
elements = np.array(columns + beams + [[22, 23]], dtype=float)
sections = {"member": {"A": 9.0e-5, "I": 2.0e-10}}
supports = [{"nodes": [1, 2, 3, 4], "fix": "all"}]
model = dynid.Model.from_arrays(xy, elements, materials={"steel": {"E": 210.0e9, "rho": 7800}}, sections=sections,
                                supports=supports)
# The structure as built: column 9 is 15 % less stiff than designed.
truth = dynid.Model.from_arrays(xy, elements, materials={"steel": {"E": 210.0e9, "rho": 7800}, "steel85": {"E": 178.5e9, "rho": 7800}},
                                sections=sections, supports=supports,
                                element_material=["steel85" if k == 9 else "steel" for k in range(1, 32)])

# A roving-hammer test: 40 accelerometers, hits at 17ux and 20ux, 2 % noise.
test = dynid.simulate_test(truth, sensors="translations", excitation="impact", inputs=["17ux", "20ux"],
                           sample_rate_hz=25.6, duration_s=120, impacts=3, band_hz=[0, 10], damping={"modal": 0.01},
                           noise=0.02, force_noise=0.02, seed=7)
rec = test["recordings"][0]
print(f"recordings: {len(test['recordings'])} hammer locations, {len(rec['records'])} hits each, "
      f"{rec['records'][0].shape[0]} samples x {rec['records'][0].shape[1]} channels at {rec['sample_rate_hz']} Hz")

ident = dynid.identify(test["recordings"], method="lscf", band_hz=[0.3, 8])
print("identified (Hz):", [round(m["frequency_hz"], 4) for m in ident["modes"]])
print("truth (Hz):     ", np.round(test["truth"]["frequency_hz"][:len(ident["modes"])], 4))

d = dynid.detect(model, ident, modes=4, noise={"frequency": 0.002, "shape": 0.03})
print("detect: ranking", [e["id"] for e in d["localization"]["elements"][:3]], "confidence set", d["localization"]["confidence_set"])

u = dynid.update(model, ident, modes=4, objective="combined", noise={"frequency": 0.002, "shape": 0.03},
                 parameters=[{"name": "E9", "factor": "E", "elements": [9]}, {"name": "E10", "factor": "E", "elements": [10]}])
print("update:", {p["name"]: round(p["value"], 3) for p in u["parameters"]})

disc = dynid.discover(model, ident, kinds=["element_stiffness", "element_mass", "lumped_mass"], frequency_noise=0.002, shape_noise=0.03)
print("discover:", disc["verdict"], "-", disc["findings"][0]["description"] if disc["findings"] else "no finding")
assert 9 in d["localization"]["confidence_set"]
assert abs(next(p["value"] for p in u["parameters"] if p["name"] == "E9") - 0.85) < 0.05

"""A real structure from MATLAB files: the SMU package's steel pedestrian bridge (SAP2000 export; 946 DOFs, 17
stiffness influence matrices and a mass matrix in a MATLAB 5.0 file; ../shared/data/real/gt-pedestrian-bridge).
The model is built from the file's variables, its modes compared with the five identified ones.

Run:  PYTHONPATH=build/python python3 examples/bridge_mat.py
"""
import os
import pathlib
import sys

import numpy as np

import dynid

shared = pathlib.Path(os.environ.get("DYNID_SHARED_DIR", pathlib.Path(__file__).resolve().parents[2] / "shared"))
d = shared / "data" / "real" / "gt-pedestrian-bridge"
if not d.is_dir():
    print(f"skipped: {d} not found (the shared data)")
    sys.exit(0)
f = d / "SteelPedestrianBridgeExp.mat"
print(dynid.mat_version(f), "-", len(dynid.mat_variables(f)), "variables")
groups = ["K_Frame", "K_Truss"] + [f"K_Conc{k}" for k in range(1, 12)] + ["K_y1", "K_z1", "K_y2", "K_z2"]
model = dynid.Model.from_mat(f, K="K_whole", M="M0", groups=groups)
print(model)
r = dynid.modal(model, modes=5)
e = d / "ExpModeInfo_FEM.mat"
measured_hz = np.sqrt(dynid.read_mat(e, "lambdaExp").ravel()) / (2 * np.pi)
sensors = dynid.read_mat(f, "measDOFs").ravel().astype(int) - 1
mac = dynid.mac(dynid.read_mat(e, "psiExp_m"), r["shapes"][sensors, :])
pairs = dynid.pair_modes(mac, measured_hz, r["frequency_hz"])
print("measured Hz   model Hz   error %   MAC")
for p in pairs["pairs"]:
    fm, fa = measured_hz[p["a"]], r["frequency_hz"][p["b"]]
    print(f"{fm:10.3f}  {fa:9.3f}  {100 * (fa / fm - 1):+7.1f}  {p['mac']:.3f}")

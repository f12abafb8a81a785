"""Quick start: the paper's five-story frame (Table 2) and its damaged element (Table 3) from Python.

Run (after scripts/setup.sh):  PYTHONPATH=build/python python3 examples/quickstart.py
"""
import pathlib

import dynid

cases = pathlib.Path(__file__).resolve().parents[1] / "cases"
frame = dynid.load_case(cases / "paper-frame")
r = dynid.modal(frame)
print("Table 2 (Hz):", r["frequency_hz"][:4])          # 0.6496 1.5019 2.0748 3.2737

d = dynid.detect(dynid.load_case(cases / "paper-frame-damage" / "element9-case1.yaml"))
q = d["quantification"][0]
print(f"Table 3: element {q['element']} changed by dk = {q['dk']:+.4f}, dm = {q['dm']:+.4f} "
      f"(first order {q['dk_first_order']:+.4f}, {q['dm_first_order']:+.4f})")
assert abs(r["frequency_hz"][0] - 0.6496) < 1e-4 and q["element"] == 9

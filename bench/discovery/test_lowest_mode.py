#!/usr/bin/python3
"""An impact test's lowest mode near the bottom of the band discovery takes from the model (0.6 x the model's lowest
visible mode) is identified where it is: LSCF fits impacts from half the band's bottom (docs/method.md, "LSCF's
lowest lines"). Regression check on one generated case of the dev split (index 221: a null case, a linked frame
hit at two places, 27 accelerometers, band 1.78-44.6 Hz), where the truth's lowest mode is at 2.9667 Hz: fitted
from the band's bottom, its cluster stood on 0.3 of the orders at 2.9036 Hz (2.1 % low), was kept because its
shape matched the model's, and discovery named an attached mass of 577 kg.

Usage: test_lowest_mode.py DYNID [WORKDIR]   (exit 0 when every check holds; ctest bench.discovery_lowest_mode)
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import run  # noqa: E402


def checks(sc, truth, result):
    failures = []
    f1 = min(m["frequency_hz"] for m in truth["modes"] if not m.get("suspension"))
    measured = [m["frequency_hz"] for m in result["measured"]["modes"]]
    print(f"truth's lowest mode {f1:.4f} Hz; measured {[round(f, 4) for f in measured]}")
    # Within 0.5 %: the identification benchmark's "found" (the other modes here are 0.01-0.3 % off).
    if not any(abs(f / f1 - 1) < 5e-3 for f in measured):
        failures.append(f"no measured mode within 0.5 % of the truth's lowest mode at {f1:.4f} Hz")
    print("dynid said:", sc["said"])
    if not sc["null_right"]:
        failures.append("the null case is not called consistent")
    return failures


if __name__ == "__main__":
    sys.exit(run.regression_check(221, checks, "dynid-lowest-"))

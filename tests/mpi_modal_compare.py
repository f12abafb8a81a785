#!/usr/bin/python3
"""`mpirun -n 2 dynid modal CASE` against `dynid modal CASE` (ctest cli.modal_mpi2).

    mpi_modal_compare.py DYNID CASE WORKDIR MPIEXEC [MPIEXEC ARGS...]

Runs both, with --json, and checks: both succeed; the distributed run says it used 2 ranks; the same number of
modes, the same rigid-body flags; every eigenvalue to 1e-10 relative (the issue's requirement; both solve to a
Ritz tolerance of 1e-10 and agree far closer on this model); every relative eigen-residual of the distributed
run <= 1e-10. The shapes are compared by MAC in tests/test_distributed.cpp (the JSON holds none).
"""
import json, os, subprocess, sys

def run(cmd, out):
    if os.path.exists(out):
        os.remove(out)
    p = subprocess.run(cmd + ["--json", out, "-v"], capture_output=True, text=True, timeout=280)
    print("$", " ".join(cmd), "-> exit", p.returncode)
    print(p.stdout[-3000:], p.stderr[-3000:])
    if p.returncode != 0:
        sys.exit("failed: " + " ".join(cmd))
    with open(out) as f:
        return json.load(f), p.stdout

def main():
    dynid, case, work, mpiexec = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    serial, _ = run([dynid, "modal", case], os.path.join(work, "modal-serial.json"))
    dist, text = run(mpiexec + [dynid, "modal", case], os.path.join(work, "modal-mpi2.json"))
    bad = []
    if "2 ranks" not in dist["solver"]["method"]:
        bad.append("the distributed run's method is '%s', not a 2-rank one" % dist["solver"]["method"])
    a, b = serial["modes"], dist["modes"]
    if len(a) != len(b):
        bad.append("%d modes serial, %d distributed" % (len(a), len(b)))
    worst = 0.0
    for x, y in zip(a, b):
        if x["rigid_body"] != y["rigid_body"]:
            bad.append("mode %d: rigid-body flags differ" % x["index"])
        if not x["rigid_body"]:
            d = abs(x["eigenvalue"] - y["eigenvalue"]) / abs(x["eigenvalue"])
            worst = max(worst, d)
            if d > 1e-10:
                bad.append("mode %d: eigenvalue %.17g serial, %.17g distributed (rel. %.2e > 1e-10)"
                           % (x["index"], x["eigenvalue"], y["eigenvalue"], d))
        if y["residual"] > 1e-10:
            bad.append("mode %d: distributed residual %.2e > 1e-10" % (y["index"], y["residual"]))
    print("largest relative eigenvalue difference: %.2e over %d modes" % (worst, len(a)))
    if bad:
        sys.exit("\n".join(bad))
    print("ok")

if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Peer eigen-solvers on the same K and M as dynid (Matrix Market files), for bench/scaling.

    peers.py scipy K.mtx M.mtx --nev 20 --sigma 0
    peers.py slepc K.mtx M.mtx --nev 20 --sigma 0          (PETSc's Cholesky through CHOLMOD)
    peers.py slepc-mumps K.mtx M.mtx --nev 20 --sigma 0    (PETSc's Cholesky through MUMPS)

Prints one JSON line: peer, solve time (factorization + Lanczos, file reading excluded), load time, peak
resident memory of the process (MB), the eigenvalues found. Uses Debian's python3-scipy and python3-slepc4py
(run with /usr/bin/python3).
"""
import argparse, json, os, resource, sys, time

def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("peer", choices=["scipy", "slepc", "slepc-mumps"])
    ap.add_argument("K")
    ap.add_argument("M")
    ap.add_argument("--nev", type=int, default=20)
    ap.add_argument("--sigma", type=float, default=0.0)
    ap.add_argument("--tol", type=float, default=1e-10)
    a = ap.parse_args()
    import numpy as np, scipy.io, scipy.sparse
    t0 = time.perf_counter()
    K = scipy.sparse.csr_matrix(scipy.io.mmread(a.K))
    M = scipy.sparse.csr_matrix(scipy.io.mmread(a.M))
    t_load = time.perf_counter() - t0
    t0 = time.perf_counter()
    if a.peer == "scipy":
        from scipy.sparse.linalg import eigsh
        vals = eigsh(K.tocsc(), k=a.nev, M=M.tocsc(), sigma=a.sigma, which="LM", tol=a.tol,
                     return_eigenvectors=True)[0]
        detail = "scipy.sparse.linalg.eigsh (ARPACK, SuperLU shift-invert)"
    else:
        os.environ.setdefault("PETSC_DIR", "/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real")
        os.environ.setdefault("SLEPC_DIR", "/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-real")
        for d in (os.environ["PETSC_DIR"], os.environ["SLEPC_DIR"]):
            sys.path.append(os.path.join(d, "lib/python3/dist-packages"))
        import petsc4py
        petsc4py.init([])
        import slepc4py
        slepc4py.init([])
        from petsc4py import PETSc
        from slepc4py import SLEPc
        def mat(A):
            A = A.tocsr()
            m = PETSc.Mat().createAIJ(size=A.shape, csr=(A.indptr, A.indices, A.data))
            m.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            m.assemble()
            return m
        PK, PM = mat(K), mat(M)
        eps = SLEPc.EPS().create()
        eps.setOperators(PK, PM)
        eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        eps.setDimensions(a.nev)
        eps.setTolerances(a.tol, 1000)
        eps.setTarget(a.sigma)
        eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
        st = eps.getST()
        st.setType(SLEPc.ST.Type.SINVERT)
        st.setShift(a.sigma)
        ksp = st.getKSP()
        ksp.setType(PETSc.KSP.Type.PREONLY)
        pc = ksp.getPC()
        pc.setType(PETSc.PC.Type.CHOLESKY)
        pc.setFactorSolverType("mumps" if a.peer == "slepc-mumps" else "cholmod")
        eps.solve()
        n = eps.getConverged()
        vals = np.array(sorted(eps.getEigenvalue(i).real for i in range(n)))[: a.nev]
        detail = "SLEPc Krylov-Schur, shift-and-invert, PETSc Cholesky via " + (
            "MUMPS" if a.peer == "slepc-mumps" else "CHOLMOD")
    t_solve = time.perf_counter() - t0
    print(json.dumps({"peer": a.peer, "detail": detail, "time_s": t_solve, "load_s": t_load,
                      "peak_rss_mb": peak_mb(), "eigenvalues": sorted(float(v) for v in vals)}))

if __name__ == "__main__":
    main()

"""Models from arrays and matrices against the case files, and a round trip through SciPy."""
import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
import scipy.sparse.linalg as sla

import dynid
from conftest import PAPER_MATERIALS, PAPER_SECTIONS, paper_frame_arrays


def test_arrays_equal_the_case_file(cases, paper_frame):
    case = dynid.load_case(cases / "paper-frame").model
    assert paper_frame.dofs == case.dofs
    np.testing.assert_array_equal(paper_frame.coordinates, case.coordinates)
    np.testing.assert_array_equal(paper_frame.element_nodes, case.element_nodes)
    Ka, Ma = paper_frame.matrices()
    Kc, Mc = case.matrices()
    # The same elements assembled in the same order: bitwise equal.
    assert (Ka != Kc).nnz == 0 and (Ma != Mc).nnz == 0
    fa = dynid.modal(paper_frame, modes=8)["frequency_hz"]
    fc = dynid.modal(case, modes=8)["frequency_hz"]
    np.testing.assert_array_equal(fa, fc)


def test_arrays_options_and_errors():
    xy, el = paper_frame_arrays()
    with pytest.raises(dynid.InputError, match="element 3: node 99.0 does not exist|node 99"):
        bad = el.copy()
        bad[2, 1] = 99
        dynid.Model.from_arrays(xy, bad, materials=PAPER_MATERIALS, sections=PAPER_SECTIONS, supports={1: "all"})
    with pytest.raises(dynid.InputError, match="not supported against"):
        dynid.Model.from_arrays(xy, el, materials=PAPER_MATERIALS, sections=PAPER_SECTIONS)
    with pytest.raises(dynid.InputError, match="unknown option 'suports'"):
        dynid.Model.from_arrays(xy, el, materials=PAPER_MATERIALS, sections=PAPER_SECTIONS, suports={1: "all"})
    with pytest.raises(dynid.InputError, match="nodes must be an"):
        dynid.Model.from_arrays(np.zeros((4, 5)), el, materials=PAPER_MATERIALS, sections=PAPER_SECTIONS)


def test_matrices_equal_the_model(paper_frame):
    """Element matrices exported from the model and read back as matrix elements give the same K, M, modes."""
    dofs = paper_frame.dofs
    elements = []
    for eid in paper_frame.element_ids:
        e = paper_frame.element_matrices(int(eid))
        keep = [k for k, q in enumerate(e["equations"]) if q >= 0]  # restrained DOFs are eliminated
        elements.append({"id": int(eid), "dofs": [e["equations"][k] for k in keep],
                         "K": e["K"][np.ix_(keep, keep)], "M": e["M"][np.ix_(keep, keep)]})
    nodes = np.column_stack([paper_frame.node_ids, paper_frame.coordinates])
    m = dynid.Model.from_matrices(dofs=dofs, nodes=nodes, elements=elements)
    K1, M1 = paper_frame.matrices()
    K2, M2 = m.matrices()
    assert abs(K1 - K2).max() <= 1e-15 * abs(K1).max()
    assert abs(M1 - M2).max() <= 1e-15 * abs(M1).max()
    np.testing.assert_allclose(dynid.modal(m, modes=6)["frequency_hz"], dynid.modal(paper_frame, modes=6)["frequency_hz"], rtol=1e-12)
    # The assembled K and M alone (one remainder element) and as groups of columns and beams.
    K, M = paper_frame.matrices()
    groups = dynid.Model.from_matrices(dofs=dofs, nodes=nodes, groups={"all": (K, M)})
    np.testing.assert_allclose(dynid.modal(groups, modes=6)["frequency_hz"], dynid.modal(paper_frame, modes=6)["frequency_hz"], rtol=1e-12)


def test_eigsh_round_trip_on_exported_matrices(cases, cli, tmp_path):
    """dynid export-matrices writes K.mtx, M.mtx; SciPy's eigsh on them agrees with dynid's modes to 1e-8."""
    cli("export-matrices", cases / "paper-frame", tmp_path / "m")
    K = sp.csc_matrix(scipy.io.mmread(tmp_path / "m" / "K.mtx"))
    M = sp.csc_matrix(scipy.io.mmread(tmp_path / "m" / "M.mtx"))
    lam, phi = sla.eigsh(K, k=8, M=M, sigma=0, which="LM")
    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    r = dynid.modal(dynid.load_case(cases / "paper-frame"), modes=8)
    np.testing.assert_allclose(r["eigenvalues"], lam, rtol=1e-8)
    mac = np.diag(dynid.mac(r["shapes"], phi))
    np.testing.assert_allclose(mac, 1.0, atol=1e-8)
    # Python's own matrices, and dynid's solver on SciPy's matrices.
    Kp, Mp = dynid.load_case(cases / "paper-frame").model.matrices()
    assert abs(Kp - K).max() <= 1e-15 * abs(K).max()
    s = dynid.solve_eigen(K, M, modes=8)
    np.testing.assert_allclose(s["eigenvalues"], lam, rtol=1e-8)


def test_residual_forces_three_ways(paper_frame):
    """Eq. (6) from sparse matrices, dense matrices and the model's operator agree; zero for the model's own modes."""
    r = dynid.modal(paper_frame, modes=4)
    K, M = paper_frame.matrices()
    R1 = dynid.residual_forces(K, M, r["eigenvalues"], r["shapes"])
    R2 = dynid.residual_forces(K.toarray(), M.toarray(), r["eigenvalues"], r["shapes"])
    R3 = dynid.ResidualForces(paper_frame)(r["eigenvalues"], r["shapes"])
    scale = abs(K).max() * abs(r["shapes"]).max()
    assert abs(R1 - R2).max() <= 1e-12 * scale and abs(R1 - R3).max() == 0.0
    assert abs(R1).max() <= 1e-9 * scale
    changed = paper_frame.changed({9: (-0.15, 0.0)})
    rc = dynid.modal(changed, modes=4)
    R = dynid.ResidualForces(paper_frame)(rc["eigenvalues"], rc["shapes"])
    p = dynid.pseudo_residual_force(R)
    top = {paper_frame.dofs[i] for i in np.argsort(p)[-6:]}
    assert top == {"9ux", "9uy", "9rz", "13ux", "13uy", "13rz"}  # element 9 joins nodes 9 and 13


def test_serep_reproduces_modes(paper_frame):
    r = dynid.modal(paper_frame, modes=6)
    masters = paper_frame.equations([f"{n}ux" for n in range(5, 25)])
    s = dynid.serep(r["shapes"], r["eigenvalues"], masters)
    assert s["rank"] == 6
    # The reduced model reproduces the modes at the masters (eq. 1): K~ u_i = lambda_i M~ u_i.
    U = r["shapes"][masters, :]
    R = s["K"] @ U - s["M"] @ U * r["eigenvalues"]
    assert abs(R).max() <= 1e-9 * abs(s["K"] @ U).max()
    np.testing.assert_allclose(s["T"][masters, :], np.eye(len(masters)) @ (U @ s["P"]), atol=1e-12)

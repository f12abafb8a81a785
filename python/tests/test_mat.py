""".mat input: v5 files written by SciPy, v7.3 (HDF5) files written with h5py in MATLAB's layout (two writers
independent of dynid's reader, libmatio), the real SAP2000 matrices of ../shared, and named errors."""
import json
import time

import h5py
import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

import dynid
from conftest import CASES


# ---- a v7.3 writer in MATLAB's HDF5 layout (what MATLAB's save -v7.3 writes) ----------------------------------------

def _header(path):
    text = ("MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: " + time.strftime("%a %b %d %H:%M:%S %Y") +
            " HDF5 schema 1.00 .").encode()
    with open(path, "r+b") as f:
        f.write(text.ljust(116, b" ") + b"\0" * 8 + b"\x00\x02" + b"IM")


def _class(obj, text):
    """MATLAB_class: a scalar, NUL-terminated fixed-length string (one byte longer than the name, so that h5py's
    NUL-padded write converts to it without cutting the last letter)."""
    t = h5py.h5t.C_S1.copy()
    t.set_size(len(text) + 1)
    t.set_strpad(h5py.h5t.STR_NULLTERM)
    a = h5py.h5a.create(obj.id, b"MATLAB_class", t, h5py.h5s.create(h5py.h5s.SCALAR))
    a.write(np.array(text.encode(), dtype=f"S{len(text) + 1}"))


def _put(f, refs, name, value):
    """Writes one MATLAB value: a real matrix (stored transposed), scipy.sparse, str, or a list (a cell array)."""
    if isinstance(value, str):
        d = f.create_dataset(name, data=np.array([[ord(c)] for c in value], dtype=np.uint16))
        _class(d, "char")
        d.attrs["MATLAB_int_decode"] = np.int32(2)
    elif isinstance(value, list):
        r = np.empty((len(value), 1), dtype=h5py.ref_dtype)
        for k, v in enumerate(value):
            n = f"{name}_{k}"
            _put(refs, refs, n, v)
            r[k, 0] = refs[n].ref
        d = f.create_dataset(name, data=r)
        _class(d, "cell")
    elif sp.issparse(value):
        c = sp.csc_matrix(value)
        g = f.create_group(name)
        _class(g, "double")
        g.attrs["MATLAB_sparse"] = np.uint64(c.shape[0])
        g.create_dataset("data", data=c.data)
        g.create_dataset("ir", data=c.indices.astype(np.uint64))
        g.create_dataset("jc", data=c.indptr.astype(np.uint64))
    else:
        a = np.atleast_2d(np.asarray(value, dtype=float))
        d = f.create_dataset(name, data=a.T)  # MATLAB is column-major: HDF5 holds the transpose
        _class(d, "double")


def savemat73(path, variables):
    with h5py.File(path, "w", userblock_size=512) as f:
        refs = f.create_group("#refs#")
        for k, v in variables.items():
            _put(f, refs, k, v)
    _header(path)


def savemat(path, variables, version):
    """version: "v5" (as SciPy writes by default), "v5z" (v5 with each variable deflated: MATLAB's -v7), "v4" (MATLAB's
    -v4: matrices, text and sparse matrices only) or "v7.3"."""
    if version == "v4":
        scipy.io.savemat(path, variables, format="4")
    elif version in ("v5", "v5z"):
        def cell(v):  # a list is a cell array (n x 1), an object array for SciPy
            a = np.empty((len(v), 1), dtype=object)
            for k, x in enumerate(v):
                a[k, 0] = x
            return a
        scipy.io.savemat(path, {k: (cell(v) if isinstance(v, list) else v) for k, v in variables.items()}, format="5",
                         do_compression=version == "v5z")
    else:
        savemat73(path, variables)


@pytest.fixture(scope="module")
def frame_mats(paper_frame):
    """The paper frame's K, M and its column / beam groups."""
    K, M = paper_frame.matrices()
    n = K.shape[0]
    groups = {}
    for name, ids in (("columns", range(1, 21)), ("beams", range(21, 32))):
        Kg = sp.lil_matrix((n, n))
        Mg = sp.lil_matrix((n, n))
        for eid in ids:
            e = paper_frame.element_matrices(eid)
            q = e["equations"]
            for a in range(len(q)):
                for b in range(len(q)):
                    if q[a] >= 0 and q[b] >= 0:
                        Kg[q[a], q[b]] += e["K"][a, b]
                        Mg[q[a], q[b]] += e["M"][a, b]
        groups[name] = (sp.csc_matrix(Kg), sp.csc_matrix(Mg))
    dofs = np.array([[int(d[:-2]), "xyz".index(d[-1]) + 1 if d[-2] == "u" else 3 + "xyz".index(d[-1]) + 1]
                     for d in paper_frame.dofs], dtype=float)
    nodes = np.column_stack([paper_frame.node_ids, paper_frame.coordinates])
    return K, M, groups, dofs, nodes


@pytest.mark.parametrize("version", ["v5", "v5z", "v4", "v7.3"])
@pytest.mark.parametrize("storage", ["sparse", "dense"])
def test_matrix_model_from_mat(tmp_path, paper_frame, frame_mats, version, storage):
    K, M, groups, dofs, nodes = frame_mats
    conv = (lambda A: A) if storage == "sparse" else (lambda A: A.toarray())
    path = tmp_path / f"frame-{version}.mat"
    savemat(path, {"K0": conv(K), "M0": conv(M), "Kc": conv(groups["columns"][0]), "Mc": conv(groups["columns"][1]),
                   "Kb": conv(groups["beams"][0]), "Mb": conv(groups["beams"][1]), "DOFS": dofs, "NODES": nodes}, version)
    assert dynid.mat_version(path) == {"v7.3": "MATLAB 7.3 (HDF5)", "v4": "MATLAB 4"}.get(version, "MATLAB 5.0 (v5/v7)")
    # Variables read back exactly.
    Kr = dynid.read_mat(path, "K0", "sparse")
    assert (Kr != K).nnz == 0
    np.testing.assert_array_equal(dynid.read_mat(path, "NODES"), nodes)
    # The model, named by variables as a case file names them.
    m = dynid.Model.from_mat(path, K="K0", M="M0", groups={"columns": {"K": "Kc", "M": "Mc"}, "beams": {"K": "Kb", "M": "Mb"}},
                             dofs="DOFS", nodes="NODES")
    ref = dynid.modal(paper_frame, modes=8)["frequency_hz"]
    np.testing.assert_allclose(dynid.modal(m, modes=8)["frequency_hz"], ref, rtol=1e-12)
    assert m.element_groups == ["columns", "beams"]  # K0 / M0 equal the sum: no remainder element
    # The same through a case file, with detection of a 15 % loss of the column group.
    case = tmp_path / "case.yaml"
    case.write_text(f"""name: frame-from-mat
model:
  matrices: {{mat: {path.name}, K: K0, M: M0, groups: {{columns: {{K: Kc, M: Mc}}, beams: {{K: Kb, M: Mb}}}}, dofs: DOFS, nodes: NODES}}
detect:
  modes: 4
  changed: {{elements: [{{id: 1, dk: -0.15}}]}}
  measured_dofs: all
""")
    c = dynid.load_case(case)
    np.testing.assert_allclose(dynid.modal(c, modes=8)["frequency_hz"], ref, rtol=1e-12)
    d = dynid.detect(c)
    assert d["quantification"][0]["element"] == 1 and abs(d["quantification"][0]["dk"] + 0.15) < 1e-4


@pytest.mark.parametrize("version", ["v5", "v7.3"])
def test_element_matrices_recording_and_modes_from_mat(tmp_path, paper_frame, version):
    Ke, Me, De = [], [], []
    for eid in paper_frame.element_ids:
        e = paper_frame.element_matrices(int(eid))
        keep = [k for k, q in enumerate(e["equations"]) if q >= 0]
        Ke.append(e["K"][np.ix_(keep, keep)])
        Me.append(e["M"][np.ix_(keep, keep)])
        De.append(np.array([[e["equations"][k] + 1.0 for k in keep]]))
    test = dynid.simulate_test(paper_frame, sensors=["21ux", "24ux", "13ux"], excitation="ambient", sample_rate_hz=20,
                               duration_s=60, seed=3, max_frequency_hz=40)
    rec = test["recordings"][0]
    truth = test["truth"]
    path = tmp_path / f"all-{version}.mat"
    savemat(path, {"KE": Ke, "ME": Me, "DE": De, "data": rec["records"][0].T, "fs": np.array([[20.0]]),
                   "channels": [c["dof"] for c in rec["channels"]], "f": truth["frequency_hz"], "phi": truth["shapes"],
                   "labels": truth["dofs"]}, version)
    m = dynid.Model.from_mat(path, elements={"K": "KE", "M": "ME", "dofs": "DE"})
    np.testing.assert_allclose(dynid.modal(m, modes=6)["frequency_hz"], dynid.modal(paper_frame, modes=6)["frequency_hz"], rtol=1e-12)
    r = dynid.read_mat_recording(path)  # data, fs, channels: the default names
    assert [c["dof"] for c in r["channels"]] == ["21ux", "24ux", "13ux"]
    np.testing.assert_array_equal(r["records"][0], rec["records"][0])
    assert r["sample_rate_hz"] == 20.0
    r2 = dynid.read_mat_recording(path, channel_labels=["1ux", "2ux", "3ux"], sample_rate_hz=40.0)
    assert [c["dof"] for c in r2["channels"]] == ["1ux", "2ux", "3ux"] and r2["sample_rate_hz"] == 40.0
    md = dynid.read_mat_modal_data(path, frequency_hz="f", shapes="phi", dofs="labels")
    np.testing.assert_array_equal(md["shapes"], truth["shapes"])
    np.testing.assert_array_equal(md["frequency_hz"], truth["frequency_hz"])
    assert md["dofs"] == truth["dofs"]


def test_malformed_mat_files_are_named(tmp_path, frame_mats):
    K, M, groups, dofs, nodes = frame_mats
    path = tmp_path / "some.mat"
    scipy.io.savemat(path, {"K0": K, "M0": M, "cube": np.zeros((2, 2, 2)), "text": "abc", "rect": np.zeros((3, 4)),
                            "cplx": np.eye(3) * 1j, "bad": np.array([[np.nan, 1.0], [1.0, 1.0]])})
    cases = [
        (dict(K="K0", M="nope", groups=["K0"]), r"no variable 'nope' \(the assembled mass matrix M\); the file holds: K0 \(60 x 60 sparse\)"),
        (dict(K="K0", M="cube", groups=["K0"]), r"variable 'cube' \(the assembled mass matrix M\) is 2 x 2 x 2; a square matrix is needed"),
        (dict(K="K0", M="rect", groups=["K0"]), r"variable 'rect' .* is 3 x 4; a square matrix is needed"),
        (dict(K="K0", M="text", groups=["K0"]), r"variable 'text' .* is 1 x 3; a square matrix is needed|is a char"),
        (dict(K="K0", M="cplx", groups=["K0"]), r"variable 'cplx' .* is complex; real values are needed"),
        (dict(K="K0", M="bad", groups=["K0"]), r"variable 'bad' .*: entry \(1, 1\) is not finite"),
        (dict(K="K0", M="M0", groups=["K0"], dofs="rect"), r"variable 'rect' \(the DOF table.*\) is 3 x 4; n x 2"),
        (dict(K="K0", M="M0"), r"model matrices: name groups \(group stiffness variables\) or elements \(cell arrays\)"),
    ]
    for names, message in cases:
        with pytest.raises(dynid.InputError, match=message):
            dynid.Model.from_mat(path, **names)
    (tmp_path / "not.mat").write_bytes(b"MATLAB 5.0 MAT-file" + b"\0" * 40)
    with pytest.raises(dynid.InputError, match=r"not.mat: not a MATLAB .mat file"):
        dynid.mat_variables(tmp_path / "not.mat")
    with pytest.raises(dynid.InputError, match=r"missing.mat: cannot open the file"):
        dynid.mat_variables(tmp_path / "missing.mat")
    # A recording whose channel labels match the columns, not the rows.
    scipy.io.savemat(tmp_path / "rec.mat", {"data": np.zeros((100, 2)), "fs": 10.0, "channels": np.array(["1ux", "2ux"], dtype=object)})
    with pytest.raises(dynid.InputError, match=r"has 100 rows but 2 channel labels are given; dynid reads channels x samples: transpose it"):
        dynid.read_mat_recording(tmp_path / "rec.mat")
    # A case naming a variable that is not there: the case file's line and the variable.
    (tmp_path / "c.yaml").write_text("model:\n  matrices: {mat: some.mat, K: K0, M: M0, groups: [Kx]}\n")
    with pytest.raises(dynid.InputError, match=r"some.mat: no variable 'Kx' \(stiffness of group 'Kx'\)"):
        dynid.load_case(tmp_path / "c.yaml")


@pytest.mark.parametrize("compressed", [False, True])
def test_every_kind_of_v5_variable_opens(tmp_path, compressed):
    """dynid checks every v5 variable's tags against its array when it opens a file (io/src/mat_v5_check.cpp):
    intact files of every class SciPy writes (structs and struct arrays, nested cells, non-ASCII text, complex,
    logical, integers, empty and sparse complex arrays, small elements) must open and list as they are; the
    dimensions are checked against the data too (a struct array's elements x fields, a text's characters)."""
    path = tmp_path / "all.mat"
    cell = np.empty((1, 3), dtype=object)
    cell[0, 0], cell[0, 1], cell[0, 2] = "ab", np.arange(3.0), {"x": 1.0}
    scipy.io.savemat(path, {"s": {"a": np.eye(2), "b": "text", "c": {"d": np.int8(3)}}, "c": cell,
                            "t": np.array(["1ux", "2uy"]), "z": np.array([[1 + 2j, 3j]]), "l": np.array([[True, False]]),
                            "i": np.arange(5, dtype=np.uint16), "e": np.zeros((0, 3)), "es": "",
                            "sz": sp.csc_matrix(np.array([[0, 1j], [2.0, 0]])), "big": np.arange(200.0).reshape(10, 20),
                            "sa": np.array([[(1.0, "x"), (np.arange(4.0), "yy"), (3.0, {"n": 2.0})]],
                                           dtype=[("p", object), ("q", object)]),
                            "u": "h\u00e9llo \u2192 \U0001F600"},
                     do_compression=compressed)
    listed = {v["name"]: v for v in dynid.mat_variables(path)}
    assert sorted(listed) == sorted(["s", "c", "t", "z", "l", "i", "e", "es", "sz", "big", "sa", "u"])
    assert listed["s"]["type"] == "struct" and listed["c"]["type"] == "cell" and listed["sz"]["complex"]
    assert listed["sa"]["type"] == "struct" and listed["sa"]["shape"] == (1, 3)  # a struct array: 3 elements x 2 fields
    np.testing.assert_array_equal(dynid.read_mat(path, "big"), np.arange(200.0).reshape(10, 20))


def test_real_sap2000_bridge_matrices(shared, tmp_path):
    """The SMU package's steel pedestrian bridge (SAP2000 export, MATLAB 5.0 files; ../shared/data/real)."""
    d = shared / "data" / "real" / "gt-pedestrian-bridge"
    f = d / "SteelPedestrianBridgeExp.mat"
    names = {v["name"]: v for v in dynid.mat_variables(f)}
    groups = ["K_Frame", "K_Truss"] + [f"K_Conc{k}" for k in range(1, 12)] + ["K_y1", "K_z1", "K_y2", "K_z2"]
    assert all(names[g]["shape"] == (946, 946) for g in groups)
    ref = scipy.io.loadmat(f)  # the independent reader
    for g in ("K_whole", "K_y1", "K_z1", "M0"):  # double, uint8 and uint16 storage
        A = dynid.read_mat(f, g, "sparse")
        assert abs(A - sp.csc_matrix(ref[g].astype(float))).max() == 0.0, g
    # K_whole is the sum of the 17 influence matrices (PROVENANCE: to 1e-14).
    S = sum(dynid.read_mat(f, g, "sparse") for g in groups)
    Kw = dynid.read_mat(f, "K_whole", "sparse")
    assert abs(S - Kw).max() <= 1e-13 * abs(Kw).max()
    # The nominal model: 4.660, 4.875, 6.654, 9.901, 11.381 Hz (PROVENANCE.md, 4 significant digits).
    m = dynid.Model.from_mat(f, K="K_whole", M="M0", groups=groups)
    assert m.num_dofs == 946 and m.element_groups.count("remainder") == 1  # M0 is not in any group
    r = dynid.modal(m, modes=5)
    np.testing.assert_allclose(r["frequency_hz"], [4.660, 4.875, 6.654, 9.901, 11.381], rtol=2e-4)
    # The measured modes (lambda in (rad/s)^2): 4.063, 4.550, 6.823, 8.653, 11.498 Hz.
    e = d / "ExpModeInfo_FEM.mat"
    meas = dynid.read_mat(f, "measDOFs").ravel().astype(int)
    lam = dynid.read_mat(e, "lambdaExp").ravel()
    np.testing.assert_allclose(np.sqrt(lam) / (2 * np.pi), [4.063, 4.550, 6.823, 8.653, 11.498], rtol=2e-4)
    # The model's modes at the measured DOFs against the identified shapes: the MACs of PROVENANCE.md (3 digits).
    psi = dynid.read_mat(e, "psiExp_m")
    model_at = r["shapes"][meas - 1, :]
    pairs = dynid.pair_modes(dynid.mac(psi, model_at), np.sqrt(lam) / (2 * np.pi), r["frequency_hz"])
    macs = [p["mac"] for p in pairs["pairs"]]
    np.testing.assert_allclose(macs, [0.971, 0.986, 0.955, 0.966, 0.903], atol=1.5e-3)

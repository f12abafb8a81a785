#!/usr/bin/env python3
"""Writes the seed corpora fuzz/corpus/<target>/: small valid files from cases/ and tests/data/, and hand-made
malformed ones (truncated, wrong counts, huge declared sizes, binary garbage, wrong byte order). Run from
anywhere; it rewrites the seeds it makes and leaves files the fuzzer added (scripts/fuzz.sh does not add any)."""
import glob
import os
import random
import re
import struct

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
rng = random.Random(1)  # reproducible garbage
garbage = bytes(rng.randrange(256) for _ in range(512))


def read(rel):
    with open(os.path.join(root, rel), "rb") as f:
        return f.read()


def write(target, name, data):
    d = os.path.join(here, "corpus", target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def variants(target, name, data):
    """The file itself, cut in half, and cut just before the end."""
    write(target, name, data)
    write(target, "truncated-half-" + name, data[: len(data) // 2])
    write(target, "truncated-end-" + name, data[: max(len(data) - 7, 0)])


# --- Gmsh ---
for rel in ["cases/paper-frame-gmsh/frame.msh"] + sorted(glob.glob("tests/data/mesh/*.msh", root_dir=root)):
    variants("fuzz_gmsh", os.path.basename(os.path.dirname(rel)) + "-" + os.path.basename(rel), read(rel))
g22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n2 1 0 0\n$EndNodes\n$Elements\n1\n1 1 2 7 1 1 2\n$EndElements\n"
write("fuzz_gmsh", "tiny-22.msh", g22)
write("fuzz_gmsh", "nodes-1e12.msh", g22.replace("$Nodes\n2\n", "$Nodes\n1000000000000\n"))
write("fuzz_gmsh", "wrong-count.msh", g22.replace("$Nodes\n2\n", "$Nodes\n3\n"))
write("fuzz_gmsh", "elements-huge.msh", g22.replace("$Elements\n1\n", "$Elements\n9223372036854775807\n"))
write("fuzz_gmsh", "tags-huge.msh", g22.replace("1 1 2 7 1 1 2", "1 1 2000000000 7 1 1 2"))
g41 = ("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 1 0 0\n1 0 0 0 1 0 0 1 7 2 1 -2\n$EndEntities\n"
       "$Nodes\n1 2 1 2\n1 1 0 2\n1\n2\n0 0 0\n1 0 0\n$EndNodes\n$Elements\n1 1 1 1\n1 1 1 1\n1 1 2\n$EndElements\n")
write("fuzz_gmsh", "tiny-41.msh", g41)
write("fuzz_gmsh", "nodes-1e12-41.msh", g41.replace("$Nodes\n1 2 1 2\n", "$Nodes\n1 1000000000000 1 1000000000000\n"))
write("fuzz_gmsh", "blocks-huge-41.msh", g41.replace("$Elements\n1 1 1 1\n", "$Elements\n4294967296 1 1 1\n"))
bin22 = read("tests/data/mesh/paper-frame-22-bin.msh")
i = bin22.index(b"\n", bin22.index(b"2.2 1 8")) + 1
write("fuzz_gmsh", "byte-order-22-bin.msh", bin22[:i] + struct.pack(">i", 1) + bin22[i + 4:])
head = b"$MeshFormat\n4.1 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n$Nodes\n"
write("fuzz_gmsh", "huge-binary-count-41.msh", head + struct.pack("<4Q", 1, 10**12, 1, 10**12) + b"\n$EndNodes\n")
write("fuzz_gmsh", "garbage.msh", garbage)
write("fuzz_gmsh", "garbage-after-format.msh", b"$MeshFormat\n2.2 1 8\n" + garbage)

# --- Abaqus ---
inp = read("cases/paper-frame-abaqus/frame.inp")
variants("fuzz_abaqus", "paper-frame.inp", inp)
# The unit tests' space frame (tests/test_mesh_files.cpp, kSpaceFrame) with its *INCLUDE expanded (refused when
# parsing from memory), and a *BEAM GENERAL SECTION added.
test_src = read("tests/test_mesh_files.cpp").decode()
space = re.search(r'kSpaceFrame = R"\((.*?)\)"', test_src, re.S).group(1)
members = re.search(r'Write\("members.inp", "(.*?)"\)', test_src).group(1).replace("\\n", "\n")
space = space.replace("*INCLUDE, INPUT=members.inp\n", members)
write("fuzz_abaqus", "space-frame.inp", space + "*BEAM GENERAL SECTION, ELSET=x, SECTION=GENERAL, DENSITY=7850\n"
      "0.01, 1e-4, 0, 1e-4, 1e-5\n0., 0., 1.\n2.1e11, 8e10\n*BOUNDARY\n2, ENCASTRE\n*STEP\n*END STEP\n")
write("fuzz_abaqus", "generate-huge.inp", "*NODE\n1, 0, 0\n*NSET, NSET=A, GENERATE\n1, 2000000000, 1\n"
      "*ELSET, ELSET=B, GENERATE\n-2147483648, 2147483647, 1\n")
write("fuzz_abaqus", "include.inp", "*INCLUDE, INPUT=/dev/zero\n")
write("fuzz_abaqus", "bad-numbers.inp", "*NODE\n1, 1e999, nan\n99999999999, 0, 0\n*ELEMENT, TYPE=B21\n1, 1, 99999999999\n")
write("fuzz_abaqus", "garbage.inp", garbage)

# --- Matrix Market ---
mm = ("%%MatrixMarket matrix coordinate real symmetric\n% K\n3 3 5\n1 1 4.0\n2 1 -1\n2 2 4\n3 2 -1\n3 3 4\n")
variants("fuzz_matrix_market", "sym.mtx", mm)
write("fuzz_matrix_market", "general.mtx", "%%MatrixMarket matrix coordinate real general\n2 3 3\n1 1 1\n2 3 2e3\n1 3 -0.5\n")
write("fuzz_matrix_market", "nnz-huge.mtx", "%%MatrixMarket matrix coordinate real general\n2147483647 2147483647 4611686014132420609\n1 1 1\n")
write("fuzz_matrix_market", "wrong-count.mtx", "%%MatrixMarket matrix coordinate integer general\n2 2 3\n1 1 1\n2 2 2\n")
write("fuzz_matrix_market", "outside.mtx", "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1\n")
write("fuzz_matrix_market", "array.mtx", "%%MatrixMarket matrix array real general\n2 2\n1\n2\n3\n4\n")
write("fuzz_matrix_market", "garbage.mtx", garbage)

# --- modal data (JSON) ---
for rel in ["cases/smu-four-story/measured.json", "cases/smu-eighteen-story/measured.json"]:
    variants("fuzz_modal_data", rel.split("/")[1] + ".json", read(rel))
write("fuzz_modal_data", "full.json", '{"modes": [{"frequency_hz": 1.5, "damping_ratio": 0.02, "mpc": 0.99, '
      '"frequency_std_hz": 0.01, "damping_std": 0.001, "shape": {"1ux": 1, "2+Y": -0.5, "3:rz": 0.25}}, '
      '{"frequency_hz": 4, "shape": {"1ux": 0.3, "2+Y": 1, "3:rz": 0}}]}')
write("fuzz_modal_data", "wrong-dofs.json", '{"modes": [{"frequency_hz": 1, "shape": {"1ux": 1}}, {"frequency_hz": 2, "shape": {"1uy": 1, "2ux": 3}}]}')
write("fuzz_modal_data", "deep.json", "[" * 5000 + "]" * 5000)
write("fuzz_modal_data", "big-numbers.json", '{"modes": [{"frequency_hz": 1e400, "shape": {"99999999999999ux": 1e999}}]}')
write("fuzz_modal_data", "garbage.json", garbage)

# --- case files ---
for rel in sorted(glob.glob("cases/*/*.yaml", root_dir=root)) + sorted(glob.glob("tests/data/bad/*.yaml", root_dir=root)):
    data = read(rel)
    if len(data) <= 8000:
        write("fuzz_case", rel.split("/")[-2] + "-" + os.path.basename(rel), data)
write("fuzz_case", "generate-huge.yaml", """model:
  materials: {steel: {E: 2.1e11, rho: 7850, nu: 0.3}}
  sections: {s: {A: 1e-2, Iy: 1e-4, Iz: 1e-4, J: 1e-6}}
  generate:
    frame3d: {bays_x: 2147483647, bays_y: 2147483647, stories: 2147483647, divisions: 2147483647,
              material: steel, column: s, beam: s}
""")
write("fuzz_case", "beam-huge.yaml", """model:
  materials: {steel: {E: 2.1e11, rho: 7850}}
  sections: {s: {A: 1e-2, I: 1e-4}}
  generate: {beam: {length: 1, elements: 2147483647, material: steel, section: s, support: cantilever}}
""")
write("fuzz_case", "deep.yaml", "a: " + "[" * 3000 + "]" * 3000 + "\n")
write("fuzz_case", "anchors.yaml", "a: &a [1, 2]\nb: &b [*a, *a, *a]\nc: [*b, *b, *b]\nmodel: *a\n")
write("fuzz_case", "mesh-device.yaml", "model:\n  file: /dev/zero\n")
write("fuzz_case", "garbage.yaml", garbage)

# --- UFF, text tables, LabVIEW (samples from ../shared/data when present: heads cut at a line break) ---
shared = os.path.join(os.path.dirname(root), "shared", "data")


def head(path, n=6000):
    with open(path, "rb") as f:
        data = f.read(n)
    return data[: data.rfind(b"\n") + 1] if len(data) == n else data


uffs = os.path.join(shared, "uff-samples")
for name in ["binary8byte.uff", "TestLab 161 164 18 15 82.uff", "mesh_Oros-modal_uff15_uff2412.uff",
             "Sample_UFF58_ascii.uff", "Sample_UFF58b_bin.uff"]:
    p = os.path.join(uffs, name)
    if os.path.exists(p):
        data = head(p, 12000) if name.startswith("Sample") else read(p)
        variants("fuzz_uff", name.replace(" ", "-"), data)
write("fuzz_uff", "truncated-58.uff", read("tests/data/bad/truncated-58.uff"))
b8 = os.path.join(uffs, "binary8byte.uff")
if os.path.exists(b8):
    data = read(b8)
    # record 1 of 58b: "58b  byte-order  format  lines  bytes ..."; declare huge sizes and the other byte order
    i = data.index(b"58b")
    j = data.index(b"\n", i)
    write("fuzz_uff", "58b-other-byte-order.uff", data[:i] + b"58b     2" + data[i + 9:])
    write("fuzz_uff", "58b-huge-bytes.uff", data[:i] + b"58b     1     2          11  9999999999     0     0           0           0" + data[j - 1 if data[j - 1:j] == b"\r" else j:])
    k = data.index(b"       250")
    write("fuzz_uff", "58b-huge-points.uff", data[:k] + b"2000000000" + data[k + 10:])
write("fuzz_uff", "garbage.uff", garbage)
write("fuzz_uff", "delimiters.uff", "    -1\n    -1\n    -1\n    58\n    -1\n")

tit = os.path.join(shared, "real", "tool-impact-test")
for name in ["frf_point_1.txt", "impact_point1_time.txt"]:
    p = os.path.join(tit, name)
    if os.path.exists(p):
        variants("fuzz_text_table", name, head(p, 3000))
write("fuzz_text_table", "header.csv", "# comment\ntime,force,acc1\n0,1,2\n0.01,1.5,2e-3\n0.02,-1,nan\n")
write("fuzz_text_table", "ragged.csv", "t a\n0 1\n1 2 3\n2\n")
write("fuzz_text_table", "uneven.txt", "0 1\n1 1\n1.5 1\n4 1\n")
write("fuzz_text_table", "big-numbers.txt", "1e999 -1e999\n1e-999 0x1p3\ninf nan\n")
write("fuzz_text_table", "garbage.csv", garbage)

usc = os.path.join(shared, "real", "usc-cantilever-ds4")
for name in ["FFT_data.lvm", "data_set_1_downsampled_by_16.lvm"]:
    p = os.path.join(usc, name)
    if os.path.exists(p):
        data = head(p, 3000)
        variants("fuzz_lvm", name, data)
        write("fuzz_lvm", "samples-huge-" + name, data.replace(b"Samples\t150000", b"Samples\t999999999999"))
        write("fuzz_lvm", "channels-huge-" + name, data.replace(b"Channels\t1", b"Channels\t2147483647"))
write("fuzz_lvm", "no-x.lvm", "LabVIEW Measurement\t\nX_Columns\tNo\n***End_of_Header***\t\n\nChannels\t2\t\t\n"
      "Samples\t3\t3\t\nDelta_X\t0.1\t0.1\t\n***End_of_Header***\t\t\nA\tB\n1\t2\n3\t4\n5\t6\n")
write("fuzz_lvm", "garbage.lvm", b"LabVIEW Measurement\n" + garbage)

#!/usr/bin/env python3
"""Writes the paper frame of cases/paper-frame/case.yaml as mesh files, so that the mesh-file cases and tests
are reproducible:

  cases/paper-frame-gmsh/frame.msh       Gmsh MSH 4.1 ASCII
  cases/paper-frame-abaqus/frame.inp     Abaqus .inp (B23 elements, general beam section, ENCASTRE base)
  tests/data/mesh/paper-frame-22.msh     Gmsh MSH 2.2 ASCII
  tests/data/mesh/paper-frame-22-bin.msh Gmsh MSH 2.2 binary
  tests/data/mesh/paper-frame-41-bin.msh Gmsh MSH 4.1 binary

Same nodes (ids and coordinates), elements (ids and node order), section, material and supports as the case.
Gmsh files: one geometry point per node, one curve per element; physical groups "columns" (vertical
members), "beams" (horizontal members) and "base" (the supported points, as point elements numbered after the
lines). Binary files are little-endian. Usage: scripts/make-paper-frame-meshes.py (no arguments).
"""
import os
import struct
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def load_case():
    with open(os.path.join(ROOT, "cases", "paper-frame", "case.yaml")) as f:
        case = yaml.safe_load(f)["model"]
    nodes = {int(n[0]): (float(n[1]), float(n[2]), 0.0) for n in case["nodes"]}
    elements = [(int(e[0]), int(e[1]), int(e[2])) for e in case["elements"]]
    (mat_name, mat), = case["materials"].items()
    (sec_name, sec), = case["sections"].items()
    base = sorted(n for s in case["supports"] for n in s["nodes"])
    assert all(s["fix"] == "all" for s in case["supports"])
    return nodes, elements, mat, sec, base


def num(x):
    """Shortest text that reads back as the same double."""
    return repr(float(x))


class Frame:
    def __init__(self):
        self.nodes, self.elements, self.mat, self.sec, self.base = load_case()
        # physical groups: (dim, tag, name)
        self.physical = [(0, 1, "base"), (1, 2, "columns"), (1, 3, "beams")]
        self.points = [(len(self.elements) + k + 1, n) for k, n in enumerate(self.base)]  # (element tag, node)

    def group_of(self, e):
        _, a, b = e
        return 2 if self.nodes[a][0] == self.nodes[b][0] else 3

    def point_groups(self, n):
        return [1] if n in self.base else []

    def bounds(self, e):
        _, a, b = e
        pa, pb = self.nodes[a], self.nodes[b]
        return [min(pa[k], pb[k]) for k in range(3)] + [max(pa[k], pb[k]) for k in range(3)]

    def names(self):
        out = "$PhysicalNames\n%d\n" % len(self.physical)
        out += "".join('%d %d "%s"\n' % p for p in self.physical)
        return out + "$EndPhysicalNames\n"

    # ---- MSH 4.1 -------------------------------------------------------------------------------------
    def msh41_ascii(self):
        out = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n" + self.names()
        out += "$Entities\n%d %d 0 0\n" % (len(self.nodes), len(self.elements))
        for n, x in self.nodes.items():
            g = self.point_groups(n)
            out += " ".join([str(n)] + [num(v) for v in x] + [str(len(g))] + [str(t) for t in g]) + "\n"
        for e in self.elements:
            out += " ".join([str(e[0])] + [num(v) for v in self.bounds(e)] + ["1", str(self.group_of(e)),
                                                                            "2", str(e[1]), str(-e[2])]) + "\n"
        out += "$EndEntities\n"
        out += "$Nodes\n%d %d %d %d\n" % (len(self.nodes), len(self.nodes), min(self.nodes), max(self.nodes))
        for n, x in self.nodes.items():
            out += "0 %d 0 1\n%d\n%s\n" % (n, n, " ".join(num(v) for v in x))
        nel = len(self.elements) + len(self.points)
        out += "$EndNodes\n$Elements\n%d %d 1 %d\n" % (nel, nel, nel)
        for e in self.elements:
            out += "1 %d 1 1\n%d %d %d\n" % (e[0], e[0], e[1], e[2])
        for tag, n in self.points:
            out += "0 %d 15 1\n%d %d\n" % (n, tag, n)
        return (out + "$EndElements\n").encode()

    def msh41_binary(self):
        out = b"$MeshFormat\n4.1 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n" + self.names().encode()
        out += b"$Entities\n" + struct.pack("<4Q", len(self.nodes), len(self.elements), 0, 0)
        for n, x in self.nodes.items():
            g = self.point_groups(n)
            out += struct.pack("<i3dQ", n, *x, len(g)) + b"".join(struct.pack("<i", t) for t in g)
        for e in self.elements:
            out += struct.pack("<i6dQiQii", e[0], *self.bounds(e), 1, self.group_of(e), 2, e[1], -e[2])
        out += b"\n$EndEntities\n$Nodes\n"
        out += struct.pack("<4Q", len(self.nodes), len(self.nodes), min(self.nodes), max(self.nodes))
        for n, x in self.nodes.items():
            out += struct.pack("<iiiQQ3d", 0, n, 0, 1, n, *x)
        nel = len(self.elements) + len(self.points)
        out += b"\n$EndNodes\n$Elements\n" + struct.pack("<4Q", nel, nel, 1, nel)
        for e in self.elements:
            out += struct.pack("<iiiQ3Q", 1, e[0], 1, 1, *e)
        for tag, n in self.points:
            out += struct.pack("<iiiQ2Q", 0, n, 15, 1, tag, n)
        return out + b"\n$EndElements\n"

    # ---- MSH 2.2 (tags: physical group, elementary entity) ---------------------------------------------
    def msh22_ascii(self):
        out = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n" + self.names()
        out += "$Nodes\n%d\n" % len(self.nodes)
        out += "".join("%d %s\n" % (n, " ".join(num(v) for v in x)) for n, x in self.nodes.items())
        out += "$EndNodes\n$Elements\n%d\n" % (len(self.elements) + len(self.points))
        for e in self.elements:
            out += "%d 1 2 %d %d %d %d\n" % (e[0], self.group_of(e), e[0], e[1], e[2])
        for tag, n in self.points:
            out += "%d 15 2 1 %d %d\n" % (tag, n, n)
        return (out + "$EndElements\n").encode()

    def msh22_binary(self):
        out = b"$MeshFormat\n2.2 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n" + self.names().encode()
        out += b"$Nodes\n%d\n" % len(self.nodes)
        out += b"".join(struct.pack("<i3d", n, *x) for n, x in self.nodes.items())
        out += b"\n$EndNodes\n$Elements\n%d\n" % (len(self.elements) + len(self.points))
        out += struct.pack("<3i", 1, len(self.elements), 2)
        out += b"".join(struct.pack("<5i", e[0], self.group_of(e), e[0], e[1], e[2]) for e in self.elements)
        out += struct.pack("<3i", 15, len(self.points), 2)
        out += b"".join(struct.pack("<4i", tag, 1, n, n) for tag, n in self.points)
        return out + b"\n$EndElements\n"

    # ---- Abaqus ---------------------------------------------------------------------------------------
    def inp(self):
        E, rho = float(self.mat["E"]), float(self.mat["rho"])
        G = E / (2 * 1.3)  # dynid's default nu = 0.3 (plane frames do not use G)
        out = "** The paper frame (cases/paper-frame), written by scripts/make-paper-frame-meshes.py\n"
        out += "*HEADING\nTwo connected five-story steel frames: 31 B23 elements, 24 nodes\n"
        out += "*NODE, NSET=ALL\n"
        out += "".join("%d, %s, %s\n" % (n, num(x[0]), num(x[1])) for n, x in self.nodes.items())
        for name, g in (("COLUMNS", 2), ("BEAMS", 3)):
            out += "*ELEMENT, TYPE=B23, ELSET=%s\n" % name
            out += "".join("%d, %d, %d\n" % e for e in self.elements if self.group_of(e) == g)
        out += "*ELSET, ELSET=FRAME\nCOLUMNS, BEAMS\n"
        out += "*NSET, NSET=BASE\n%s\n" % ", ".join(str(n) for n in self.base)
        out += "** A, I11, I12, I22, J; n1 direction (planar beams: 0, 0, -1); E, G\n"
        out += "*BEAM GENERAL SECTION, ELSET=FRAME, SECTION=GENERAL, DENSITY=%s\n" % num(rho)
        out += "%s, %s, 0., %s, %s\n" % (num(self.sec["A"]), num(self.sec["I"]), num(self.sec["I"]), num(2 * float(self.sec["I"])))
        out += "0., 0., -1.\n%s, %s\n" % (num(E), num(G))
        out += "*BOUNDARY\nBASE, ENCASTRE\n"
        out += "*STEP\n*FREQUENCY, EIGENSOLVER=LANCZOS\n8\n*END STEP\n"
        return out.encode()


def write(rel, data):
    path = os.path.join(ROOT, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)
    print("wrote", rel)


def main():
    f = Frame()
    write("cases/paper-frame-gmsh/frame.msh", f.msh41_ascii())
    write("cases/paper-frame-abaqus/frame.inp", f.inp())
    write("tests/data/mesh/paper-frame-22.msh", f.msh22_ascii())
    write("tests/data/mesh/paper-frame-22-bin.msh", f.msh22_binary())
    write("tests/data/mesh/paper-frame-41-bin.msh", f.msh41_binary())


if __name__ == "__main__":
    main()

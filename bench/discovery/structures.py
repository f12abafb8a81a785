"""Structure families of the benchmark: the analysis model (what the engineer has), drawn at realistic values.

A Structure holds the analysis mesh (nodes, Euler-Bernoulli elements, sections, materials, groups, supports) and
the physical members it is made of (a member = a straight chain of analysis elements between joints). It writes
itself as a dynid case-file model and builds itself in fe.py for the mesh-convergence check. Node ids: joints
first, then member-interior nodes; truth models add their own nodes from 10000 on.
"""
import math

import numpy as np

import fe

SLOTS_XYZ = {"ux": 0, "uy": 1, "uz": 2}

FAMILIES = ("cantilever", "simply_supported", "pinned_pinned", "free_free", "plane_frame", "linked_frame",
            "frame3d")

# Nominal material data (the analysis model and the truth share them: the effects are the only differences).
MATERIALS = {
    "steel": dict(E=(200e9, 212e9), rho=(7800, 7870), nu=0.3),
    "aluminium": dict(E=(68e9, 72e9), rho=(2690, 2710), nu=0.33),
    "concrete": dict(E=(28e9, 36e9), rho=(2350, 2500), nu=0.2),
    "timber": dict(E=(10e9, 14e9), rho=(420, 560), nu=0.3),
}


def draw_material(rng, name):
    d = MATERIALS[name]
    return dict(E=float(round(rng.uniform(*d["E"]), -7)), rho=float(round(rng.uniform(*d["rho"]))), nu=d["nu"])


def rectangle(b, d):
    """Rectangle b wide, d deep (d in the bending plane): A, Iz (in-plane), Iy, J (Saint-Venant)."""
    a, c = max(b, d), min(b, d)
    J = a * c**3 * (1 / 3 - 0.21 * c / a * (1 - c**4 / (12 * a**4)))
    return dict(A=b * d, Iz=b * d**3 / 12, Iy=d * b**3 / 12, J=J, shape=("rectangle", b, d))


def i_section(D, B, tf, tw):
    """Doubly symmetric I: depth D, flange width B. I_strong about the axis parallel to the flanges."""
    hw = D - 2 * tf
    A = 2 * B * tf + hw * tw
    strong = (B * D**3 - (B - tw) * hw**3) / 12
    weak = 2 * tf * B**3 / 12 + hw * tw**3 / 12
    J = (2 * B * tf**3 + (D - tf) * tw**3) / 3
    return dict(A=A, strong=strong, weak=weak, J=J, shape=("I", D, B, tf, tw))


def hollow(D, B, t):
    """Rectangular hollow section D deep, B wide, wall t (Bredt's torsion constant for the closed wall)."""
    A = 2 * t * (D + B - 2 * t)
    strong = (B * D**3 - (B - 2 * t) * (D - 2 * t) ** 3) / 12
    weak = (D * B**3 - (D - 2 * t) * (B - 2 * t) ** 3) / 12
    J = 2 * t * (B - t) ** 2 * (D - t) ** 2 / (B + D - 2 * t)
    return dict(A=A, strong=strong, weak=weak, J=J, shape=("RHS", D, B, t))


def draw_i(rng, kind):
    """HEB-like columns (B = D) or IPE-like beams (B = D / 2), at realistic proportions."""
    if kind == "column":
        D = rng.uniform(0.14, 0.36)
        return i_section(D, D, D * rng.uniform(0.06, 0.085), D * rng.uniform(0.035, 0.055))
    D = rng.uniform(0.2, 0.5)
    return i_section(D, 0.5 * D, D * rng.uniform(0.035, 0.05), D * rng.uniform(0.022, 0.032))


class Structure:
    """The analysis model and its members."""

    def __init__(self, family, element):
        self.family, self.element = family, element
        self.ndim = 3 if element == "frame3d" else 2
        self.nodes = {}
        self.materials = {}
        self.sections = {}
        self.elements = {}
        self.members = []
        self.supports = {}       # node -> restrained DOF names
        self.free_free = False
        self.vertical = 2 if self.ndim == 3 else 1
        self.layout = {}         # the family's drawn dimensions (reported in truth.json)

    # construction
    def node(self, xyz):
        nid = len(self.nodes) + 1
        self.nodes[nid] = np.array([*xyz, 0.0][:3], float) if len(xyz) == 2 else np.array(xyz, float)
        return nid

    def member(self, a, b, n_el, section, material, group, orientation=None):
        """A straight member from joint a to joint b, meshed into n_el analysis elements."""
        xa, xb = self.nodes[a], self.nodes[b]
        chain, els = [a], []
        for k in range(1, n_el):
            chain.append(self.node(xa + (xb - xa) * k / n_el))
        chain.append(b)
        for p, q in zip(chain[:-1], chain[1:]):
            eid = len(self.elements) + 1
            self.elements[eid] = dict(n=(p, q), section=section, material=material, group=group,
                                      member=len(self.members), orientation=orientation)
            els.append(eid)
        self.members.append(dict(nodes=chain, elements=els, group=group, section=section, material=material,
                                 orientation=orientation))
        return len(self.members) - 1

    # geometry helpers
    def length(self, eid):
        a, b = self.elements[eid]["n"]
        return float(np.linalg.norm(self.nodes[b] - self.nodes[a]))

    def member_length(self, mi):
        m = self.members[mi]
        return float(np.linalg.norm(self.nodes[m["nodes"][-1]] - self.nodes[m["nodes"][0]]))

    def offset(self, eid):
        """Distance of an element's first node from its member's first node."""
        m = self.members[self.elements[eid]["member"]]
        return sum(self.length(e) for e in m["elements"][:m["elements"].index(eid)])

    def direction(self, mi):
        m = self.members[mi]
        v = self.nodes[m["nodes"][-1]] - self.nodes[m["nodes"][0]]
        return v / np.linalg.norm(v)

    def depth(self, mi):
        """Section depth in the bending plane (for offsets of masses mounted on a member)."""
        shape = self.sections[self.members[mi]["section"]]["shape"]
        return shape[2] if shape[0] == "rectangle" else shape[1]

    def locate(self, mi, s):
        """Element and fraction of the point at distance s from the member's first node."""
        m = self.members[mi]
        for eid in m["elements"]:
            L = self.length(eid)
            if s <= L * (1 + 1e-12) or eid == m["elements"][-1]:
                return eid, min(max(s / L, 0.0), 1.0)
            s -= L
        raise AssertionError

    def point(self, eid, frac):
        a, b = self.elements[eid]["n"]
        return self.nodes[a] + frac * (self.nodes[b] - self.nodes[a])

    def props(self, eid):
        e = self.elements[eid]
        mat, sec = self.materials[e["material"]], self.sections[e["section"]]
        return dict(E=mat["E"], G=mat["E"] / (2 * (1 + mat["nu"])), rho=mat["rho"], nu=mat["nu"], A=sec["A"],
                    Iz=sec["Iz"], Iy=sec.get("Iy", 0.0), J=sec.get("J", 0.0), orientation=e["orientation"])

    def mass(self):
        return sum(self.props(e)["rho"] * self.props(e)["A"] * self.length(e) for e in self.elements)

    def group_elements(self, group=None):
        return sorted(e for e, d in self.elements.items() if group is None or d["group"] == group)

    def groups(self):
        return sorted({d["group"] for d in self.elements.values()})

    def translations(self):
        """DOF names a node of this model moves in."""
        return {"beam2d": ["uy"], "frame2d": ["ux", "uy"], "frame3d": ["ux", "uy", "uz"]}[self.element]

    def measurable(self):
        """(node, dof) translations that are not restrained."""
        return [(n, d) for n in self.nodes for d in self.translations() if d not in self.supports.get(n, [])]

    def sensing(self):
        """The measurable DOFs a test would put sensors on: the transverse ones of a single member (its axial
        motion is not what a vibration test of a beam measures), all of them in frames."""
        if len(self.members) == 1:
            axis = np.abs(self.direction(0))
            return [(n, d) for n, d in self.measurable() if axis[SLOTS_XYZ[d]] < 0.5]
        return self.measurable()

    def joints_of(self, node):
        """Members with an end at this node: [(member index, end 0|1)]."""
        out = []
        for mi, m in enumerate(self.members):
            if m["nodes"][0] == node:
                out.append((mi, 0))
            if m["nodes"][-1] == node:
                out.append((mi, 1))
        return out

    def end_element(self, mi, end):
        return self.members[mi]["elements"][0 if end == 0 else -1]

    def dofs(self):
        n = {"beam2d": 2, "frame2d": 3, "frame3d": 6}[self.element] * len(self.nodes)
        return n - sum(len(v) for v in self.supports.values())

    # outputs
    def fe_model(self):
        """The analysis model in fe.py (Euler-Bernoulli, consistent mass: dynid's element physics)."""
        m = fe.Model(self.ndim)
        for nid, x in self.nodes.items():
            m.node(nid, *x)
        if self.element == "beam2d":
            m.restrain_everywhere(["ux"])
        for eid in sorted(self.elements):
            p = self.props(eid)
            a, b = self.elements[eid]["n"]
            m.frame(a, b, p["E"], p["G"], p["A"], p["Iz"], p["rho"], Iy=p["Iy"], J=p["J"],
                    orientation=p["orientation"])
        for nid, dofs in self.supports.items():
            m.support(nid, dofs)
        return m

    def yaml(self):
        """The `model:` section of a dynid case file."""
        g = lambda v: f"{v:.9g}"  # noqa: E731
        out = ["model:", f"  element: {self.element}", "  materials:"]
        for name, d in self.materials.items():
            out.append(f"    {name}: {{E: {g(d['E'])}, rho: {g(d['rho'])}, nu: {g(d['nu'])}}}")
        out.append("  sections:")
        for name, s in self.sections.items():
            if s["shape"][0] == "rectangle" and self.ndim == 2:
                out.append(f"    {name}: {{rectangle: {{width: {g(s['shape'][1])}, depth: {g(s['shape'][2])}}}}}")
            elif self.ndim == 2:
                out.append(f"    {name}: {{A: {g(s['A'])}, I: {g(s['Iz'])}}}")
            else:
                out.append(f"    {name}: {{A: {g(s['A'])}, Iy: {g(s['Iy'])}, Iz: {g(s['Iz'])}, J: {g(s['J'])}}}")
        out.append("  nodes:")
        for nid, x in self.nodes.items():
            xs = [g(v) for v in (x if self.ndim == 3 else x[:2])]
            out.append(f"    - [{nid}, {', '.join(xs)}]")
        out.append("  elements:")
        for eid in sorted(self.elements):
            e = self.elements[eid]
            extra = ""
            if e["orientation"] is not None:
                extra = f", orientation: [{', '.join(g(v) for v in e['orientation'])}]"
            out.append(f"    - {{id: {eid}, nodes: [{e['n'][0]}, {e['n'][1]}], material: {e['material']}, "
                       f"section: {e['section']}, group: {e['group']}{extra}}}")
        if self.free_free:
            out.append("  supports: free")
        else:
            out.append("  supports:")
            for nid, dofs in self.supports.items():
                out.append(f"    - {{node: {nid}, fix: [{', '.join(dofs)}]}}")
        return "\n".join(out) + "\n"

    def summary(self):
        return dict(family=self.family, element=self.element, nodes=len(self.nodes), elements=len(self.elements),
                    members=len(self.members), dofs=self.dofs(), mass_kg=self.mass(), groups=self.groups())


# ---- families ------------------------------------------------------------------------------------------------
# Every family takes n_el, the analysis elements per member (per beam for single beams). The geometry a family
# draws does not depend on n_el (the size budget is checked with the coarsest mesh of its ladder), so the
# generator can refine a drawn structure until its analysis mesh is converged (generate.converged_structure).

MESH_LADDER = {"beam": (16, 24, 32, 40, 48, 64, 80), "plane": (4, 6, 8), "space": (3, 4, 6)}
MAX_DOFS_2D, MAX_DOFS_3D = 420, 480     # budget on the coarsest mesh ...
CAP_DOFS_2D, CAP_DOFS_3D = 420, 540     # ... and on the converged one (dynid's run time grows with the DOFs)


def ladder(family):
    return MESH_LADDER["space" if family == "frame3d" else "plane" if family in ("plane_frame", "linked_frame")
                       else "beam"]


def _single_beam(rng, family, material, lab, n_el, element, vertical=False):
    """A straight beam: lab bars (steel, aluminium) or building members (timber, concrete)."""
    st = Structure(family, element)
    st.materials[material] = draw_material(rng, material)
    if lab:
        L = rng.uniform(0.3, 1.6)
        b = rng.uniform(0.015, 0.06)
        d = rng.uniform(1 / 120, 1 / 40) * L
    elif vertical:
        L = rng.uniform(4.0, 10.0)
        b = d = rng.uniform(1 / 60, 1 / 35) * L
    else:
        L = rng.uniform(2.0, 7.0)
        d = rng.uniform(1 / 25, 1 / 14) * L
        b = d * rng.uniform(0.4, 0.8)
    st.sections["s"] = rectangle(round(b, 4), round(d, 4))
    end = (0.0, round(L, 3)) if vertical else (round(L, 3), 0.0)
    a, c = st.node((0.0, 0.0)), st.node(end)
    st.member(a, c, n_el, "s", material, "beam")
    st.layout = dict(length=round(L, 3), elements_per_member=n_el)
    return st, a, c


def cantilever(rng, n_el=16, vertical=None, lab=None):
    """Horizontal cantilever bar (beam2d) or a vertical mast (frame2d, so that its weight loads it axially)."""
    vertical = rng.random() < 0.3 if vertical is None else vertical
    if vertical:
        st, a, _ = _single_beam(rng, "cantilever", str(rng.choice(["steel", "timber", "concrete"])), False, n_el,
                                "frame2d", vertical=True)
        st.supports[a] = ["ux", "uy", "rz"]
        return st
    lab = rng.random() < 0.75 if lab is None else lab
    mat = str(rng.choice(["steel", "aluminium"]) if lab else rng.choice(["timber", "concrete"]))
    st, a, _ = _single_beam(rng, "cantilever", mat, lab, n_el, "beam2d")
    st.supports[a] = ["uy", "rz"]
    return st


def simply_supported(rng, n_el=16, lab=None):
    lab = rng.random() < 0.5 if lab is None else lab
    mat = str(rng.choice(["steel", "aluminium"]) if lab else rng.choice(["timber", "concrete", "steel"]))
    st, a, c = _single_beam(rng, "simply_supported", mat, lab, n_el, "beam2d")
    st.supports[a] = ["uy"]
    st.supports[c] = ["uy"]
    return st


def pinned_pinned(rng, n_el=16):
    """A strip pinned at both ends with its axial motion restrained (frame2d: a preload can act)."""
    mat = str(rng.choice(["steel", "aluminium"]))
    st, a, c = _single_beam(rng, "pinned_pinned", mat, True, n_el, "frame2d")
    st.supports[a] = ["ux", "uy"]
    st.supports[c] = ["ux", "uy"]
    return st


def free_free(rng, n_el=16, lab=None):
    """A bar hung on soft supports for a free-free test (the suspension is part of every truth)."""
    lab = rng.random() < 0.8 if lab is None else lab
    mat = str(rng.choice(["steel", "aluminium"]) if lab else rng.choice(["timber", "concrete"]))
    st, _, _ = _single_beam(rng, "free_free", mat, lab, n_el, "beam2d")
    st.free_free = True
    return st


def _frame_sections(rng, st, material):
    if material == "steel":
        col, beam = draw_i(rng, "column"), draw_i(rng, "beam")
        # Plane frames: columns bend about their strong axis (70 %) or weak axis.
        strong = rng.random() < 0.7
        st.sections["col"] = dict(A=col["A"], Iz=col["strong"] if strong else col["weak"],
                                  Iy=col["weak"] if strong else col["strong"], J=col["J"], shape=col["shape"])
        st.sections["beam"] = dict(A=beam["A"], Iz=beam["strong"], Iy=beam["weak"], J=beam["J"],
                                   shape=beam["shape"])
    elif material == "concrete":
        c = rng.uniform(0.3, 0.5)
        st.sections["col"] = rectangle(round(c, 3), round(c, 3))
        bd = rng.uniform(0.4, 0.65)
        st.sections["beam"] = rectangle(round(bd * rng.uniform(0.5, 0.7), 3), round(bd, 3))
    else:  # glulam timber
        c = rng.uniform(0.16, 0.3)
        st.sections["col"] = rectangle(round(c, 3), round(c, 3))
        st.sections["beam"] = rectangle(round(rng.uniform(0.14, 0.2), 3), round(rng.uniform(0.3, 0.6), 3))


def _plane_grid(st, x0, bays, stories, span, height, n_el, material):
    """Joints and members of one plane frame (clamped bases); returns the joint grid {(bay, story): node}."""
    J = {}
    for s in range(stories + 1):
        for b in range(bays + 1):
            J[b, s] = st.node((x0 + b * span, s * height))
    for b in range(bays + 1):
        st.supports[J[b, 0]] = ["ux", "uy", "rz"]
        for s in range(stories):
            st.member(J[b, s], J[b, s + 1], n_el, "col", material, "column")
    for s in range(1, stories + 1):
        for b in range(bays):
            st.member(J[b, s], J[b + 1, s], n_el, "beam", material, "beam")
    return J


def _plane_frame_dofs(bays, stories, n_el, tie=False):
    joints = (bays + 1) * (stories + 1)
    members = (bays + 1) * stories + bays * stories
    return 3 * (joints + (n_el - 1) * members + (4 * n_el - 1 if tie else 0)) - 3 * (bays + 1)


def plane_frame(rng, n_el=4, tie=None, tall=False):
    """Plane frame of 1-6 bays x 1-8 stories (drawn within the analysis-size budget); optionally a tie rod
    across one bay at mid-story (group 'tie'), a member an imposed strain can load. Tall: slender (stories >= 2
    bays, at least 4), for self-weight."""
    material = str(rng.choice(["steel", "steel", "concrete", "timber"]))
    tie = rng.random() < 0.3 if tie is None else tie
    while True:
        bays = int(rng.integers(1, 7))
        stories = int(rng.integers(4 if tall else 1, 9))
        if _plane_frame_dofs(bays, stories, 4, tie) <= MAX_DOFS_2D and (not tall or stories >= 2 * bays):
            break
    st = Structure("plane_frame", "frame2d")
    st.materials[material] = draw_material(rng, material)
    _frame_sections(rng, st, material)
    span = round(rng.uniform(3.0, 8.0), 2)
    height = round(rng.uniform(2.8, 4.5), 2)
    J = _plane_grid(st, 0.0, bays, stories, span, height, n_el, material)
    st.layout = dict(bays=bays, stories=stories, span=span, height=height, elements_per_member=n_el)
    if tie:
        # A round steel tie rod between the mid-heights of the two columns of one bay and story.
        b, s = int(rng.integers(0, bays)), int(rng.integers(0, stories))
        d = rng.uniform(0.03, 0.07)
        mids = [next(m for m in st.members if m["group"] == "column" and m["nodes"][0] == J[c, s])["nodes"][n_el // 2]
                for c in (b, b + 1)]
        if "steel" not in st.materials:
            st.materials["steel"] = draw_material(rng, "steel")
        st.sections["tie"] = dict(A=math.pi * d * d / 4, Iz=math.pi * d**4 / 64, Iy=math.pi * d**4 / 64,
                                  J=math.pi * d**4 / 32, shape=("circle", d))
        st.member(mids[0], mids[1], 4 * n_el, "tie", "steel", "tie")   # a slender rod: its own modes need more
        st.layout["tie"] = dict(bay=b, story=s, diameter=round(d, 4))
    return st


def linked_frame(rng, n_el=4):
    """Two plane frames side by side joined by link beams (group 'link') at some common levels."""
    material = str(rng.choice(["steel", "steel", "concrete"]))
    while True:
        ba, bb = int(rng.integers(1, 4)), int(rng.integers(1, 4))
        sa, sb = int(rng.integers(2, 7)), int(rng.integers(1, 7))
        links = int(rng.integers(1, min(sa, sb) + 1))
        dofs = _plane_frame_dofs(ba, sa, 4) + _plane_frame_dofs(bb, sb, 4) + 3 * links * 3
        if dofs <= MAX_DOFS_2D:
            break
    st = Structure("linked_frame", "frame2d")
    st.materials[material] = draw_material(rng, material)
    _frame_sections(rng, st, material)
    span_a, span_b = round(rng.uniform(3.0, 7.0), 2), round(rng.uniform(3.0, 7.0), 2)
    height = round(rng.uniform(2.8, 4.2), 2)
    gap = round(rng.uniform(2.5, 6.0), 2)
    Ja = _plane_grid(st, 0.0, ba, sa, span_a, height, n_el, material)
    Jb = _plane_grid(st, ba * span_a + gap, bb, sb, span_b, height, n_el, material)
    levels = sorted(int(v) for v in rng.choice(np.arange(1, min(sa, sb) + 1), size=links, replace=False))
    for s in levels:
        st.member(Ja[ba, s], Jb[0, s], n_el, "beam", material, "link")
    st.layout = dict(bays=(ba, bb), stories=(sa, sb), spans=(span_a, span_b), gap=gap, height=height,
                     links=levels, elements_per_member=n_el)
    return st


def frame3d(rng, n_el=3, tall=False):
    """Space frame of 1-3 x 1-2 bays and 1-5 stories (drawn within the budget) of steel hollow sections (square
    columns, rectangular beams with their depth vertical; closed sections keep torsion modes far above bending);
    the columns' deeper side along x or y."""
    while True:
        bx, by = int(rng.integers(1, 4)), int(rng.integers(1, 3))
        stories = int(rng.integers(3 if tall else 1, 6))
        joints = (bx + 1) * (by + 1) * (stories + 1)
        members = (bx + 1) * (by + 1) * stories + (bx * (by + 1) + by * (bx + 1)) * stories
        if 6 * (joints + 2 * members) - 6 * (bx + 1) * (by + 1) <= MAX_DOFS_3D:
            break
    st = Structure("frame3d", "frame3d")
    st.materials["steel"] = draw_material(rng, "steel")
    c = rng.uniform(0.15, 0.35)
    col = hollow(c, c * rng.uniform(0.8, 1.0), c * rng.uniform(0.04, 0.07))
    d = rng.uniform(0.2, 0.45)
    beam = hollow(d, d * rng.uniform(0.45, 0.65), d * rng.uniform(0.03, 0.05))
    st.sections["col"] = dict(A=col["A"], Iy=col["strong"], Iz=col["weak"], J=col["J"], shape=col["shape"])
    st.sections["beam"] = dict(A=beam["A"], Iy=beam["strong"], Iz=beam["weak"], J=beam["J"], shape=beam["shape"])
    sx, sy = round(rng.uniform(4.0, 8.0), 2), round(rng.uniform(4.0, 7.0), 2)
    height = round(rng.uniform(3.0, 4.2), 2)
    web = [1.0, 0.0, 0.0] if rng.random() < 0.5 else [0.0, 1.0, 0.0]   # the columns' deeper side
    J = {}
    for s in range(stories + 1):
        for j in range(by + 1):
            for i in range(bx + 1):
                J[i, j, s] = st.node((i * sx, j * sy, s * height))
    for (i, j, s), n in J.items():
        if s == 0:
            st.supports[n] = list(fe.SLOTS)
        else:
            st.member(J[i, j, s - 1], n, n_el, "col", "steel", "column", orientation=web)
            if i > 0:
                st.member(J[i - 1, j, s], n, n_el, "beam", "steel", "beam", orientation=[0.0, 0.0, 1.0])
            if j > 0:
                st.member(J[i, j - 1, s], n, n_el, "beam", "steel", "beam", orientation=[0.0, 0.0, 1.0])
    st.layout = dict(bays=(bx, by), stories=stories, spans=(sx, sy), height=height, column_web=web,
                     elements_per_member=n_el)
    return st

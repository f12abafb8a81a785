"""Truth models: the structure as it really is, built by fe.py on a finer mesh with concealed effects.

The truth mesh splits every analysis element into REFINE equal sub-elements, plus the break points the effects
need (ends of a damaged zone, a short link, a mass footprint...). Analysis node ids are kept; points on members
get ids from 10000, other extra nodes (ground points, foundation blocks) from 20000. An effect is a small class:
it draws its place when created (registering the break points it needs), and for any magnitude it modifies
member segments, supports, adds elements and axial forces. Magnitude 0 is never used: the truth *without* the
effect is the model built without it.
"""
import numpy as np

import fe

REFINE = 3
MERGE = 0.01   # break points closer than this share of an analysis element to another point are that point


class Truth:
    """Truth-mesh builder for a Structure and a list of effects."""

    def __init__(self, st, refine=REFINE):
        self.st = st
        self.refine = refine
        self.breaks = {eid: set() for eid in st.elements}
        self.extra = {}              # id -> coordinates of nodes off the members
        self.ids = None

    # set-up (effects call these when they are created, before finalize)
    def point(self, eid, frac):
        """Register a break point on an analysis element; returns its key for node_at."""
        frac = float(round(frac, 12))
        if 0.0 < frac < 1.0:
            self.breaks[eid].add(frac)
        return eid, frac

    def new_node(self, xyz):
        nid = 20000 + len(self.extra)
        self.extra[nid] = np.asarray(xyz, float)
        return nid

    def finalize(self):
        """Fix the truth mesh and number its member points (deterministically, element by element)."""
        self.fracs, self.ids = {}, {}
        nxt = 10000
        for eid in sorted(self.st.elements):
            # The uniform points first, then the break points that are not (nearly) one of them already: a
            # near-coincident pair would make a sliver element that ruins the conditioning of K.
            merged = [float(x) for x in np.round(np.arange(1, self.refine) / self.refine, 12)]
            for x in sorted(self.breaks[eid]):
                if min([abs(x - y) for y in merged + [0.0, 1.0]]) > MERGE:
                    merged.append(x)
            merged.sort()
            self.fracs[eid] = [0.0] + merged + [1.0]
            a, b = self.st.elements[eid]["n"]
            self.ids[eid, 0.0], self.ids[eid, 1.0] = a, b
            for x in merged:
                self.ids[eid, x] = nxt
                nxt += 1

    def node_at(self, eid, frac):
        """Node at a registered point (or the point it was merged into)."""
        best = min(self.fracs[eid], key=lambda x: abs(x - frac))
        assert abs(best - frac) <= MERGE + 1e-12, (eid, frac)
        return self.ids[eid, best]

    # building
    def build(self, effects, mags):
        """The fe.Model of the truth with these effects at these magnitudes, and its axial forces."""
        st = self.st
        m = fe.Model(st.ndim)
        for nid, x in st.nodes.items():
            m.node(nid, *x)
        for (eid, frac), nid in self.ids.items():
            if nid >= 10000:
                m.node(nid, *st.point(eid, frac))
        for nid, x in self.extra.items():
            m.node(nid, *x)
        if st.element == "beam2d":
            m.restrain_everywhere(["ux"])
        self.segment_of = {}
        pairs = list(zip(effects, mags))
        for eid in sorted(st.elements):
            p = st.props(eid)
            fr = self.fracs[eid]
            for x0, x1 in zip(fr[:-1], fr[1:]):
                mod = dict(E=1.0, I=1.0, mu=0.0, eps0=0.0, skip=False)
                for eff, mag in pairs:
                    d = eff.segment(eid, x0, x1, mag)
                    if d:
                        mod["E"] *= d.get("E", 1.0)
                        mod["I"] *= d.get("I", 1.0)
                        mod["mu"] += d.get("mu", 0.0)
                        mod["eps0"] += d.get("eps0", 0.0)
                        mod["skip"] |= d.get("skip", False)
                if mod["skip"]:
                    continue
                rho = p["rho"] + mod["mu"] / p["A"]   # non-structural mass rides on the member's translations
                idx = m.frame(self.ids[eid, x0], self.ids[eid, x1], p["E"] * mod["E"], p["G"] * mod["E"], p["A"],
                              p["Iz"] * mod["I"], rho, Iy=p["Iy"] * mod["I"], J=p["J"] * mod["E"],
                              orientation=p["orientation"], eps0=mod["eps0"],
                              tag="member" if mod["mu"] == 0.0 else "member+nsm")
                self.segment_of[idx] = (eid, x0, x1)
        supports = {n: list(d) for n, d in st.supports.items()}
        for eff, mag in pairs:
            eff.supports(supports, mag)
        for n, d in supports.items():
            m.support(n, d)
        for eff, mag in pairs:
            eff.extras(m, self, mag)
        axial = {}
        for eff, mag in pairs:
            for i, N in eff.axial(m, self, mag).items():
                axial[i] = axial.get(i, 0.0) + N
        return m, axial

    def measurable_labels(self, dofs=None):
        """(node, slot) of the analysis model's unrestrained translations (shared by every truth)."""
        return [(n, fe.SLOT[d]) for n, d in self.st.measurable() if dofs is None or d in dofs]


class ContinuumTruth:
    """A single straight beam as a plane-stress Q9 continuum (the truth of the shear kind).

    The beam's depth is the magnitude (shear deformation grows as L/h falls). The analysis nodes become the
    mid-height nodes at their x; the mesh has 4 Q9 elements through the depth and 4 node columns per analysis
    element along the length. Supports act on whole end faces (clamped root: ux = uy = 0; a simple support:
    uy = 0 over the face, the face free to rotate; axial restraint at mid-height)."""

    def __init__(self, st, ny=4):
        self.st = st
        self.ny = ny
        self.n_an = len(st.elements)
        self.nx = 2 * self.n_an          # Q9 elements along the length: node spacing L / (4 n)
        self.L = st.member_length(0)

    def build(self, effects, mags):
        """The continuum with the effects; its depth is the magnitude of the shear effect among them."""
        st = self.st
        depth = next(mag for eff, mag in zip(effects, mags) if eff.kind == "shear")
        p = st.props(1)
        b = st.sections["s"]["shape"][1]
        nx, ny = self.nx, self.ny
        m = fe.Model(2)
        chain = st.members[0]["nodes"]
        ids = {}
        nxt = 10000
        for j in range(2 * ny + 1):
            for i in range(2 * nx + 1):
                if j == ny and i % 4 == 0:
                    ids[i, j] = chain[i // 4]
                else:
                    ids[i, j] = nxt
                    nxt += 1
                m.node(ids[i, j], self.L * i / (2 * nx), depth * (j / (2 * ny) - 0.5))
        for ex in range(nx):
            for ey in range(ny):
                m.quad9([ids[2 * ex + i, 2 * ey + j] for j in range(3) for i in range(3)], self.L / nx, depth / ny,
                        p["E"], p["nu"], b, p["rho"])
        self.ids = ids
        face = {0: [ids[0, j] for j in range(2 * ny + 1)], 1: [ids[2 * nx, j] for j in range(2 * ny + 1)]}
        for end, node in ((0, chain[0]), (1, chain[-1])):
            dofs = st.supports.get(node, [])
            if "rz" in dofs:                      # clamped: the whole face
                for n in face[end]:
                    m.support(n, ["ux", "uy"])
            elif "uy" in dofs:                    # simple support: the face held vertically, free to rotate
                for n in face[end]:
                    m.support(n, ["uy"])
                if "ux" in dofs or end == 0:
                    m.support(node, ["ux"])
        for eff, mag in zip(effects, mags):
            if eff.kind != "shear":
                eff.extras(m, self, mag)
        return m, {}

    def node_near(self, x):
        """Mid-height node nearest to x along the beam."""
        i = int(round(x / self.L * 2 * self.nx))
        return self.ids[i, self.ny]

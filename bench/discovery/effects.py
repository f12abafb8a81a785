"""The concealed effects (truth kinds), each built by a route that differs from the candidate that should
explain it.

An effect draws its place when created and then acts, for a magnitude `mag`, through four hooks the truth
builder calls: segment (properties of a truth member segment), supports, extras (added elements) and axial
(axial forces for geometric stiffness). `accept()` says which candidate kinds, nodes, elements or element sets
count as naming it; `reference(mag)` gives the value each accepted candidate should report, in dynid's units
(engine/src/candidates.cpp, physical()). The magnitude is set by generate.py so that the largest frequency
shift of the data's modes meets a target.
"""
import math

import numpy as np

import fe
from truth import ContinuumTruth


def _unit(v):
    return np.asarray(v, float) / np.linalg.norm(v)


def _perpendicular(st, mi, rng):
    """A direction normal to a member: 'up' for horizontal members, a random horizontal side for columns."""
    a = st.direction(mi)
    vert = np.eye(3)[st.vertical]
    if abs(a @ vert) < 0.7:
        n = vert - (vert @ a) * a
    elif st.ndim == 2:
        n = np.array([1.0, 0.0, 0.0]) * rng.choice([-1.0, 1.0])
    else:
        n = np.eye(3)[int(rng.integers(0, 2))] * rng.choice([-1.0, 1.0])
    return _unit(n)


def _choose_member(st, rng, prefer=None, share=0.7, groups=None):
    """A member, of group `prefer` with probability `share` when such members exist."""
    ms = [i for i, m in enumerate(st.members) if groups is None or m["group"] in groups]
    pref = [i for i in ms if st.members[i]["group"] == prefer]
    if pref and (rng.random() < share or len(pref) == len(ms)):
        return int(rng.choice(pref))
    rest = [i for i in ms if i not in pref] or ms
    return int(rng.choice(rest))


def _section_stiffness(st, eid, axis=None):
    """E I of an element for bending in the plane (2D) or about a global rotation axis (3D)."""
    p = st.props(eid)
    if st.ndim == 2:
        return p["E"] * p["Iz"]
    a, b = st.elements[eid]["n"]
    R = fe.frame_axes(st.nodes[a], st.nodes[b], p["orientation"])
    g = np.eye(3)[axis]
    return p["E"] * (p["Iy"] if abs(R[1] @ g) > abs(R[2] @ g) else p["Iz"])


class Effect:
    kind = ""
    variant = ""
    log = True          # bisection in log(mag)

    def segment(self, eid, x0, x1, mag):
        return None

    def supports(self, supports, mag):
        pass

    def extras(self, m, truth, mag):
        pass

    def axial(self, m, truth, mag):
        return {}

    def finish(self, m, truth, mag, axial):
        """Called on the final truth build (effects whose reference comes from a static analysis)."""

    def accept(self):
        raise NotImplementedError

    def reference(self, mag):
        raise NotImplementedError

    def describe(self, mag):
        raise NotImplementedError


# ---- masses ------------------------------------------------------------------------------------------------

class AttachedMass(Effect):
    """A block of finite size mounted on a member between analysis nodes: its mass spread over 2-4 truth nodes
    of its footprint, on top of (or beside) the member, each part with rotary inertia."""
    kind = "attached_mass"

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        mi = _choose_member(st, rng, prefer="beam", groups=("beam", "column", "link"))
        Lm = st.member_length(mi)
        lb = rng.uniform(0.01, 0.04) * Lm           # the block's footprint along the member
        while True:                                 # its centre away from the analysis nodes
            s = rng.uniform(0.1 * Lm, 0.9 * Lm)
            eid, c = st.locate(mi, s)
            if 0.2 < c < 0.8:
                break
        npts = int(rng.integers(2, 5))
        self.keys = [ctx.truth.point(*st.locate(mi, s + x * lb)) for x in np.linspace(-0.5, 0.5, npts)]
        self.height = rng.uniform(0.2, 0.6) * lb
        self.offset = _perpendicular(st, mi, rng) * (st.depth(mi) / 2 + self.height / 2)
        self.centre = st.point(eid, c)
        self.st, self.eid, self.c, self.lb = st, eid, c, lb
        self.lo, self.hi = 1e-5 * st.mass(), 3.0 * st.mass()

    def extras(self, m, truth, mag):
        part = mag / len(self.keys)
        inertia = part * self.height**2 / 12
        for key in self.keys:
            m.point_mass(truth.node_at(*key), part, inertia=(inertia,) * 3, offset=self.offset, tag="effect")

    def accept(self):
        st, Le = self.st, self.st.length(self.eid)
        nodes = [n for n, x in st.nodes.items() if np.linalg.norm(x - self.centre) <= Le * 1.0001]
        els = []
        for e in st.elements:
            a, b = (st.nodes[n] for n in st.elements[e]["n"])
            t = np.clip((self.centre - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
            if np.linalg.norm(a + t * (b - a) - self.centre) <= Le * 1.0001:
                els.append(e)
        return dict(kinds=["lumped_mass", "element_point_mass", "element_mass"], nodes=sorted(nodes),
                    elements=sorted(els))

    def reference(self, mag):
        st = self.st
        pct = {e: 100 * mag / (st.props(e)["rho"] * st.props(e)["A"] * st.length(e)) for e in self.accept()["elements"]}
        return {"lumped_mass": dict(parameter="mass", unit="kg", value=mag),
                "element_point_mass": dict(parameter="mass", unit="kg", value=mag),
                "element_mass": dict(parameter="mass change", unit="%", per_element=pct, rule="single")}

    def describe(self, mag):
        return (f"a {mag:.4g} kg block, {self.lb:.3g} m long, on element {self.eid} at {self.c:.2f} of its length "
                f"(spread over {len(self.keys)} truth nodes, mounted {np.linalg.norm(self.offset):.3g} m off the axis)")


class SensorMass(Effect):
    """Accelerometers of unequal mass (uniaxial / triaxial, +-30 %) with rotary inertia from their mounting height,
    each fixed slightly off its measured node."""
    kind = "sensor_mass"

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        nodes = sorted({n for n, _ in ctx.sensors})
        w = rng.uniform(0.7, 1.3, len(nodes))
        self.weights = w / w.mean()
        self.keys, self.size, self.offsets = [], [], []
        for n in nodes:
            # The element on the interior side of the node (either side for interior nodes).
            els = [e for e, d in st.elements.items() if n in d["n"]]
            eid = int(rng.choice(els))
            start = st.elements[eid]["n"][0] == n
            d = rng.uniform(0.05, 0.15)
            self.keys.append(ctx.truth.point(eid, d if start else 1 - d))
            a = rng.uniform(0.008, 0.02)
            self.size.append(a)
            self.offsets.append(_perpendicular(st, st.elements[eid]["member"], rng) * (st.depth(0) / 2 + a / 2))
        self.nodes = nodes
        self.lo, self.hi = 1e-6 * st.mass(), 0.3 * st.mass() / len(nodes)

    def extras(self, m, truth, mag):
        for key, w, a, off in zip(self.keys, self.weights, self.size, self.offsets):
            mi = mag * w
            m.point_mass(truth.node_at(*key), mi, inertia=(mi * a * a / 6,) * 3, offset=off, tag="effect")

    def accept(self):
        return dict(kinds=["sensor_mass"], global_=True)

    def reference(self, mag):
        return {"sensor_mass": dict(parameter="mass per sensor", unit="kg", value=mag)}

    def describe(self, mag):
        return (f"{len(self.nodes)} accelerometers of {mag * self.weights.min():.3g}-{mag * self.weights.max():.3g} kg "
                f"(mean {mag:.3g} kg) mounted slightly off the measured nodes")


class DistributedMass(Effect):
    """Non-structural mass on the members of a group (slabs, cladding, fittings), varying +-20 % along each
    member; the group's length-weighted mean is the reference."""
    kind = "distributed_mass"

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        groups = st.groups()
        if len(groups) == 1:
            self.group = groups[0]
        else:
            self.group = "beam" if rng.random() < 0.7 else str(rng.choice([g for g in groups if g != "tie"]))
        self.els = set(st.group_elements(self.group))
        self.members = sorted({st.elements[e]["member"] for e in self.els})
        # Profile p(s) = 1 + 0.2 sin(pi k s / L + phase) per member, normalised to a group mean of 1.
        self.st = st
        self.prof = {mi: (int(rng.integers(1, 3)), rng.uniform(0, 2 * math.pi)) for mi in self.members}
        total = sum(self._integral(mi, 0.0, st.member_length(mi)) for mi in self.members)
        self.norm = sum(st.member_length(mi) for mi in self.members) / total
        rhoA = np.mean([st.props(e)["rho"] * st.props(e)["A"] for e in self.els])
        self.lo, self.hi = 1e-4 * rhoA, 10 * rhoA

    def _integral(self, mi, s0, s1):
        """Integral of the profile over [s0, s1] along member mi."""
        k, ph = self.prof[mi]
        w = math.pi * k / self.st.member_length(mi)
        return (s1 - s0) - 0.2 / w * (math.cos(w * s1 + ph) - math.cos(w * s0 + ph))

    def segment(self, eid, x0, x1, mag):
        if eid not in self.els:
            return None
        st = self.st
        mi, s, L = st.elements[eid]["member"], st.offset(eid), st.length(eid)
        mean = self._integral(mi, s + x0 * L, s + x1 * L) / ((x1 - x0) * L)
        return dict(mu=mag * self.norm * mean)

    def accept(self):
        return dict(kinds=["distributed_mass"], element_sets=[sorted(self.els)])

    def reference(self, mag):
        return {"distributed_mass": dict(parameter="mass per length", unit="kg/m", value=mag)}

    def describe(self, mag):
        return f"non-structural mass of {mag:.4g} kg/m on average (+-20 % along each member) on group '{self.group}'"


# ---- connections and supports ------------------------------------------------------------------------------

class JointFlexibility(Effect):
    """A member end joined to its joint through a short flexible link (1-2 % of the member, reduced bending
    stiffness), or an eccentric end-plate connection: the member ends e = 10-40 mm from the joint (a rigid
    offset) and is tied to it by a rotational spring k.

    Magnitude: the added end flexibility c (rad / N m) relative to the analysis member (full length, E I):
    link: l / EI_link - l / EI; offset e + spring k: 1 / k - e / EI. Reference: 1 / c."""
    kind = "joint_flexibility"

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        joints = [n for n in st.nodes if len(st.joints_of(n)) >= 2 and n not in st.supports]
        self.joint = int(rng.choice(joints))
        ends = st.joints_of(self.joint)
        beams = [e for e in ends if st.members[e[0]]["group"] != "column"]
        mi, end = beams[int(rng.integers(len(beams)))] if beams and rng.random() < 0.75 else ends[int(rng.integers(len(ends)))]
        self.mi, self.end = mi, end
        self.eid = st.end_element(mi, end)
        Lm, Le = st.member_length(mi), st.length(self.eid)
        self.EI = _section_stiffness(st, self.eid)
        self.variant = "link" if rng.random() < 0.6 else "offset + spring"
        self.l = rng.uniform(0.01, 0.02) * Lm if self.variant == "link" else min(rng.uniform(0.01, 0.04), 0.01 * Lm)
        f = self.l / Le if end == 0 else 1 - self.l / Le
        self.key = ctx.truth.point(self.eid, f)
        self.zone = (0.0, f) if end == 0 else (f, 1.0)
        self.st = st
        # Up to k = E I / (3 L), a twelfth of the member's own end stiffness 4 E I / L: a softer spring is a pin,
        # and its stiffness no longer shows in the frequencies.
        self.lo, self.hi = 1e-4 * Lm / self.EI, 3 * Lm / self.EI
        if self.variant != "link":
            # The spring's flexibility at least three times the offset's removed one (1 / k >= 3 e / EI):
            # otherwise the rigid offset, not the spring, would shape the connection.
            self.lo = max(self.lo, 2 * self.l / self.EI)

    def segment(self, eid, x0, x1, mag):
        if eid != self.eid or x0 < self.zone[0] - 1e-9 or x1 > self.zone[1] + 1e-9:
            return None
        if self.variant == "link":
            return dict(I=1.0 / (1.0 + mag * self.EI / self.l))
        return dict(skip=True)

    def extras(self, m, truth, mag):
        if self.variant == "link":
            return
        p = truth.node_at(*self.key)
        m.rigid_link(p, self.joint, rotations=False)
        m.spring2(p, self.joint, "rz", 1.0 / (mag + self.l / self.EI), tag="effect")
        pr = self.st.props(self.eid)
        m.point_mass(self.joint, pr["rho"] * pr["A"] * self.l, tag="effect")   # the offset's own mass

    def accept(self):
        return dict(kinds=["semi_rigid_joint"], nodes=[self.joint], elements=[self.eid])

    def reference(self, mag):
        return {"semi_rigid_joint": dict(parameter="stiffness", unit="N m/rad", value=1.0 / mag)}

    def describe(self, mag):
        if self.variant == "link":
            return (f"element {self.eid} joins joint {self.joint} through a {self.l * 1000:.0f} mm link of "
                    f"E I = {self.l / (self.l / self.EI + mag):.4g} N m2 (added end flexibility of "
                    f"{1 / mag:.4g} N m/rad)")
        return (f"element {self.eid} ends {self.l * 1000:.0f} mm from joint {self.joint}, tied to it by a spring of "
                f"{1 / (mag + self.l / self.EI):.4g} N m/rad (added end flexibility of {1 / mag:.4g} N m/rad)")


class SupportFlexibility(Effect):
    """A support that is not rigid: a short stub (0.3-1 % of the member) of reduced bending stiffness below the
    support node, or a foundation block (mass, rotary inertia) on a rotational spring, held by stiff
    translational springs.
    Space frames: flexible about one horizontal axis only. Reference: the rotational stiffness."""
    kind = "support_flexibility"

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        bases = [n for n in st.supports if len(st.joints_of(n)) == 1 and st.supports[n] and
                 any(d.startswith("r") for d in st.supports[n])]
        self.node = int(rng.choice(bases))
        self.mi, _ = st.joints_of(self.node)[0]
        self.eid = st.end_element(self.mi, 0 if st.members[self.mi]["nodes"][0] == self.node else 1)
        self.axis = 5 if st.ndim == 2 else int(rng.integers(3, 5))       # rz, or rx / ry
        self.EI = _section_stiffness(st, self.eid, None if st.ndim == 2 else self.axis - 3)
        Lm = st.member_length(self.mi)
        self.variant = "stub" if rng.random() < 0.5 else "block"
        away = -st.direction(self.mi) if st.members[self.mi]["nodes"][0] == self.node else st.direction(self.mi)
        lab = Lm < 2.0
        if self.variant == "stub":
            self.l = rng.uniform(0.003, 0.01) * Lm
            self.ground = ctx.truth.new_node(st.nodes[self.node] + away * self.l)
        else:
            self.e = rng.uniform(0.005, 0.02) if lab else rng.uniform(0.05, 0.2)
            pr = st.props(self.eid)
            self.block_mass = rng.uniform(0.05, 0.3) * pr["rho"] * pr["A"] * Lm
            self.block = ctx.truth.new_node(st.nodes[self.node] + away * self.e)
        self.st = st
        self.kstiff = 1e3 * 4 * self.EI / Lm
        self.lo, self.hi = 1e-4 * Lm / self.EI, 3 * Lm / self.EI     # down to k = E I / (3 L), as for joints

    def supports(self, supports, mag):
        supports.pop(self.node, None)

    def extras(self, m, truth, mag):
        st, pr = self.st, self.st.props(self.eid)
        names = [fe.SLOTS[s] for s in m.slots()]
        rot = [d for d in names if d.startswith("r")]
        if self.variant == "stub":
            # Flexible about the chosen axis (E I_stub = l / c), effectively rigid about the others.
            I_flex = self.l / (mag * pr["E"])
            if st.ndim == 2:
                Iz, Iy, J = I_flex, 0.0, 0.0
            else:
                a, b = st.elements[self.eid]["n"]
                R = fe.frame_axes(st.nodes[a], st.nodes[b], pr["orientation"])
                about_y = abs(R[1] @ np.eye(3)[self.axis - 3]) > abs(R[2] @ np.eye(3)[self.axis - 3])
                Iy = I_flex if about_y else 1e3 * pr["Iy"]
                Iz = 1e3 * pr["Iz"] if about_y else I_flex
                J = 1e3 * pr["J"]
            m.frame(self.ground, self.node, pr["E"], pr["G"], pr["A"], Iz, pr["rho"], Iy=Iy, J=J,
                    orientation=pr["orientation"], tag="effect")
            m.support(self.ground)
            return
        # Foundation block: rigid with the support node, its centre e away; the support node held in translation
        # (stiff springs: the slab or pedestal around it), its rotation on the spring.
        m.rigid_link(self.block, self.node)
        Ib = self.block_mass * (2 * self.e) ** 2 / 6     # a cube of side 2 e about its centre
        m.point_mass(self.block, self.block_mass, inertia=(Ib,) * 3, tag="effect")
        for d in rot:
            m.spring(self.node, d, 1.0 / mag if fe.SLOT[d] == self.axis else self.kstiff, tag="effect")
        kt = 1e3 * pr["E"] * pr["A"] / st.member_length(self.mi)
        for d in names:
            if not d.startswith("r"):
                m.spring(self.node, d, kt, tag="effect")

    def accept(self):
        return dict(kinds=["flexible_support"], nodes=[self.node], elements=[self.eid])

    def reference(self, mag):
        return {"flexible_support": dict(parameter="stiffness", unit="N m/rad", value=1.0 / mag)}

    def describe(self, mag):
        how = (f"a {self.l * 1000:.0f} mm stub" if self.variant == "stub" else
               f"a {self.block_mass:.3g} kg foundation block {self.e:.3g} m deep")
        return (f"support {self.node} rests on {how}: rotational stiffness {1 / mag:.4g} N m/rad about "
                f"{fe.SLOTS[self.axis]}")


class SupportSpring(Effect):
    """An unmodelled bracing strut: a bar of finite axial stiffness from the ground to a point near (not at) a
    node, inclined up to 20 degrees from the DOF's direction, attached through a short bracket or to the member
    a little away from the node. Reference: the strut's stiffness along the DOF, k cos^2(alpha)."""
    kind = "support_spring"

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        cands = [(n, d) for n, d in st.sensing() if n not in st.supports]
        if st.family in ("plane_frame", "linked_frame", "frame3d") and rng.random() < 0.75:
            cands = [(n, d) for n, d in cands if fe.SLOT[d] != st.vertical]      # lateral bracing
        self.node, self.dof = cands[int(rng.integers(len(cands)))]
        self.node = int(self.node)
        axis = np.eye(3)[fe.SLOT[self.dof]]
        # Tilt within a plane containing the DOF axis (the structure's plane in 2D).
        other = np.eye(3)[st.vertical] if fe.SLOT[self.dof] != st.vertical else np.eye(3)[0]
        self.alpha = rng.uniform(-20, 20) * math.pi / 180
        self.dir = math.cos(self.alpha) * axis + math.sin(self.alpha) * other
        lab = max(np.ptp([x[i] for x in st.nodes.values()]) for i in range(3)) < 2.0
        self.length = rng.uniform(0.05, 0.3) if lab else rng.uniform(1.5, 3.0)
        els = [e for e, d in st.elements.items() if self.node in d["n"]]
        eid = int(rng.choice(els))
        self.variant = "bracket" if rng.random() < 0.5 else "near"
        if self.variant == "bracket":
            mi = st.elements[eid]["member"]
            self.offset = st.direction(mi) * rng.choice([-1, 1]) * rng.uniform(0.02, 0.06) * st.length(eid)
            self.key = None
            at = st.nodes[self.node] + self.offset
        else:
            d = rng.uniform(0.03, 0.10)
            self.key = ctx.truth.point(eid, d if st.elements[eid]["n"][0] == self.node else 1 - d)
            at = st.point(*self.key)
            self.offset = None
        self.ground = ctx.truth.new_node(at - self.dir * self.length)
        # Up to the structure's own static stiffness at the node: a stiffer strut pins the node and
        # its stiffness no longer shows in the frequencies.
        k = ctx.point_stiffness(self.node, self.dof)
        self.lo, self.hi = 1e-5 * k, k

    def extras(self, m, truth, mag):
        EA = mag * self.length
        rhoA = 7850.0 * EA / 2.1e11   # a steel strut of that axial stiffness
        end = self.node if self.key is None else truth.node_at(*self.key)
        m.bar(self.ground, end, EA, rhoA=rhoA, offsets=(None, self.offset), tag="effect")
        m.support(self.ground)

    def accept(self):
        return dict(kinds=["grounded_spring"], nodes=[self.node])

    def reference(self, mag):
        return {"grounded_spring": dict(parameter="stiffness", unit="N/m", value=mag * math.cos(self.alpha) ** 2)}

    def describe(self, mag):
        where = "through a bracket" if self.variant == "bracket" else "to the member a little away from it"
        return (f"a strut of {mag:.4g} N/m ({math.degrees(self.alpha):.0f} deg from {self.dof}) braces node "
                f"{self.node} {where}")


# ---- stiffness loss ------------------------------------------------------------------------------------------

class Damage(Effect):
    """A reduced section (E I and E A, by the fraction mag) over part of a member, its ends away from the
    analysis nodes. Reference per analysis element: the flexibility-equivalent stiffness change
    1 / (1 + delta_e) = 1 + (l_e / L_e) mag / (1 - mag), l_e the damaged length inside the element."""
    kind = "damage"
    log = False

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        mi = _choose_member(st, rng, prefer="beam", share=0.6, groups=("beam", "column", "link"))
        els = st.members[mi]["elements"]
        Le = st.length(els[0])
        Lm = st.member_length(mi)
        ld = rng.uniform(0.03, 0.2) * Lm
        bounds = np.cumsum([0.0] + [st.length(e) for e in els])
        for _ in range(100):
            s0 = rng.uniform(0.03 * Lm, Lm - ld - 0.03 * Lm)
            if min(abs(s0 - bounds).min(), abs(s0 + ld - bounds).min()) > 0.1 * Le:
                break
        self.mi, self.s0, self.s1 = mi, s0, s0 + ld
        for s in (self.s0, self.s1):
            ctx.truth.point(*st.locate(mi, s))
        self.st = st
        self.lo, self.hi = 0.002, 0.9

    def overlap(self, eid):
        st = self.st
        if st.elements[eid]["member"] != self.mi:
            return 0.0
        s, L = st.offset(eid), st.length(eid)
        return max(0.0, min(s + L, self.s1) - max(s, self.s0))

    def segment(self, eid, x0, x1, mag):
        st = self.st
        if st.elements[eid]["member"] != self.mi:
            return None
        s, L = st.offset(eid), st.length(eid)
        mid = s + 0.5 * (x0 + x1) * L
        return dict(E=1.0 - mag) if self.s0 <= mid <= self.s1 else None

    def accept(self):
        return dict(kinds=["element_stiffness", "member_damage"],
                    elements=[e for e in self.st.members[self.mi]["elements"] if self.overlap(e) > 0])

    def reference(self, mag):
        pct = {e: 100 * (1 / (1 + self.overlap(e) / self.st.length(e) * mag / (1 - mag)) - 1)
               for e in self.accept()["elements"]}
        spec = dict(parameter="stiffness change", unit="%", per_element=pct, rule="flexibility")
        return {"element_stiffness": spec, "member_damage": dict(spec)}

    def describe(self, mag):
        return (f"{100 * mag:.1f} % of E I and E A lost over {self.s1 - self.s0:.3g} m of member {self.mi} "
                f"(from {self.s0:.3g} m; elements {self.accept()['elements']})")


# ---- global effects ------------------------------------------------------------------------------------------

class Shear(Effect):
    """A deep beam: the truth is a plane-stress continuum (truth.ContinuumTruth); the magnitude is its depth.
    Reference: Cowper's kappa for a rectangle, 10 (1 + nu) / (12 + 11 nu)."""
    kind = "shear"

    def __init__(self, ctx):
        self.st = ctx.st
        L = ctx.st.member_length(0)
        self.lo, self.hi = L / 60, L / 3

    def accept(self):
        return dict(kinds=["shear_deformation"], element_sets=[sorted(self.st.elements)])

    def reference(self, mag):
        nu = self.st.props(1)["nu"]
        return {"shear_deformation": dict(parameter="shear coefficient kappa", unit="",
                                          value=10 * (1 + nu) / (12 + 11 * nu))}

    def describe(self, mag):
        return f"a deep beam (L/h = {self.st.member_length(0) / mag:.2f}) that deforms in shear: plane-stress continuum"


class Preload(Effect):
    """An axial force set up by an imposed strain (a turnbuckle, thermal strain) in members restrained axially:
    a pinned-pinned strip, or a frame's tie rod (which also loads its neighbours). The axial forces come from a
    static analysis of the truth; reference: the mean axial force of the loaded members (tension > 0)."""
    kind = "preload"

    def __init__(self, ctx):
        st, rng = ctx.st, ctx.rng
        self.group = "tie" if "tie" in st.groups() else st.groups()[0]
        self.els = set(st.group_elements(self.group))
        self.sign = 1.0 if self.group == "tie" or rng.random() < 0.75 else -1.0
        self.st = st
        self.force = None
        self.lo, self.hi = 1e-8, 5e-3

    def segment(self, eid, x0, x1, mag):
        return dict(eps0=-self.sign * mag) if eid in self.els else None

    def axial(self, m, truth, mag):
        return m.static_axial_forces()

    def finish(self, m, truth, mag, axial):
        seg = [(i, truth.segment_of[i]) for i in truth.segment_of if truth.segment_of[i][0] in self.els]
        lengths = np.array([(x1 - x0) * self.st.length(e) for _, (e, x0, x1) in seg])
        self.force = float(np.dot([axial[i] for i, _ in seg], lengths) / lengths.sum())

    def accept(self):
        return dict(kinds=["axial_preload"], element_sets=[sorted(self.els)])

    def reference(self, mag):
        return {"axial_preload": dict(parameter="axial force", unit="N", value=self.force)}

    def describe(self, mag):
        what = "tension" if self.sign > 0 else "compression"
        return (f"an imposed strain of {-self.sign * mag:.3g} in group '{self.group}' sets up {what} "
                f"({self.force:.4g} N on average)" if self.force is not None else "")


class SelfWeight(Effect):
    """Geometric stiffness of the axial forces of a static analysis of the truth under gravity (-y in a plane,
    -z in space) on its members' weight, times a load factor. Reference: the factor."""
    kind = "self_weight"

    def __init__(self, ctx):
        self.st = ctx.st
        self.lo, self.hi = 1e-2, 1e4

    def axial(self, m, truth, mag):
        return {i: mag * N for i, N in m.gravity_axial_forces(tags=("member",)).items()}

    def accept(self):
        return dict(kinds=["self_weight"], global_=True)

    def reference(self, mag):
        return {"self_weight": dict(parameter="load factor", unit="", value=mag)}

    def describe(self, mag):
        return f"axial forces of {mag:.4g} x the structure's own weight (static analysis, geometric stiffness)"


class Suspension(Effect):
    """The suspension of a free-free test: vertical springs (+-20 % between the two) with a little rotational
    stiffness (k a^2, a = 2-8 mm) at two points 0.2-1 % of the length in from the ends. As background of every
    free-free truth it is soft (rigid-body frequencies 1-5 % of the first elastic one); as the `suspension` kind
    its magnitude is scaled. Reference: the mean vertical stiffness per point."""
    kind = "suspension"

    def __init__(self, ctx, background=False):
        st, rng = ctx.st, ctx.rng
        L = st.member_length(0)
        self.at = [rng.uniform(0.002, 0.01) * L, L - rng.uniform(0.002, 0.01) * L]
        continuum = isinstance(ctx.truth, ContinuumTruth)
        self.keys = None if continuum else [ctx.truth.point(*st.locate(0, s)) for s in self.at]
        self.split = rng.uniform(-0.2, 0.2)
        self.a = rng.uniform(0.002, 0.008)
        self.background = background
        self.pendulum = st.mass() * 9.81 / (2 * rng.uniform(0.3, 1.0))   # cords 0.3-1 m long, per point
        w1 = 2 * math.pi * ctx.f1
        self.k_soft = (rng.uniform(0.01, 0.05) * w1) ** 2 * st.mass() / 2
        self.lo, self.hi = self.k_soft, 0.25 * w1 * w1 * st.mass()    # bounce below about 0.7 f1

    def extras(self, m, truth, mag):
        for i, s in enumerate(self.at):
            k = mag * (1 + self.split if i == 0 else 1 - self.split)
            n = truth.node_near(s) if self.keys is None else truth.node_at(*self.keys[i])
            m.spring(n, "uy", k, tag="effect")
            if self.keys is None:          # continuum: the cords' pendulum stiffness holds it along the beam
                m.spring(n, "ux", self.pendulum, tag="effect")
            else:
                m.spring(n, "rz", k * self.a**2, tag="effect")

    def accept(self):
        return dict(kinds=["suspension_stiffness"], global_=True)

    def reference(self, mag):
        return {"suspension_stiffness": dict(parameter="stiffness per point", unit="N/m", value=mag)}

    def describe(self, mag):
        return (f"suspension springs of {mag:.4g} N/m on average at {self.at[0]:.3g} m and {self.at[1]:.3g} m "
                f"(rotational {mag * self.a**2:.3g} N m/rad)")


KINDS = {"attached_mass": AttachedMass, "sensor_mass": SensorMass, "distributed_mass": DistributedMass,
         "joint_flexibility": JointFlexibility, "support_flexibility": SupportFlexibility,
         "support_spring": SupportSpring, "damage": Damage, "shear": Shear, "preload": Preload,
         "self_weight": SelfWeight, "suspension": Suspension}

"""The ideal candidate: the analysis model plus the candidate that should explain an effect, in its own form
(as engine/src/candidates.cpp describes it), built here in fe.py.

For every case the generator records how well this ideal candidate, at the reference value and at its own best
value, reproduces the truth's data modes. A residual far below the effect's shift says the reference is what
a perfect engine would find; a larger one says the candidate form itself cannot represent the truth exactly
(an off-node mass named at a node, a strut near a node), which is part of what the benchmark measures.
"""
import math

import numpy as np
from scipy.optimize import minimize_scalar

import fe
from modes import Modes, mac


def _model(st, eff, value):
    """fe.Model of the analysis model with the candidate of `eff` (an effects.Effect) at `value`."""
    kind = CANDIDATE[eff.kind]
    m = fe.Model(st.ndim)
    for nid, x in st.nodes.items():
        m.node(nid, *x)
    if st.element == "beam2d":
        m.restrain_everywhere(["ux"])
    acc = eff.accept()
    group = set(acc["element_sets"][0]) if "element_sets" in acc else set()
    damaged = set(acc.get("elements", [])) if kind == "member_damage" else set()
    joint_el = eff.eid if kind == "semi_rigid_joint" else None
    for eid in sorted(st.elements):
        p = st.props(eid)
        a, b = st.elements[eid]["n"]
        if eid == joint_el:             # the member end released onto a spring at the joint
            m.node(30000, *st.nodes[eff.joint])
            a, b = (30000, b) if a == eff.joint else (a, 30000)
        E, rho, kappa = p["E"], p["rho"], None
        if eid in damaged:
            E *= 1 + value / 100
        if kind == "distributed_mass" and eid in group:
            rho += value / p["A"]
        if kind == "shear_deformation":
            kappa = value
        m.frame(a, b, E, p["G"] * E / p["E"], p["A"], p["Iz"], rho, Iy=p["Iy"], J=p["J"], orientation=p["orientation"],
                kappa=kappa, rotary=kind == "shear_deformation")
    supports = {n: list(d) for n, d in st.supports.items()}
    if kind == "flexible_support":
        axis = fe.SLOTS[eff.axis]
        supports[eff.node] = [d for d in supports[eff.node] if d != axis]
        m.spring(eff.node, axis, value)
    for n, d in supports.items():
        m.support(n, d)
    if kind == "semi_rigid_joint":
        m.rigid_link(30000, eff.joint, rotations=False)
        m.spring2(30000, eff.joint, "rz", value)
    elif kind == "grounded_spring":
        m.spring(eff.node, eff.dof, value)
    elif kind == "lumped_mass":
        nodes = acc["nodes"]
        node = min(nodes, key=lambda n: np.linalg.norm(st.nodes[n] - eff.centre))
        m.point_mass(node, value)
    elif kind == "sensor_mass":
        for n in eff.nodes:
            m.point_mass(n, value)
    elif kind == "suspension_stiffness":
        xs = {n: x[0] for n, x in st.nodes.items()}
        for n in (min(xs, key=xs.get), max(xs, key=xs.get)):
            m.spring(n, "uy", value)
    axial = {}
    if kind == "axial_preload":
        axial = {i: value for i, mb in enumerate(m.members) if sorted(st.elements)[i] in group}
    elif kind == "self_weight":
        axial = {i: value * N for i, N in m.gravity_axial_forces().items()}
    return m, axial


CANDIDATE = {"attached_mass": "lumped_mass", "sensor_mass": "sensor_mass", "distributed_mass": "distributed_mass",
             "joint_flexibility": "semi_rigid_joint", "support_flexibility": "flexible_support",
             "support_spring": "grounded_spring", "damage": "member_damage", "shear": "shear_deformation",
             "preload": "axial_preload", "self_weight": "self_weight", "suspension": "suspension_stiffness"}


def _reference(eff, ref, st):
    spec = ref[CANDIDATE[eff.kind]] if CANDIDATE[eff.kind] in ref else ref["element_stiffness"]
    if "value" in spec:
        return spec["value"]
    els = eff.accept()["elements"]
    L = [st.length(e) for e in els]
    flex = sum(l * (1 / (1 + spec["per_element"][e] / 100) - 1) for e, l in zip(els, L)) / sum(L)
    return 100 * (1 / (1 + flex) - 1)


def check(st, eff, ref, truth_modes, idx, labels):
    """Residuals of the ideal candidate against the truth's data modes idx: at the reference value, and at its
    own best value (a 1-D fit of the RMS relative frequency error). Returns a dict for truth.json."""
    target = truth_modes.f[idx]
    Xt = truth_modes.X[:, idx]

    def errors(value):
        m, axial = _model(st, eff, value)
        modes = Modes(m, axial, len(idx) + 12, labels, labels)
        if modes.unstable:
            return np.full(len(idx), np.inf)
        M = mac(Xt, modes.X)
        return np.array([modes.f[int(M[j].argmax())] / target[j] - 1 for j in range(len(idx))])
    value = _reference(eff, ref, st)
    at_ref = errors(value)
    if CANDIDATE[eff.kind] == "member_damage":
        res = minimize_scalar(lambda v: float(np.sqrt(np.mean(errors(v) ** 2))), bounds=(-95.0, 300.0),
                              method="bounded", options=dict(xatol=0.05))
        best = float(res.x)
    else:
        sign = 1.0 if value > 0 else -1.0
        res = minimize_scalar(lambda t: float(np.sqrt(np.mean(errors(sign * math.exp(t)) ** 2))),
                              bounds=(math.log(abs(value) / 10), math.log(abs(value) * 10)), method="bounded",
                              options=dict(xatol=1e-3))
        best = sign * math.exp(res.x)
    at_best = errors(best)
    return dict(candidate=CANDIDATE[eff.kind], reference=value, best_value=best,
                best_over_reference=best / value if value else None,
                residual_at_reference_pct=100 * float(np.abs(at_ref).max()),
                residual_at_best_pct=100 * float(np.abs(at_best).max()))

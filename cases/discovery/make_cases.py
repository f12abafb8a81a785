#!/usr/bin/env python3
"""Writes the discovery suite's case files (analysis models, truth models, case.yaml per case).

Each truth model is meshed three times as finely as the analysis model and, where dynid's own elements allow,
models its effect differently from the candidate that should explain it (a joint as a short soft member, not a
spring; a block of mass between nodes with rotary inertia; damage over part of an element; sensors of unequal
mass beside their nodes). Shear and preload use dynid's Timoshenko and geometric-stiffness kernels, the
candidates' own forms (README.md says so; bench/discovery tests them against an independent continuum and an
imposed strain). Identification uses dynid's one band rule (no band per case).
Analysis-model nodes keep their ids in the truth model; extra truth nodes are numbered from 1000.
Run from anywhere: python3 cases/discovery/make_cases.py (stdlib only).
"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def fmt(v):
    return repr(float(v)) if isinstance(v, float) else str(v)


class Mesh:
    def __init__(self):
        self.nodes = {}      # id -> (x, y)
        self.elements = []   # dicts
        self.next_extra = 1000
        self.next_el = 1
        self.masses = []
        self.supports = []

    def node(self, nid, x, y):
        self.nodes[nid] = (x, y)
        return nid

    def extra(self, x, y):
        nid = self.next_extra
        self.next_extra += 1
        self.nodes[nid] = (x, y)
        return nid

    def element(self, a, b, section, group, **kw):
        e = dict(id=self.next_el, nodes=[a, b], section=section, group=group)
        e.update(kw)
        self.next_el += 1
        self.elements.append(e)
        return e["id"]

    def yaml(self, header):
        out = [header]
        out.append("  nodes:")
        for nid, (x, y) in sorted(self.nodes.items()):
            out.append(f"    - [{nid}, {x:.6g}, {y:.6g}]")
        out.append("  elements:")
        for e in self.elements:
            extra = "".join(f", {k}: {fmt(v)}" for k, v in e.items() if k not in ("id", "nodes", "section", "group"))
            out.append(f"    - {{id: {e['id']}, nodes: [{e['nodes'][0]}, {e['nodes'][1]}], section: {e['section']}, group: {e['group']}{extra}}}")
        if self.masses:
            out.append("  point_masses:")
            for i, mm in enumerate(self.masses):
                inertia = f", inertia: [0, 0, {mm[2]:.6g}]" if len(mm) > 2 else ""
                out.append(f"    - {{id: {9000 + i}, node: {mm[0]}, mass: {mm[1]:.6g}{inertia}}}")
        out.append("  supports:")
        for s in self.supports:
            out.append(f"    - {s}")
        return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------------------------------------------
# A plane steel frame: 2 bays x 3 stories, span 4 m, story 3 m; analysis members in 4 elements, truth in 8.
FRAME_HEADER = """model:
  element: frame2d
  materials:
    steel: {E: 2.1e11, rho: 7850, nu: 0.3}
  sections:
    column: {A: 5.38e-3, I: 5.70e-5}
    beam: {A: 3.91e-3, I: 5.79e-5}
  defaults: {material: steel}
"""
BAYS, STORIES, SPAN, HEIGHT = 2, 3, 4.0, 3.0


def joint_id(i, j):  # column line i (0..BAYS), level j (0..STORIES)
    return 1 + j * (BAYS + 1) + i


def frame(div, sub, hooks=None):
    """Frame with `div` analysis elements per member; each split into `sub` truth elements.
    hooks: dict of callables to modify members: key (kind, i, j) -> fn(mesh, a, b, section, group, points)."""
    m = Mesh()
    hooks = hooks or {}
    for j in range(STORIES + 1):
        for i in range(BAYS + 1):
            m.node(joint_id(i, j), i * SPAN, j * HEIGHT)
    mid = [100]  # analysis interior node ids start at 100

    def member(a, b, section, group, key):
        xa, ya = m.nodes[a]
        xb, yb = m.nodes[b]
        # analysis interior nodes
        ids = [a]
        for k in range(1, div):
            t = k / div
            ids.append(m.node(mid[0], xa + t * (xb - xa), ya + t * (yb - ya)))
            mid[0] += 1
        ids.append(b)
        hook = hooks.get(key)
        pts = []  # (node id, x, y) along the member at truth resolution
        for k in range(div):
            n0, n1 = ids[k], ids[k + 1]
            x0, y0 = m.nodes[n0]
            x1, y1 = m.nodes[n1]
            pts.append(n0)
            for s in range(1, sub):
                t = s / sub
                pts.append(m.extra(x0 + t * (x1 - x0), y0 + t * (y1 - y0)))
        pts.append(b)
        if hook:
            hook(m, pts, section, group)
        else:
            for k in range(len(pts) - 1):
                m.element(pts[k], pts[k + 1], section, group)

    for j in range(STORIES):
        for i in range(BAYS + 1):
            member(joint_id(i, j), joint_id(i, j + 1), "column", "column", ("column", i, j))
    for j in range(1, STORIES + 1):
        for i in range(BAYS):
            member(joint_id(i, j), joint_id(i + 1, j), "beam", "beam", ("beam", i, j))
    m.supports.append("{nodes: [%s], fix: all}" % ", ".join(str(joint_id(i, 0)) for i in range(BAYS + 1)))
    return m


def link_hook(at_start, link_len, link_section):
    """The member's end joint connects through a short member (length link_len, its own section)."""
    def hook(m, pts, section, group):
        if at_start:
            a = pts[0]
            xa, ya = m.nodes[a]
            xb, yb = m.nodes[pts[1]]
            L = ((xb - xa) ** 2 + (yb - ya) ** 2) ** 0.5
            t = link_len / L
            n = m.extra(xa + t * (xb - xa), ya + t * (yb - ya))
            m.element(a, n, link_section, group)
            m.element(n, pts[1], section, group)
            for k in range(1, len(pts) - 1):
                m.element(pts[k], pts[k + 1], section, group)
        else:
            raise NotImplementedError
    return hook


def partial_damage_hook(k_index, sub, start=0.1, end=0.9):
    """A reduced section over [start, end] of analysis element k_index (0-based along the member), its ends away
    from the analysis nodes: the truth re-meshes that element with nodes at those fractions."""
    def hook(m, pts, section, group):
        a, b = pts[k_index * sub], pts[(k_index + 1) * sub]
        (xa, ya), (xb, yb) = m.nodes[a], m.nodes[b]
        for k in range(len(pts) - 1):
            if k // sub != k_index:
                m.element(pts[k], pts[k + 1], section, group)
        for x in pts[k_index * sub + 1:(k_index + 1) * sub]:   # the element's regular truth nodes are not used
            del m.nodes[x]
        inner = [m.extra(xa + f * (xb - xa), ya + f * (yb - ya)) for f in (start, 0.5 * (start + end), end)]
        chain = [a] + inner + [b]
        for k in range(len(chain) - 1):
            m.element(chain[k], chain[k + 1], section + "_damaged" if 1 <= k <= 2 else section, group)
    return hook


DIV = 4    # analysis elements per member
SUB = 3    # truth elements per analysis element


def analysis_frame():
    return frame(DIV, 1)


def mid_node(m, x, y):
    for nid, (a, b) in m.nodes.items():
        if abs(a - x) < 1e-9 and abs(b - y) < 1e-9:
            return nid
    raise KeyError((x, y))


def element_id_of(m, a, b):
    for e in m.elements:
        if set(e["nodes"]) == {a, b}:
            return e["id"]
    raise KeyError((a, b))


FRAME_SENSORS = None


def frame_sensors(m):
    # ux and uy at every free joint, uy at beam mid-spans, ux at column mid-heights: 33 accelerometers.
    s = []
    for j in range(1, STORIES + 1):
        for i in range(BAYS + 1):
            s += [f"{joint_id(i, j)}ux", f"{joint_id(i, j)}uy"]
    for j in range(1, STORIES + 1):
        for i in range(BAYS):
            s.append(f"{mid_node(m, (i + 0.5) * SPAN, j * HEIGHT)}uy")
    for j in range(STORIES):
        for i in range(BAYS + 1):
            s.append(f"{mid_node(m, i * SPAN, (j + 0.5) * HEIGHT)}ux")
    return s


def frame_test(sensors, seed):
    hammer = mid_node(analysis_frame(), 1.5 * SPAN, HEIGHT)
    return f"""    test:
      sensors: [{", ".join(sensors)}]
      excitation: impact
      inputs: [{joint_id(BAYS, STORIES)}ux, {hammer}uy]
      sample_rate_hz: 256
      duration_s: 16
      impacts: 5
      band_hz: [0, 110]
      damping: {{modal: 0.01}}
      noise: 0.02
      force_noise: 0.02
      seed: {seed}
      identify: {{method: lscf}}
"""


def write(folder, name, text):
    d = os.path.join(HERE, folder)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "w") as f:
        f.write(text)


def frame_case(folder, description, truth_mesh, truth_sections, expect, seed, note):
    a = analysis_frame()
    write("frame", "analysis.yaml", "# The plane frame as modelled (rigid joints, fixed bases, no added mass).\n" + a.yaml(FRAME_HEADER))
    header = FRAME_HEADER + "".join(f"    {k}: {v}\n" for k, v in truth_sections.items())
    header = header.replace("  defaults:", "  defaults:", 1)
    # sections: add extra sections into the sections block
    if truth_sections:
        lines = FRAME_HEADER.split("\n")
        idx = lines.index("  defaults: {material: steel}")
        lines[idx:idx] = [f"    {k}: {v}" for k, v in truth_sections.items()]
        header = "\n".join(lines)
    write(folder, "truth.yaml", f"# Truth model ({note}); meshed 3x finer than the analysis model.\n" + truth_mesh.yaml(header))
    sensors = frame_sensors(a)
    case = f"""# {description}
# The analysis model never sees truth.yaml: dynid simulates an impact test on it (33 accelerometers, 2 hammer
# locations, 1 % damping, 2 % noise), identifies the modes (LSCF) and runs discovery on the analysis model.
name: {folder}
description: "{description}"
model: {{include: ../frame/analysis.yaml}}
discover:
  truth:
    model: {{include: truth.yaml}}
{frame_test(sensors, seed)}  expect: {expect}
"""
    write(folder, "case.yaml", case)


def main():
    # 1. semi-rigid beam-column joint: the first-story left beam connects to joint 4 through a 20 mm soft link
    #    (E I_link / l = 6.0e6 N m/rad; the beam's 4 E I / L = 1.2e7).
    k_joint = 6.0e6
    l = 0.02
    I_link = k_joint * l / 2.1e11
    t = frame(DIV, SUB, {("beam", 0, 1): link_hook(True, l, "link")})
    a = analysis_frame()
    # analysis element of the left first-story beam adjacent to joint 4
    beam_nodes = [n for n, (x, y) in a.nodes.items() if 100 <= n < 1000 and abs(y - HEIGHT) < 1e-9 and 0 < x < SPAN]
    e_an = element_id_of(a, joint_id(0, 1), beam_nodes[0])
    frame_case("frame-semi-rigid-joint", "Semi-rigid connection of a beam to its column (concealed as a 20 mm soft member).",
               t, {"link": f"{{A: 3.91e-3, I: {I_link:.6g}}}"},
               f"{{kind: semi_rigid_joint, nodes: [{joint_id(0, 1)}], elements: [{e_an}], parameter: stiffness, value: {k_joint}}}", 11,
               f"joint {joint_id(0, 1)}: 20 mm link, E I / l = {k_joint:g} N m/rad")

    # 2. flexible column base: the middle column stands on a 20 mm soft stub (E I / l = 3.0e6 N m/rad).
    k_base = 1.5e7
    l = 0.02
    I_stub = k_base * l / 2.1e11
    t = frame(DIV, SUB, {("column", 1, 0): link_hook(True, l, "stub")})
    col_nodes = [n for n, (x, y) in a.nodes.items() if 100 <= n < 1000 and abs(x - SPAN) < 1e-9 and 0 < y < HEIGHT]
    e_col = element_id_of(a, joint_id(1, 0), col_nodes[0])
    frame_case("frame-flexible-base", "Column base that is not fixed (concealed as a 20 mm soft stub).",
               t, {"stub": f"{{A: 5.38e-3, I: {I_stub:.6g}}}"},
               f"{{kind: flexible_support, nodes: [{joint_id(1, 0)}], parameter: stiffness, value: {k_base}}}", 12,
               f"base of node {joint_id(1, 0)}: 20 mm stub, E I / l = {k_base:g} N m/rad")

    # 3. attached mass: a 120 kg block on the second-story right beam, centred 1/6 m beside its mid-span node
    #    (between analysis nodes), carried by the two truth nodes under it, each with its own rotary inertia.
    t = frame(DIV, SUB)
    mid2 = mid_node(a, 1.5 * SPAN, 2 * HEIGHT)
    beside = mid_node(t, 1.5 * SPAN + (SPAN / DIV) / SUB, 2 * HEIGHT)
    e_mass = element_id_of(a, mid2, mid_node(a, 1.75 * SPAN, 2 * HEIGHT))
    t.masses = [(mid2, 60.0, 0.8), (beside, 60.0, 0.8)]
    block = (f"{{kind: [lumped_mass, element_point_mass], nodes: [{mid2}], elements: [{e_mass}], parameter: mass, "
             f"value: 120}}")
    frame_case("frame-attached-mass", "Unmodelled 120 kg block (rotary inertia 1.6 kg m^2) beside a beam mid-span, between nodes.",
               t, {}, block, 13, f"a 120 kg block centred 1/6 m from node {mid2}, on two truth nodes")

    # 4. damage: half the bending stiffness lost over 0.8 m of a first-story beam, from 0.1 m into the element
    #    next to mid-span to 0.1 m before its end. Flexibility-equivalent change of that element:
    #    1 / (1 + d) = 1 + 0.8 (1 / 0.5 - 1)  ->  d = -44.4 %.
    t = frame(DIV, SUB, {("beam", 0, 1): partial_damage_hook(1, SUB)})
    e_dmg = element_id_of(a, mid_node(a, 0.25 * SPAN, HEIGHT), mid_node(a, 0.5 * SPAN, HEIGHT))
    frame_case("frame-damage", "Half the bending stiffness lost over 0.8 m inside one element of a first-story beam.", t,
               {"beam_damaged": "{A: 3.91e-3, I: 2.895e-5}"},
               f"{{kind: [element_stiffness, member_damage], elements: [{e_dmg}], parameter: stiffness change, value: -44.4}}", 14,
               "a reduced section (I x 0.5) over 0.8 m of the second quarter of the left first-story beam")

    # 5. two effects: flexible base (as 2) and the 120 kg block (as 3) at once.
    t = frame(DIV, SUB, {("column", 1, 0): link_hook(True, 0.02, "stub")})
    t.masses = [(mid2, 60.0, 0.8), (beside, 60.0, 0.8)]
    frame_case("frame-two-effects", "Two effects at once: a flexible column base and an attached mass.", t,
               {"stub": f"{{A: 5.38e-3, I: {I_stub:.6g}}}"},
               f"{{kind: flexible_support, nodes: [{joint_id(1, 0)}], parameter: stiffness, value: {k_base}, "
               f"also: [{block}]}}", 15,
               "flexible base of the middle column and the 120 kg block")

    # 6. null case: the truth is the analysis model (meshed finer); only noise separates data and model.
    t = frame(DIV, SUB)
    frame_case("frame-null", "Null case: the structure is as modelled; only measurement noise.", t, {},
               "{verdict: consistent}", 16, "identical physics")

    beams()


# ---------------------------------------------------------------------------------------------------------------
def beam_mesh(L, n, support, ids_from=1, extra_sub=1):
    """Nodes along x: analysis nodes 1..n+1; truth adds extra_sub-1 nodes between (ids 1000+)."""
    m = Mesh()
    for k in range(n + 1):
        m.node(ids_from + k, L * k / n, 0.0)
    for k in range(n):
        a, b = ids_from + k, ids_from + k + 1
        pts = [a]
        for s in range(1, extra_sub):
            pts.append(m.extra(L * (k + s / extra_sub) / n, 0.0))
        pts.append(b)
        for q in range(len(pts) - 1):
            m.element(pts[q], pts[q + 1], "s", "beam")
    if support == "simply_supported":
        m.supports += [f"{{node: {ids_from}, fix: [uy]}}", f"{{node: {ids_from + n}, fix: [uy]}}"]
    elif support == "cantilever":
        m.supports += [f"{{node: {ids_from}, fix: all}}"]
    return m


def beam_case(folder, description, header_a, header_t, a, t, sensors, inputs, fs, dur, expect, seed, note):
    write(folder, "analysis.yaml", "# The beam as modelled.\n" + a.yaml(header_a))
    write(folder, "truth.yaml", f"# Truth model ({note}); meshed finer than the analysis model.\n" + t.yaml(header_t))
    case = f"""# {description}
# The analysis model never sees truth.yaml: dynid simulates an impact test on it ({len(sensors)} accelerometers,
# 1 % damping, 2 % noise), identifies the modes (LSCF) and runs discovery on the analysis model.
name: {folder}
description: "{description}"
model: {{include: analysis.yaml}}
discover:
  truth:
    model: {{include: truth.yaml}}
    test:
      sensors: [{", ".join(sensors)}]
      excitation: impact
      inputs: [{", ".join(inputs)}]
      sample_rate_hz: {fs}
      duration_s: {dur}
      impacts: 5
      damping: {{modal: 0.01}}
      noise: 0.02
      force_noise: 0.02
      seed: {seed}
      identify: {{method: lscf}}
  expect: {expect}
"""
    write(folder, "case.yaml", case)


def beam_header(material, props, width, depth):
    return f"""model:
  element: beam2d
  materials:
    {material}: {{{props}}}
  sections:
    s: {{rectangle: {{width: {width}, depth: {depth}}}}}
  defaults: {{material: {material}}}
"""


STEEL = "E: 2.1e11, rho: 7850, nu: 0.3"


def beams():
    # 7. sensor mass loading: a light aluminium cantilever (600 x 25 x 3 mm, 0.12 kg) carrying five
    #    accelerometers of 4.5 to 7.5 g (6 g on average), each a third of an element beside its measured node, with
    #    the rotary inertia of a 10 mm cube mounted on the surface.
    hdr = beam_header("alu", "E: 7.0e10, rho: 2700, nu: 0.33", 0.025, 0.003)
    a = beam_mesh(0.6, 10, "cantilever")
    t = beam_mesh(0.6, 10, "cantilever", extra_sub=3)
    sensors_n = [3, 5, 7, 9, 11]
    grams = [4.5, 6.0, 7.5, 5.0, 7.0]
    beside = {n: min(x for x, (px, _) in t.nodes.items() if x >= 1000 and abs(px - (n - 1) * 0.06 + 0.02) < 1e-9)
              for n in sensors_n}
    t.masses = [(beside[n], g / 1000, g / 1000 * (0.01 ** 2 / 12 + 0.0065 ** 2)) for n, g in zip(sensors_n, grams)]
    beam_case("beam-sensor-mass", "Accelerometers (4.5-7.5 g, off their nodes) loading a light cantilever.", hdr, hdr, a, t,
              [f"{n}uy" for n in sensors_n], ["11uy"], 2048, 8,
              "{kind: sensor_mass, parameter: mass per sensor, value: 0.006}", 21,
              "five accelerometers of 4.5-7.5 g a third of an element inboard of the sensor nodes, with rotary inertia")

    # 8. shear deformation: a deep steel beam (2 m span, 400 x 100 mm, L/h = 5), simply supported; truth in
    #    Timoshenko elements (Cowper's kappa for a rectangle, 10 (1 + nu) / (12 + 11 nu) = 0.8497; rotary inertia),
    #    three times finer.
    kappa = 10 * 1.3 / (12 + 11 * 0.3)
    hdr = beam_header("steel", STEEL, 0.1, 0.4)
    hdr_t = hdr.replace("s: {rectangle: {width: 0.1, depth: 0.4}}", f"s: {{rectangle: {{width: 0.1, depth: 0.4}}, shear_factor: {kappa:.6f}}}").replace(
        "  element: beam2d\n", "  element: beam2d\n  rotary_inertia: true\n")
    a = beam_mesh(2.0, 20, "simply_supported")
    t = beam_mesh(2.0, 20, "simply_supported", extra_sub=3)
    beam_case("deep-beam-shear", "Shear deformation and rotary inertia of a deep beam (L/h = 5) modelled as Euler-Bernoulli.", hdr, hdr_t, a, t,
              [f"{n}uy" for n in range(3, 20, 2)], ["7uy"], 16384, 1,
              f"{{kind: shear_deformation, parameter: shear coefficient kappa, value: {kappa:.4f}}}", 22, "Timoshenko, Cowper's kappa")

    # 9. axial preload: a tensioned steel strip (2 m, 40 x 5 mm), pinned at both ends, 1 kN tension.
    hdr = beam_header("steel", STEEL, 0.04, 0.005)
    a = beam_mesh(2.0, 20, "simply_supported")
    t = beam_mesh(2.0, 20, "simply_supported", extra_sub=3)
    for e in t.elements:
        e["axial_force"] = 1000.0
    beam_case("strip-preload", "A pinned steel strip under 1 kN of tension the model leaves out.", hdr, hdr, a, t,
              [f"{n}uy" for n in range(3, 20, 2)], ["7uy"], 512, 16,
              "{kind: axial_preload, parameter: axial force, value: 1000}", 23, "1 kN tension in every element")


if __name__ == "__main__":
    main()

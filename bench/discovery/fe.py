"""An independent finite-element code for the concealed-physics benchmark (numpy/scipy only).

It shares nothing with dynid's element kernels: the truths of the benchmark are built here, so that discovery
is measured on data made by a different code with its own discretisation.

Elements
  * frame members, plane (ux, uy, rz) and space (6 DOF per node): Euler-Bernoulli or Timoshenko bending
    (interdependent interpolation of Friedman & Kosmatka 1993, exact for static end loads), consistent mass,
    optional rotary inertia, consistent geometric stiffness of an axial force, imposed axial strain;
  * bars (axial only) with optional rigid offsets at either end;
  * point masses with rotary inertia, optionally eccentric (a rigid offset from the node);
  * grounded springs and springs between two nodes on one DOF type;
  * plane-stress Q9 quadrilaterals (biquadratic Lagrange, 3x3 Gauss: no shear locking in bending);
  * supports, and rigid links (slave translations = master translations + rotation x arm; slave rotations
    tied or left free).

Every node carries the six DOF slots ux, uy, uz, rx, ry, rz; slots no element touches are dropped, restrained
slots removed, and rigid links eliminated by a transformation u = T q. Modal analysis solves the inverted
problem M x = mu (K + s M) x (mu = 1 / (lambda + s)), so the lowest modes are the best conditioned ones; dense
LAPACK below `DENSE_LIMIT` DOFs, ARPACK shift-invert above.
"""
import functools

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

SLOTS = ("ux", "uy", "uz", "rx", "ry", "rz")
SLOT = {n: i for i, n in enumerate(SLOTS)}
DENSE_LIMIT = 700
GRAVITY = 9.81

# ---- element kernels ---------------------------------------------------------------------------------------

_GAUSS5 = np.polynomial.legendre.leggauss(5)


@functools.lru_cache(maxsize=4096)
def bending_block(L, EI, GAk, rhoA, rhoI):
    """Bending in one plane on (w1, t1, w2, t2) with w' = t (t = rotation of the section, w' - t = shear strain).

    GAk = kappa G A (0: Euler-Bernoulli). Returns stiffness, translational mass, rotary mass and the geometric
    stiffness of a unit axial force (tension positive), each integrated by 5-point Gauss (exact: degree <= 6).
    """
    phi = 0.0 if GAk == 0.0 else 12.0 * EI / (GAk * L * L)
    c = 1.0 / (1.0 + phi)
    K = np.zeros((4, 4))
    Mt = np.zeros((4, 4))
    Mr = np.zeros((4, 4))
    G = np.zeros((4, 4))
    for xi_g, w_g in zip(*_GAUSS5):
        x = 0.5 * (xi_g + 1.0)
        wt = 0.5 * w_g * L
        # Transverse displacement w and section rotation t; derivatives with respect to the physical x.
        Nw = c * np.array([2 * x**3 - 3 * x**2 - phi * x + 1 + phi,
                           L * (x**3 - (2 + phi / 2) * x**2 + (1 + phi / 2) * x),
                           -(2 * x**3 - 3 * x**2 - phi * x),
                           L * (x**3 - (1 - phi / 2) * x**2 - (phi / 2) * x)])
        dNw = c / L * np.array([6 * x**2 - 6 * x - phi,
                                L * (3 * x**2 - (4 + phi) * x + 1 + phi / 2),
                                -(6 * x**2 - 6 * x - phi),
                                L * (3 * x**2 - (2 - phi) * x - phi / 2)])
        Nt = c * np.array([6 / L * (x**2 - x), 3 * x**2 - (4 + phi) * x + 1 + phi,
                           -6 / L * (x**2 - x), 3 * x**2 - (2 - phi) * x])
        dNt = c / L * np.array([6 / L * (2 * x - 1), 6 * x - (4 + phi), -6 / L * (2 * x - 1), 6 * x - (2 - phi)])
        K += wt * EI * np.outer(dNt, dNt)
        if GAk:
            g = dNw - Nt
            K += wt * GAk * np.outer(g, g)
        Mt += wt * rhoA * np.outer(Nw, Nw)
        Mr += wt * rhoI * np.outer(Nt, Nt)
        G += wt * np.outer(dNw, dNw)
    return K, Mt, Mr, G


def _bar(k):
    return k * np.array([[1.0, -1.0], [-1.0, 1.0]])


def _bar_mass(m):
    return m / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])


@functools.lru_cache(maxsize=4096)
def frame_local(ndim, L, E, G, A, Iz, Iy, J, rho, kappa, rotary):
    """Local stiffness, mass and unit-force geometric stiffness of a frame member.

    Plane: DOFs (u1, v1, rz1, u2, v2, rz2). Space: (u, v, w, rx, ry, rz) at each end; bending in the local x-y
    plane (v, rz: EIz) and x-z plane (w, ry: EIy, with w' = -ry). Torsion G J with polar mass rho (Iy + Iz); the
    geometric stiffness of torsion uses the polar radius of gyration (Iy + Iz) / A.
    """
    n = 6 if ndim == 2 else 12
    K = np.zeros((n, n))
    M = np.zeros((n, n))
    Kg = np.zeros((n, n))
    ax = [0, 3] if ndim == 2 else [0, 6]
    K[np.ix_(ax, ax)] += _bar(E * A / L)
    M[np.ix_(ax, ax)] += _bar_mass(rho * A * L)
    planes = [([1, 2, 4, 5] if ndim == 2 else [1, 5, 7, 11], Iz, 1.0)]
    if ndim == 3:
        planes.append(([2, 4, 8, 10], Iy, -1.0))
        tx = [3, 9]
        K[np.ix_(tx, tx)] += _bar(G * J / L)
        M[np.ix_(tx, tx)] += _bar_mass(rho * (Iy + Iz) * L)
        Kg[np.ix_(tx, tx)] += _bar((Iy + Iz) / (A * L))
    for idx, I, s in planes:
        GAk = 0.0 if kappa is None else kappa * G * A
        kb, mt, mr, gb = bending_block(L, E * I, GAk, rho * A, rho * I)
        D = np.diag([1.0, s, 1.0, s])
        ii = np.ix_(idx, idx)
        K[ii] += D @ kb @ D
        M[ii] += D @ (mt + (mr if rotary else 0.0)) @ D
        Kg[ii] += D @ gb @ D
    return K, M, Kg


def frame_axes(a, b, orientation=None):
    """Rows e_x, e_y, e_z of a member from a to b; the orientation vector lies in the local x-z plane
    (default global Z, or global X for a member along Z); e_y = v x e_x, e_z = e_x x e_y."""
    ex = (b - a) / np.linalg.norm(b - a)
    v = np.array([0.0, 0.0, 1.0]) if orientation is None else np.asarray(orientation, float)
    if orientation is None and abs(ex[2]) > 0.999:
        v = np.array([1.0, 0.0, 0.0])
    ey = np.cross(v, ex)
    ey /= np.linalg.norm(ey)
    return np.array([ex, ey, np.cross(ex, ey)])


@functools.lru_cache(maxsize=64)
def q9_matrices(dx, dy, E, nu, t, rho):
    """Plane-stress Q9 on a dx x dy rectangle: stiffness and consistent mass on (ux, uy) of the nodes
    ordered (i, j) -> 3 j + i (i along x), 3x3 Gauss."""
    D = E / (1 - nu**2) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    g, w = np.polynomial.legendre.leggauss(3)

    def lag(s):
        return np.array([s * (s - 1) / 2, 1 - s * s, s * (s + 1) / 2]), np.array([s - 0.5, -2 * s, s + 0.5])

    K = np.zeros((18, 18))
    M = np.zeros((18, 18))
    jac = dx * dy / 4
    for a, wa in zip(g, w):
        for b, wb in zip(g, w):
            lx, dlx = lag(a)
            ly, dly = lag(b)
            N = np.outer(ly, lx).ravel()
            Nx = np.outer(ly, dlx).ravel() * 2 / dx
            Ny = np.outer(dly, lx).ravel() * 2 / dy
            B = np.zeros((3, 18))
            B[0, 0::2] = Nx
            B[1, 1::2] = Ny
            B[2, 0::2] = Ny
            B[2, 1::2] = Nx
            K += wa * wb * jac * t * B.T @ D @ B
            Nm = np.zeros((2, 18))
            Nm[0, 0::2] = N
            Nm[1, 1::2] = N
            M += wa * wb * jac * t * rho * Nm.T @ Nm
    return K, M


def arm_matrix(r, ndim):
    """Rigid-arm map from a node's DOFs to the translations of a point at offset r: u_p = u + theta x r.
    Plane: columns (ux, uy, rz), rows (ux, uy). Space: columns all six, rows (ux, uy, uz)."""
    r = np.asarray(r, float)
    if ndim == 2:
        return np.array([[1.0, 0.0, -r[1]], [0.0, 1.0, r[0]]])
    S = np.array([[0.0, r[2], -r[1]], [-r[2], 0.0, r[0]], [r[1], -r[0], 0.0]])  # theta x r = S theta
    return np.hstack([np.eye(3), S])


# ---- the model ---------------------------------------------------------------------------------------------

class Member:
    """A frame member element as assembled (kept for static force recovery and geometric stiffness)."""

    def __init__(self, n1, n2, props, R, L, dofs, tag):
        self.n1, self.n2, self.props, self.R, self.L, self.dofs, self.tag = n1, n2, props, R, L, dofs, tag


class Model:
    """A frame / continuum model. ndim = 2 (plane x-y: slots ux, uy, rz) or 3 (space)."""

    def __init__(self, ndim=2):
        self.ndim = ndim
        self.nodes = {}
        self.members = []
        self.parts = []          # (dofs [(node, slot)], K or None, M or None, tag)
        self.fixed = set()       # (node, slot)
        self.links = {}          # slave (node, slot) -> [(master (node, slot), coefficient)]
        self.fixed_everywhere = set()

    # nodes and constraints
    def node(self, nid, x, y, z=0.0):
        self.nodes[nid] = np.array([x, y, z], float)

    def slots(self, names=None):
        if names is None:
            return [0, 1, 5] if self.ndim == 2 else list(range(6))
        return [SLOT[n] for n in names]

    def support(self, nid, dofs=None):
        for s in self.slots(dofs):
            self.fixed.add((nid, s))

    def restrain_everywhere(self, names):
        """A DOF type that no node has (e.g. ux of a beam model without axial DOFs)."""
        self.fixed_everywhere.update(SLOT[n] for n in names)

    def rigid_link(self, slave, master, rotations=True):
        """Slave translations follow the master's rigidly (lever arm = slave - master); slave rotations are tied
        to the master's when `rotations`, else they stay independent DOFs."""
        r = self.nodes[slave] - self.nodes[master]
        A = arm_matrix(r, self.ndim)
        ms = self.slots()
        for row, s in enumerate([0, 1] if self.ndim == 2 else [0, 1, 2]):
            self.links[(slave, s)] = [((master, ms[c]), A[row, c]) for c in range(A.shape[1]) if A[row, c] != 0.0]
        if rotations:
            for s in ([5] if self.ndim == 2 else [3, 4, 5]):
                self.links[(slave, s)] = [((master, s), 1.0)]

    # elements
    def frame(self, n1, n2, E, G, A, Iz, rho, Iy=0.0, J=0.0, orientation=None, kappa=None, rotary=False,
              eps0=0.0, tag="member"):
        """A frame member; kappa = None is Euler-Bernoulli. eps0 = imposed axial strain (static load only)."""
        a, b = self.nodes[n1], self.nodes[n2]
        L = float(np.linalg.norm(b - a))
        if self.ndim == 2:
            c, s = (b - a)[:2] / L
            r3 = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
            R = np.kron(np.eye(2), r3)
            orient = None
        else:
            r3 = frame_axes(a, b, orientation)
            R = np.kron(np.eye(4), r3)
            orient = None if orientation is None else tuple(float(v) for v in orientation)
        props = dict(E=E, G=G, A=A, Iz=Iz, Iy=Iy, J=J, rho=rho, kappa=kappa, rotary=rotary, eps0=eps0,
                     orientation=orient)
        Kl, Ml, _ = frame_local(self.ndim, round(L, 12), E, G, A, Iz, Iy, J, rho, kappa, rotary)
        dofs = [(n, s) for n in (n1, n2) for s in self.slots()]
        self.parts.append((dofs, R.T @ Kl @ R, R.T @ Ml @ R, tag))
        self.members.append(Member(n1, n2, props, R, L, dofs, tag))
        return len(self.members) - 1

    def bar(self, n1, n2, EA, rhoA=0.0, offsets=(None, None), tag="bar"):
        """Axial bar; offsets[i] = rigid arm from node i to the bar's end (a vector), or None."""
        arms = [arm_matrix(np.zeros(3) if off is None else off, self.ndim) for off in offsets]
        ends = [self.nodes[n] + (0 if off is None else np.asarray(off, float)) for n, off in zip((n1, n2), offsets)]
        L = float(np.linalg.norm(ends[1] - ends[0]))
        e = (ends[1] - ends[0])[:self.ndim] / L
        nd = arms[0].shape[1]                       # DOFs per node
        Tb = np.zeros((2, 2 * nd))                  # node DOFs -> axial end displacements
        Tt = np.zeros((2 * self.ndim, 2 * nd))      # node DOFs -> end translations
        for k, A in enumerate(arms):
            Tb[k, k * nd:(k + 1) * nd] = e @ A
            Tt[k * self.ndim:(k + 1) * self.ndim, k * nd:(k + 1) * nd] = A
        # Consistent mass on the end translations in every direction (the bar moves with its ends).
        Mb = np.kron(_bar_mass(rhoA * L), np.eye(self.ndim))
        dofs = [(n, s) for n in (n1, n2) for s in self.slots()]
        self.parts.append((dofs, Tb.T @ _bar(EA / L) @ Tb, Tt.T @ Mb @ Tt, tag))

    def point_mass(self, nid, m, inertia=(0.0, 0.0, 0.0), offset=None, tag="mass"):
        """Mass m with rotary inertia about its own centre (Ix, Iy, Iz), at the node or at node + offset."""
        nt = self.ndim
        A = arm_matrix(np.zeros(3) if offset is None else offset, self.ndim)
        Mm = A.T @ (m * np.eye(nt)) @ A
        rot = [2] if self.ndim == 2 else [3, 4, 5]
        Ir = [inertia[2]] if self.ndim == 2 else list(inertia)
        for i, v in zip(rot, Ir):
            Mm[i, i] += v
        self.parts.append(([(nid, s) for s in self.slots()], None, Mm, tag))

    def spring(self, nid, dof, k, tag="spring"):
        self.parts.append(([(nid, SLOT[dof])], np.array([[k]]), None, tag))

    def spring2(self, n1, n2, dof, k, tag="spring"):
        self.parts.append(([(n1, SLOT[dof]), (n2, SLOT[dof])], _bar(k), None, tag))

    def quad9(self, nids, dx, dy, E, nu, t, rho, tag="solid"):
        """A rectangular Q9 with nodes nids[3 j + i] (i along x, j along y)."""
        K, M = q9_matrices(round(dx, 12), round(dy, 12), E, nu, t, rho)
        dofs = [(n, s) for n in nids for s in (0, 1)]
        self.parts.append((dofs, K, M, tag))

    # assembly
    def assemble(self, axial=None, tags=None):
        """Sparse K, M reduced to the independent DOFs. axial: member index -> axial force (tension > 0), added
        as geometric stiffness. tags: assemble only parts with these tags (e.g. the members, for gravity)."""
        return Assembled(self, axial or {}, tags)

    def static_axial_forces(self, load=None, imposed=True):
        """Linear static analysis; returns the axial force of every member (tension > 0).

        load: full-space load vector builder, a function Assembled -> vector on the full DOFs; imposed: include
        the members' imposed strains eps0 (equivalent nodal forces EA eps0 along the axis)."""
        asm = self.assemble()
        f = np.zeros(asm.nfull)
        if load is not None:
            f += load(asm)
        if imposed:
            for mb in self.members:
                e0 = mb.props["eps0"]
                if e0:
                    fl = np.zeros(len(mb.dofs))
                    ax = [0, 3] if self.ndim == 2 else [0, 6]
                    P = mb.props["E"] * mb.props["A"] * e0
                    fl[ax[0]], fl[ax[1]] = -P, P
                    fg = mb.R.T @ fl
                    for d, v in zip(mb.dofs, fg):
                        f[asm.full_index[d]] += v
        q = spla.spsolve(asm.K.tocsc(), asm.T.T @ f)
        u = asm.T @ q
        out = {}
        for i, mb in enumerate(self.members):
            ul = mb.R @ np.array([u[asm.full_index[d]] for d in mb.dofs])
            ax = [0, 3] if self.ndim == 2 else [0, 6]
            out[i] = mb.props["E"] * mb.props["A"] * ((ul[ax[1]] - ul[ax[0]]) / mb.L - mb.props["eps0"])
        return out

    def gravity_axial_forces(self, tags=("member",)):
        """Axial forces under the weight of the parts with these tags (gravity -y in a plane, -z in space):
        consistent loads f = -g M r, r the unit rigid translation along the vertical."""
        vert = 1 if self.ndim == 2 else 2

        def load(asm_all):
            asm = self.assemble(tags=tags)
            r = np.zeros(asm.nfull)
            for d, i in asm.full_index.items():
                if d[1] == vert:
                    r[i] = 1.0
            f_part = -GRAVITY * (asm.Mfull @ r)
            f = np.zeros(asm_all.nfull)
            for d, i in asm.full_index.items():
                f[asm_all.full_index[d]] += f_part[i]
            return f
        return self.static_axial_forces(load=load, imposed=False)


class Assembled:
    """K and M of a model on its independent DOFs q (u = T q on the full DOF list)."""

    def __init__(self, model, axial, tags):
        rows, cols, kv, mv = [], [], [], []
        index = {}

        def idx(d):
            if d not in index:
                index[d] = len(index)
            return index[d]
        parts = [p for p in model.parts if tags is None or p[3] in tags]
        for dofs, K, M, _ in parts:
            ii = np.array([idx(d) for d in dofs])
            r = np.repeat(ii, len(ii))
            c = np.tile(ii, len(ii))
            rows.append(r)
            cols.append(c)
            kv.append(np.zeros(len(r)) if K is None else K.ravel())
            mv.append(np.zeros(len(r)) if M is None else M.ravel())
        for i, N in axial.items():
            mb = model.members[i]
            p = mb.props
            _, _, Kg = frame_local(model.ndim, round(mb.L, 12), p["E"], p["G"], p["A"], p["Iz"], p["Iy"], p["J"],
                                   p["rho"], p["kappa"], p["rotary"])
            ii = np.array([idx(d) for d in mb.dofs])
            rows.append(np.repeat(ii, len(ii)))
            cols.append(np.tile(ii, len(ii)))
            kv.append((N * (mb.R.T @ Kg @ mb.R)).ravel())
            mv.append(np.zeros(len(ii) ** 2))
        for sl in list(model.links):  # masters must exist even if only referenced
            for d, _ in model.links[sl]:
                idx(d)
        n = len(index)
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        Kf = sp.coo_matrix((np.concatenate(kv), (rows, cols)), shape=(n, n)).tocsr()
        Mf = sp.coo_matrix((np.concatenate(mv), (rows, cols)), shape=(n, n)).tocsr()
        # Drop DOF slots no element touches (zero rows of K and M), restrained ones and slaves.
        touched = (abs(Kf).sum(axis=1).A1 > 0) | (abs(Mf).sum(axis=1).A1 > 0)
        full = [d for d in index if touched[index[d]] or d in model.links]
        self.full_dofs = full
        self.full_index = {d: i for i, d in enumerate(full)}
        sel = np.array([index[d] for d in full])
        Kf, Mf = Kf[sel][:, sel], Mf[sel][:, sel]
        free = [d for d in full if d not in model.fixed and d[1] not in model.fixed_everywhere
                and d not in model.links]
        self.dofs = free
        col = {d: j for j, d in enumerate(free)}
        tr, tc, tv = [], [], []
        for d in free:
            tr.append(self.full_index[d]); tc.append(col[d]); tv.append(1.0)
        for s, terms in model.links.items():
            if s not in self.full_index:
                continue
            for m, c in terms:
                if m in col:  # a restrained master contributes nothing
                    tr.append(self.full_index[s]); tc.append(col[m]); tv.append(c)
        self.T = sp.coo_matrix((tv, (tr, tc)), shape=(len(full), len(free))).tocsr()
        self.Kfull, self.Mfull = Kf, Mf
        self.K = (self.T.T @ Kf @ self.T).tocsr()
        self.M = (self.T.T @ Mf @ self.T).tocsr()
        self.nfull = len(full)

    def rows(self, labels):
        """Full-DOF rows of (node, slot) labels (for reading mode shapes at measured DOFs)."""
        return np.array([self.full_index[d] for d in labels], dtype=int)


def modal(asm, n, dense=None):
    """The n lowest modes: frequencies (Hz) and shapes on the full DOFs, unit modal mass. A negative
    eigenvalue (a compressed model past buckling) is returned as a negative frequency -sqrt(-lambda) / 2 pi.

    Solved as M x = mu (K + s M) x with a small positive shift s (free-free models have K singular), so the
    lowest modes are the largest mu: their relative accuracy does not suffer from stiff, light parts of a model."""
    K, M = asm.K, asm.M
    ndof = K.shape[0]
    n = min(n, ndof - 1)
    d = M.diagonal()
    ratio = K.diagonal()[d > 0] / d[d > 0]
    s = 1e-6 * float(np.median(ratio))
    if dense is None:
        dense = ndof <= DENSE_LIMIT
    if dense:
        try:
            mu, X = sla.eigh(M.toarray(), (K + s * M).toarray(), subset_by_index=[ndof - n, ndof - 1])
            mu, X = mu[::-1], X[:, ::-1]
            lam = 1.0 / mu - s
        except sla.LinAlgError:   # K + s M indefinite: a model past buckling; shift-invert Lanczos copes
            dense = False
    if not dense:
        v0 = np.random.default_rng(0).standard_normal(ndof)     # a fixed start: results are reproducible
        lam, X = spla.eigsh(K.tocsc(), k=n, M=M.tocsc(), sigma=-s, which="LM", tol=1e-12, v0=v0)
        o = np.argsort(lam)
        lam, X = lam[o], X[:, o]
    X = X / np.sqrt(np.einsum("ij,ij->j", X, M @ X))
    return np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi), asm.T @ X

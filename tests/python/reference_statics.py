"""An independent NumPy reference of the sheet's static equilibrium with one
or several rigid holders (shares no code with the FMU).

The sheet is the grid of src/physics/setup/grid.rs: nx columns, ny rows,
node (row, col) resting at (col * spacing, -row * spacing[, 0]); structural
springs, shear springs (r,c)-(r+1,c+1) and (r,c+1)-(r+1,c), bending springs
(r,c)-(r,c+2) and (r,c)-(r+2,c); in 3D an auxiliary spring from each free node
to a point `spacing` out of the plane (+z), rest length `spacing`. Every
spring is linear, f = k (|d| - L) d / |d|, L its rest distance.

Which node is held by which holder: ``holder_of_node[row][col]`` (0 free,
k holder k). Holder k is placed rigidly by a translation a_k and a rotation
vector theta_k (Rodrigues) about its pivot P_k, the rest position of its
first node in row-major order: its node i sits at P_k + a_k + R_k (X_i - P_k).
The auxiliary springs' anchor points ride with holder 1.

    eq = solve_statics(holders("top-row", 5, 4), dim=2, placements={1: ((0.02, 0.0), 0.3)})
    eq.positions       # [ny][nx][dim]
    eq.forces[1]       # force the sheet exerts on holder 1 (dim values)
    eq.torques[1]      # its torque about P_1 + a_1 (a scalar, z, in 2D; 3 values in 3D)
"""

from dataclasses import dataclass

import numpy as np


def holders(fixed_nodes, nx, ny):
    """holder_of_node of the FMU's single holder: "top-row" (1) or "top-corners" (2)."""
    if fixed_nodes not in ("top-row", 1, "top-corners", 2):
        raise ValueError(f"fixed_nodes {fixed_nodes!r}")
    h = np.zeros((ny, nx), dtype=int)
    h[0, :] = 1
    h[0, 1:nx - 1] = fixed_nodes in ("top-row", 1)
    return h


def rotation(theta, dim):
    """R of a rotation vector (3D, Rodrigues; a scalar turns about z) or of an
    angle about z (2D: a scalar, or the z component of a 3-vector)."""
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    if dim == 2:
        c, s = np.cos(theta[-1]), np.sin(theta[-1])
        return np.array([[c, -s], [s, c]])
    theta = theta if theta.size == 3 else np.array([0.0, 0.0, theta[0]])  # a scalar: about z
    angle = np.linalg.norm(theta)
    k = theta / angle if angle > 0.0 else theta
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * kx + (1.0 - np.cos(angle)) * kx @ kx


@dataclass
class Sheet:
    """The springs of a grid; points are the nx * ny nodes (index row * nx + col)
    then the auxiliary anchor points (one per free node, in node order)."""

    nx: int
    ny: int
    dim: int
    spacing: float
    node_mass: float
    holder: np.ndarray  # per node: 0 free, k holder k
    rest: np.ndarray  # (points, dim)
    a: np.ndarray  # springs' first points
    b: np.ndarray  # springs' second points
    k: np.ndarray  # stiffnesses
    length: np.ndarray  # rest lengths

    n_nodes = property(lambda self: self.nx * self.ny)
    free = property(lambda self: np.flatnonzero(self.holder == 0))

    def carried(self, k):
        """Points holder k carries: its nodes, and for holder 1 the auxiliary anchors."""
        nodes = np.flatnonzero(self.holder == k)
        return np.concatenate([nodes, np.arange(self.n_nodes, len(self.rest))]) if k == 1 else nodes


def build_sheet(holder_of_node, dim, spacing=0.1, node_mass=0.01, spring_stiffness=50.0, shear_springs=True, bending_springs=False,
                aux_stiffness=0.0, inter_holder_springs=True):
    """The grid's springs. A spring with both ends on one holder is left out
    (it never changes length); one between nodes of two different holders is
    kept (it acts when they move apart) unless ``inter_holder_springs`` is
    False, which leaves out every spring between held nodes (grid.rs with
    one holder)."""
    (ny, nx), holder = np.shape(holder_of_node), np.asarray(holder_of_node, dtype=int).ravel()
    if dim not in (2, 3):
        raise ValueError("dim must be 2 or 3")
    rest = np.zeros((nx * ny, dim))
    rest[:, 0], rest[:, 1] = np.arange(nx * ny) % nx * spacing, -(np.arange(nx * ny) // nx) * spacing
    steps = [((0, 0), (0, 1)), ((0, 0), (1, 0))] + [((0, 0), (1, 1)), ((0, 1), (1, 0))] * shear_springs
    steps += [((0, 0), (0, 2)), ((0, 0), (2, 0))] * bending_springs
    ends = [(r0 * nx + c0, r1 * nx + c1) for r in range(ny) for c in range(nx) for (r0, c0), (r1, c1) in
            (((r + dr0, c + dc0), (r + dr1, c + dc1)) for (dr0, dc0), (dr1, dc1) in steps) if max(r0, r1) < ny and max(c0, c1) < nx]
    hi, hj = holder[[i for i, _ in ends]], holder[[j for _, j in ends]]
    keep = (hi == 0) | (hj == 0) | ((hi != hj) & inter_holder_springs)
    a, b = np.array([i for i, _ in ends], dtype=int)[keep], np.array([j for _, j in ends], dtype=int)[keep]
    k = np.full(len(a), float(spring_stiffness))
    free = np.flatnonzero(holder == 0)
    if dim == 3 and aux_stiffness > 0.0:
        if not (holder == 1).any():
            raise ValueError("auxiliary springs ride with holder 1, which holds no node")
        anchors = rest[free] + [0.0, 0.0, spacing]
        a = np.concatenate([a, free])
        b = np.concatenate([b, nx * ny + np.arange(len(free))])
        k = np.concatenate([k, np.full(len(free), float(aux_stiffness))])
        rest = np.vstack([rest, anchors])
    length = np.linalg.norm(rest[b] - rest[a], axis=1)
    return Sheet(nx, ny, dim, float(spacing), float(node_mass), holder, rest, a, b, k, length)


@dataclass
class Statics:
    positions: np.ndarray  # [ny][nx][dim], every node
    forces: dict  # holder k -> force the sheet exerts on it (dim values)
    torques: dict  # holder k -> torque about P_k + a_k (scalar z in 2D, 3 values in 3D)
    pivots: dict  # holder k -> its current pivot P_k + a_k
    residual: float  # largest |force| on a free DOF over load_scale
    load_scale: float  # |weight of the free nodes| + |point load| [N]
    iterations: int  # Newton iterations in all
    stable: bool  # the tangent stiffness over the free DOFs has no eigenvalue below -1e-10 of its largest diagonal entry


class _Problem:
    """Energy, residual and tangent stiffness over the free DOFs, the held
    points at `points` and the external force `fext` on the free DOFs."""

    def __init__(self, sheet, points, fext):
        self.s, self.points, self.fext, self.free = sheet, points, fext, sheet.free
        self.dof = np.full(len(points), -1)
        self.dof[self.free] = np.arange(len(self.free))

    def place(self, u):
        x = self.points.copy()
        x[self.free] = u.reshape(-1, self.s.dim)
        return x

    def springs(self, x):
        d = x[self.s.b] - x[self.s.a]
        lng = np.linalg.norm(d, axis=1)
        return d, lng, (self.s.k * (lng - self.s.length) / lng)[:, None] * d  # pull on end a

    def point_forces(self, x):
        f_a = self.springs(x)[2]
        f = np.zeros_like(x)
        np.add.at(f, self.s.a, f_a)
        np.add.at(f, self.s.b, -f_a)
        return f

    def energy(self, u):
        lng = self.springs(self.place(u))[1]
        return 0.5 * np.sum(self.s.k * (lng - self.s.length) ** 2) - self.fext @ u

    def residual(self, u):
        return self.point_forces(self.place(u))[self.free].ravel() + self.fext

    def stiffness(self, u):
        dim, n = self.s.dim, len(self.free) * self.s.dim
        d, lng, _ = self.springs(self.place(u))
        uu = d[:, :, None] * d[:, None, :] / (lng**2)[:, None, None]
        ke = self.s.k[:, None, None] * (uu + (1.0 - self.s.length / lng)[:, None, None] * (np.eye(dim) - uu))
        kmat = np.zeros((n, n))
        ia, ib = self.dof[self.s.a], self.dof[self.s.b]
        comp = np.arange(dim)
        for p, q, sign in ((ia, ia, 1.0), (ib, ib, 1.0), (ia, ib, -1.0), (ib, ia, -1.0)):
            keep = (p >= 0) & (q >= 0)
            rows = (p[keep, None] * dim + comp)[:, :, None]
            cols = (q[keep, None] * dim + comp)[:, None, :]
            np.add.at(kmat, (np.broadcast_to(rows, ke[keep].shape), np.broadcast_to(cols, ke[keep].shape)), sign * ke[keep])
        return kmat


def _step(prob, u, r, downhill=True):
    """The Newton step K du = r, with its negative curvature turned round
    (downhill in energy); K is singular out of a flat sheet's plane at rest."""
    kmat = prob.stiffness(u)
    kmat += 1e-10 * np.abs(np.diag(kmat)).max() * np.eye(len(u))
    du = np.linalg.solve(kmat, r)
    try:
        if downhill:
            np.linalg.cholesky(kmat)
    except np.linalg.LinAlgError:
        lam, vec = np.linalg.eigh(kmat)
        neg = vec[:, lam < 0.0]
        du += neg @ (2.0 * (neg.T @ r) / np.abs(lam[lam < 0.0]))
    return du


def _newton(prob, u, tol, max_iter=100):
    """Newton with a backtracking line search (on the energy, or the residual
    near round-off); (u, iterations) or None."""
    r = prob.residual(u)
    for it in range(max_iter):
        if np.abs(r).max() <= tol:  # one more plain Newton step takes it to round-off, even next to a saddle
            polished = u + _step(prob, u, r, downhill=False)
            return (polished if np.abs(prob.residual(polished)).max() < np.abs(r).max() else u), it + 1
        du = _step(prob, u, r)
        e0, slope, step, rnorm = prob.energy(u), -(r @ du), 1.0, np.linalg.norm(r)
        while step > 1e-10:
            trial = u + step * du
            r_new = prob.residual(trial)
            if prob.energy(trial) <= e0 + 1e-4 * step * slope or np.linalg.norm(r_new) < (1.0 - 1e-4 * step) * rnorm:
                u, r = trial, r_new
                break
            step *= 0.5
        else:
            return None
    return None


def solve_statics(holder_of_node, dim, placements=None, gravity=(0.0, -9.81, 0.0), load=(0.0, 0.0, 0.0), load_row=0, load_column=None,
                  guess=None, tol=1e-12, seek_stable=False, **sheet):
    """The static equilibrium of the free nodes.

    holder_of_node: [ny][nx] ints, 0 free, k held by holder k.
    placements: {k: (a_k, theta_k)}, a_k dim (or 3) values, theta_k a
        rotation vector (3 values; in 2D an angle about z or a 3-vector of
        which z counts); holders left out stay at rest.
    gravity: 3 values (z ignored in 2D); only the free nodes' weight counts.
    load, load_row, load_column: a point load (3 values, z ignored in 2D) on
        the free node load_row rows up from the bottom edge (0: the bottom
        row, as the FMU's loadRow) in column load_column (default nx // 2).
    guess: positions [ny][nx][dim] to start from (else the rest positions;
        if Newton fails from there, placement and loads are applied in steps).
    tol: residual (largest |force| on a free DOF) over |weight| + |load|.
    seek_stable: an equilibrium whose tangent stiffness has a negative
        eigenvalue is pushed along that mode (largest entry spacing / 100,
        turned towards +z, +y in 2D) and solved again, up to 8 times.
    sheet: the keywords of build_sheet (spacing, node_mass, spring_stiffness,
        shear_springs, bending_springs, aux_stiffness, inter_holder_springs).
    """
    s = build_sheet(holder_of_node, dim, **sheet)
    placements = placements or {}
    ids = sorted({int(h) for h in s.holder if h})
    if set(placements) - set(ids):
        raise ValueError(f"placements for holders {sorted(set(placements) - set(ids))} that hold no node")
    pivots = {k: s.rest[np.flatnonzero(s.holder == k)[0]] for k in ids}
    free = s.free
    grav = np.asarray(gravity, dtype=float)[:dim]
    fext = np.tile(s.node_mass * grav, len(free))
    p_load = np.asarray(load, dtype=float)[:dim]
    column = s.nx // 2 if load_column is None else load_column
    load_node = (s.ny - 1 - load_row) * s.nx + column
    if np.any(p_load != 0.0):
        if not (0 <= load_row < s.ny and 0 <= column < s.nx) or s.holder[load_node]:
            raise ValueError("the load node must be a free node of the grid")
        j = np.flatnonzero(free == load_node)[0]
        fext[j * dim:(j + 1) * dim] += p_load
    load_scale = np.linalg.norm(s.node_mass * len(free) * grav) + np.linalg.norm(p_load)
    scale = load_scale if load_scale > 0.0 else s.spacing * s.k.max()  # no load: a spring stretched by a spacing
    tol_abs = tol * scale

    def placed(frac):
        """Held points with the placements scaled by frac; {k: (a_k, R_k)}."""
        x, moves = s.rest.copy(), {}
        for k in ids:
            a_k, theta = placements.get(k, (np.zeros(dim), 0.0))
            a_k, rot = frac * np.asarray(a_k, dtype=float)[:dim], rotation(frac * np.asarray(theta, dtype=float), dim)
            moves[k], carried = (a_k, rot), s.carried(k)
            x[carried] = pivots[k] + a_k + (s.rest[carried] - pivots[k]) @ rot.T
        return x, moves

    iterations, u, done, step = 0, s.rest[free].ravel(), 0.0, 1.0
    if guess is not None:
        solved = _newton(_Problem(s, placed(1.0)[0], fext), np.asarray(guess, dtype=float).reshape(-1, dim)[free].ravel(), tol_abs)
        if solved is not None:
            (u, iterations), done = solved, 1.0
    while done < 1.0:  # from rest, the placements and the loads in steps: halved when Newton fails, doubled when it succeeds
        frac = min(1.0, done + step)
        trial = _newton(_Problem(s, placed(frac)[0], frac * fext), u, tol_abs if frac == 1.0 else 1e-6 * tol_abs / tol)
        if trial is None:
            step *= 0.5
            if step < 1.0 / 4096:
                raise RuntimeError(f"no equilibrium found beyond {done:.4f} of the placement and loads")
            continue
        u, done, step, iterations = trial[0], frac, min(1.0, 2.0 * step), iterations + trial[1]
    points, moves = placed(1.0)
    prob = _Problem(s, points, fext)
    for _ in range(8 if seek_stable else 0):
        lam, vec = np.linalg.eigh(kmat := prob.stiffness(u))
        if lam[0] >= -1e-10 * np.abs(np.diag(kmat)).max():
            break
        mode = vec[:, 0] / np.abs(vec[:, 0]).max()
        pushed = _newton(prob, u + 0.01 * s.spacing * mode * (1.0 if mode[dim - 1::dim].sum() >= 0.0 else -1.0), tol_abs)
        if pushed is None:
            raise RuntimeError("no equilibrium found after a push out of an unstable one")
        u, iterations = pushed[0], iterations + pushed[1]
    x = prob.place(u)
    f = prob.point_forces(x)
    forces, torques, current = {}, {}, {}
    for k in ids:
        carried, current[k] = s.carried(k), pivots[k] + moves[k][0]
        forces[k], arm = f[carried].sum(axis=0), x[carried] - current[k]
        torque = np.cross(arm, f[carried]).sum(axis=0) if dim == 3 else np.sum(arm[:, 0] * f[carried, 1] - arm[:, 1] * f[carried, 0])
        torques[k] = torque if dim == 3 else float(torque)
    residual = np.abs(prob.residual(u)).max() / scale
    kmat = prob.stiffness(u)
    stable = bool(np.linalg.eigvalsh(kmat)[0] >= -1e-10 * np.abs(np.diag(kmat)).max())
    return Statics(x[:s.n_nodes].reshape(s.ny, s.nx, dim), forces, torques, current, residual, load_scale, iterations, stable)

"""Implicit coupling of the chain (python/chain.py): every communication step
is repeated from saved FMU states of both sheets until the interface agrees.

The step from t_k to t_k + h is a fixed-point problem in the load f that A
holds over the step (zero-order hold, docs/method.md section 8):

    H(f): restore A and B to t_k; A.load = f; A steps;
          B.anchor = A.loadNode(t_k + h) - A.loadNode(0); B steps
          (B's anchor moves linearly to A's node over the step: first-order hold);
          F_1 = B.anchorForce(t_k + h), F_0 = B.anchorForce(t_k)
          H(f) = (F_0 + F_1) / 2     (hold "mean", the default)
          H(f) = F_1                 (hold "end")

    r(f) = H(f) - f = 0

With "mean" the constant load A holds carries B's impulse over the step by
the trapezoidal rule (second order in h); with "end" A carries the pull at
the end of the step (first order). B's anchor ends the step where A's load
node does either way. One evaluation of H with "end" and
f = B.anchorForce(t_k) is the explicit Gauss-Seidel step; the iterations
solve the step's interface equations instead of lagging the force by one
step. The sequence of iterates f^i, H^i = H(f^i), r^i = H^i - f^i is
accelerated (serial coupling: only the force that B sends A is changed, as
preCICE does for the data of its second participant):

- Aitken's dynamic under-relaxation (Kuettler and Wall 2008):
  f^{i+1} = f^i + w_i r^i with
  w_i = -w_{i-1} r^{i-1}.(r^i - r^{i-1}) / |r^i - r^{i-1}|^2,
  the first iteration of a step with w_0 = sign(w) min(w_init, |w|) of the
  last step.
- IQN-ILS (Degroote, Bathe and Vierendeels 2009; preCICE): the columns
  V = [r^i - r^{i-1}, ...], W = [H^i - H^{i-1}, ...] (newest first, then
  those of up to `reuse` earlier steps) give the least-squares
  alpha = argmin |V alpha + r^k| and f^{k+1} = H^k + W alpha, an inverse
  Jacobian of r from the secants. Columns nearly dependent on newer ones are
  dropped before the solve (QR by Gram-Schmidt: a column whose component
  orthogonal to the kept ones is shorter than `drop` times its length goes).
  Without a column, f^{k+1} = f^k + w_init r^k.

The step has converged when |r^k| <= tol |H^k| (relative). The other
interface value, A's load node at t_k + h, is a function of f within the
step, so it has converged with f. A converged step leaves the FMUs at
t_k + h with the inputs of the last evaluation: the accepted step is one
the FMUs took, never a recombination. A step not converged after
`max_iter` evaluations raises NotConverged.
"""

import time

import numpy as np

# A's inputs and outputs and B's on the interface (x, y of the 2D sheets).
LOAD = ["loadX", "loadY"]
NODE = ["loadNodeX", "loadNodeY"]
ANCHOR = ["anchorX", "anchorY"]
FORCE = ["anchorForceX", "anchorForceY"]


class NotConverged(RuntimeError):
    """A communication step whose interface did not converge."""


class Aitken:
    """Aitken's dynamic under-relaxation of the fixed-point iteration."""

    name = "aitken"

    def __init__(self, initial=0.5):
        self.initial = initial
        self.omega = initial
        self.r_prev = None

    def start_step(self):
        self.r_prev = None

    def next(self, f, value):
        r = value - f
        if self.r_prev is None:
            self.omega = np.copysign(min(self.initial, abs(self.omega)), self.omega)
        else:
            dr = r - self.r_prev
            dr2 = dr @ dr
            if dr2 > 0.0:
                self.omega = -self.omega * (self.r_prev @ dr) / dr2
        self.r_prev = r
        return f + self.omega * r

    def end_step(self):
        pass


def filtered(v_cols, w_cols, drop):
    """The columns of V (and W alongside) kept by a QR with a drop tolerance:
    newest first, a column whose part orthogonal to those kept is shorter
    than drop times its length is left out. Returns (Q, R, W) of the kept."""
    q, r_rows, kept_w = [], [], []
    for v, w in zip(v_cols, w_cols, strict=True):
        if len(q) == len(v):
            break  # the kept columns span the interface: no further one is independent
        norm = np.linalg.norm(v)
        if norm == 0.0:
            continue
        coeffs = np.array([qi @ v for qi in q])
        orth = v - sum((c * qi for c, qi in zip(coeffs, q, strict=True)), np.zeros_like(v))
        # second pass of Gram-Schmidt against cancellation
        corr = np.array([qi @ orth for qi in q])
        orth = orth - sum((c * qi for c, qi in zip(corr, q, strict=True)), np.zeros_like(v))
        length = np.linalg.norm(orth)
        if length < drop * norm:
            continue
        r_rows.append((coeffs + corr if q else np.zeros(0), length))
        q.append(orth / length)
        kept_w.append(w)
    n = len(q)
    R = np.zeros((n, n))
    for j, (c, length) in enumerate(r_rows):
        R[:j, j] = c
        R[j, j] = length
    Q = np.array(q).T if q else np.zeros((0, 0))
    return Q, R, kept_w


class IQNILS:
    """Interface quasi-Newton with an inverse Jacobian from a least-squares
    fit of the residual differences (IQN-ILS)."""

    name = "iqn-ils"

    def __init__(self, initial=0.5, reuse=8, drop=1e-2):
        self.initial, self.reuse, self.drop = initial, reuse, drop
        self.old = []  # (V columns, W columns) of earlier steps, newest first
        self.v, self.w = [], []
        self.r_prev = self.value_prev = None

    def start_step(self):
        self.v, self.w = [], []
        self.r_prev = self.value_prev = None

    def next(self, f, value):
        r = value - f
        if self.r_prev is not None:
            self.v.insert(0, r - self.r_prev)
            self.w.insert(0, value - self.value_prev)
        self.r_prev, self.value_prev = r, value
        v_cols = self.v + [c for vs, _ in self.old for c in vs]
        w_cols = self.w + [c for _, ws in self.old for c in ws]
        Q, R, w_kept = filtered(v_cols, w_cols, self.drop)
        if not w_kept:
            return f + self.initial * r
        alpha = np.linalg.solve(R, -(Q.T @ r))
        return value + np.array(w_kept).T @ alpha

    def end_step(self):
        if self.reuse > 0 and self.v:
            self.old.insert(0, (self.v, self.w))
            del self.old[self.reuse:]


def accelerator(name, **options):
    """Aitken or IQN-ILS by name (the --coupling of chain.py)."""
    return {"aitken": Aitken, "iqn-ils": IQNILS}[name](**options)


class Stats:
    """Evaluations per communication step and the cost of the saved states."""

    def __init__(self):
        self.iterations = []
        self.saves = []  # seconds per fmi3GetFMUState of one sheet
        self.restores = []  # seconds per fmi3SetFMUState of one sheet
        self.step_time = []  # seconds per communication step, all iterations

    def summary(self):
        it = np.array(self.iterations)
        st = np.array(self.step_time)
        spent = 2 * (np.sum(self.saves) + np.sum(self.restores))
        return {
            "steps": len(it),
            "mean_iterations": float(it.mean()) if len(it) else 0.0,
            "max_iterations": int(it.max()) if len(it) else 0,
            "save_us": float(np.median(self.saves) * 1e6) if self.saves else 0.0,
            "restore_us": float(np.median(self.restores) * 1e6) if self.restores else 0.0,
            "step_ms": float(np.median(st) * 1e3) if len(st) else 0.0,
            # both sheets saved once a step and restored once an evaluation but the first
            "state_share": float(spent / st.sum()) if len(st) else 0.0,
        }


def implicit_step(a, b, t, h, offset, acc, stats, tol=1e-10, max_iter=50, hold="mean"):
    """One communication step of the implicit chain from t to t + h.

    a, b: chain.Sheet of A and B at t; A's load input is the predictor f^0.
    offset: subtracted from A's load node for B's anchor (A.loadNode(0), or
    zero for the absolute anchor). acc: Aitken or IQNILS. tol: relative
    tolerance on the residual; max_iter: evaluations of H at most; hold:
    "mean" (the load over the step is the mean of B's pull at its two ends)
    or "end" (B's pull at its end). Returns the number of evaluations; the
    FMUs are left at t + h. Raises NotConverged.
    """
    if hold not in ("mean", "end"):
        raise ValueError(f"unknown hold {hold!r}: mean or end")
    if max_iter < 1:
        raise ValueError(f"max_iter = {max_iter}: at least one evaluation a step")
    clock = time.perf_counter()
    tick = time.perf_counter()
    states = [a.slave.getFMUState(), b.slave.getFMUState()]
    stats.saves.append((time.perf_counter() - tick) / 2)
    f = np.array(a.get(*LOAD))
    start = np.array(b.get(*FORCE))
    acc.start_step()
    try:
        for i in range(1, max_iter + 1):
            if i > 1:
                tick = time.perf_counter()
                a.slave.setFMUState(states[0])
                b.slave.setFMUState(states[1])
                stats.restores.append((time.perf_counter() - tick) / 2)
            a.set(LOAD, f)
            a.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            b.set(ANCHOR, np.array(a.get(*NODE)) - offset)
            b.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            end = np.array(b.get(*FORCE))
            value = 0.5 * (start + end) if hold == "mean" else end
            r = value - f
            if np.linalg.norm(r) <= tol * np.linalg.norm(value):
                acc.end_step()
                stats.iterations.append(i)
                stats.step_time.append(time.perf_counter() - clock)
                return i
            f = acc.next(f, value)
    finally:
        for s, state in zip((a, b), states, strict=True):
            s.slave.freeFMUState(state)
    raise NotConverged(
        f"the implicit chain ({acc.name}) did not converge in the step from t = {t:g} s by {h:g} s: "
        f"after {max_iter} iterations |r| = {np.linalg.norm(r):.3e} N > tol |H| = "
        f"{tol * np.linalg.norm(value):.3e} N; the step is not accepted"
    )

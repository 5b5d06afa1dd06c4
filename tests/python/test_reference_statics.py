"""The NumPy reference of the static equilibrium (reference_statics.py, no
code shared with the FMU) against the FMU's full space, and the reference's
own balances with several holders.

The FMU starts at rest in the undeformed shape wherever its holder is placed
(linearization = equilibrium only moves the linearization point of the modal
basis), so each run is settled: full space, the default explicit Newmark
scheme, dampingAlpha = 8 1/s for 20 s in 0.5 s communication steps. The
slowest motion of these 5 x 4 and 8 x 6 sheets then decays by far more than
the 1e-6 the comparison needs: the positions of t = 15 s and t = 20 s agree
to round-off, and the velocities are at round-off.
"""

import numpy as np
import pytest

from reference_statics import holders, rotation, solve_statics

SETTLE_ALPHA, SETTLE_TIME, STEP = 8.0, 20.0, 0.5
FIXED = {"top-row": 1, "top-corners": 2}
MOVED = {"anchor": (0.02, -0.01, 0.03), "turn": (0.0, 0.0, 0.4)}  # a fifth of a 5-node row, and 0.4 rad about z
LOAD = (0.3, -0.5, 0.2)

# (id, grid nx x ny, dimension, fixed nodes, FMU settings): every combination
# of 2D / 3D, top row / top corners and a holder at rest / moved and turned,
# all with a point load; then other springs, gravity, load nodes and turns.
CASES = [(f"{d}d-{fixed}-{moved}", (5, 4), d, fixed, {"load": LOAD, **(MOVED if moved == "moved" else {})})
         for d in (2, 3) for fixed in FIXED for moved in ("rest", "moved")]
CASES += [
    ("2d-bending-no-shear-tilted-gravity", (6, 5), 2, "top-row",
     {"shear": False, "bending": True, "gravity": (2.0, -9.81, 0.0), "load": (-0.2, -0.4, 0.0), "load_node": (1, 1)}),
    ("2d-top-corners-8x6-turned-back", (8, 6), 2, "top-corners", {"anchor": (-0.05, 0.04, 0.0), "turn": (0.0, 0.0, -0.6), "load": (0.0, -1.0, 0.0)}),
    ("3d-turned-about-a-tilted-axis", (5, 4), 3, "top-row", {"anchor": (0.01, 0.02, -0.03), "turn": (0.3, -0.2, 0.25), "load": LOAD, "load_node": (0, 4)}),
    ("3d-top-corners-bending-stiff-aux", (5, 4), 3, "top-corners", {"bending": True, "aux": 2.0, "turn": (-0.2, 0.3, 0.0), "load": (0.0, 0.0, 0.5)}),
    # no auxiliary springs, nothing across the plane: the flat equilibrium,
    # unstable (compressed springs across the columns), which a run that
    # starts flat keeps exactly
    ("3d-no-aux-flat", (5, 4), 3, "top-row", {"aux": 0.0, "load": (0.3, -0.5, 0.0), "turn": (0.0, 0.0, 0.2)}),
]


def settled_fmu(new_instance, nx, ny, dim, fixed, cfg):
    inst = new_instance()
    s = inst.slave
    s.enterConfigurationMode()
    s.setUInt64([inst.vr["nx"], inst.vr["ny"], inst.vr["dimension"]], [nx, ny, dim])
    s.exitConfigurationMode()
    s.setInt64([inst.vr["reduction"], inst.vr["fixedNodes"]], [2, FIXED[fixed]])  # full space
    s.setBoolean([inst.vr["shearSprings"], inst.vr["bendingSprings"]], [cfg.get("shear", True), cfg.get("bending", False)])
    row, col = cfg.get("load_node", (0, nx // 2))
    s.setUInt64([inst.vr["loadRow"], inst.vr["loadColumn"]], [row, col])
    inst.set_f64("auxStiffness", cfg.get("aux", 0.05))
    inst.set_f64("gravity", cfg.get("gravity", (0.0, -9.81, 0.0)))
    inst.set_f64("dampingAlpha", SETTLE_ALPHA)
    names = [f"load{c}" for c in "XYZ"] + [f"anchor{c}" for c in "XYZ"] + [f"anchorR{c}" for c in "XYZ"]
    values = [*cfg.get("load", (0.0,) * 3), *cfg.get("anchor", (0.0,) * 3), *cfg.get("turn", (0.0,) * 3)]
    s.setFloat64([inst.vr[n] for n in names], values)  # before initialization: the holder placed there, the sheet at rest
    inst.initialize()
    inst.step(STEP, round((SETTLE_TIME - 5.0) / STEP))
    earlier = inst.positions().copy()
    inst.step(STEP, round(5.0 / STEP))
    out = {
        "positions": inst.positions(),
        "drift": float(np.abs(inst.positions() - earlier).max()),
        "speed": float(np.abs(inst.f64("velocities", nx * ny * dim)).max()),
        "force": np.array([inst.f64s(f"anchorForce{c}") for c in "XYZ"]),
        "torque": np.array([inst.f64s(f"anchorTorque{c}") for c in "XYZ"]),
    }
    assert not [m for m in inst.messages if m[0] > 0], inst.messages
    return out


def reference(nx, ny, dim, fixed, cfg):
    return solve_statics(holders(fixed, nx, ny), dim, placements={1: (cfg.get("anchor", (0.0,) * 3), cfg.get("turn", (0.0,) * 3))},
                         gravity=cfg.get("gravity", (0.0, -9.81, 0.0)), load=cfg.get("load", (0.0,) * 3),
                         load_row=cfg.get("load_node", (0, nx // 2))[0], load_column=cfg.get("load_node", (0, nx // 2))[1],
                         shear_springs=cfg.get("shear", True), bending_springs=cfg.get("bending", False), aux_stiffness=cfg.get("aux", 0.05))


@pytest.mark.parametrize("name,grid,dim,fixed,cfg", CASES, ids=[c[0] for c in CASES])
def test_the_fmu_settles_at_the_reference_equilibrium(new_instance, name, grid, dim, fixed, cfg):
    nx, ny = grid
    eq = reference(nx, ny, dim, fixed, cfg)
    fmu = settled_fmu(new_instance, nx, ny, dim, fixed, cfg)
    weight = eq.load_scale
    rest = np.stack(np.meshgrid(np.arange(nx) * 0.1, -np.arange(ny) * 0.1), axis=-1)
    sag = np.abs(eq.positions[..., :2] - rest).max()
    dx = np.abs(fmu["positions"] - eq.positions).max()
    df = np.abs(fmu["force"][:dim] - eq.forces[1]).max() / weight
    torque = fmu["torque"][2] if dim == 2 else fmu["torque"]
    dt = np.abs(torque - eq.torques[1]).max() / weight
    print(f"{name}: |positions - reference| {dx:.2e} m (sheet moved up to {sag:.3f} m from rest), "
          f"|anchorForce - F_1| {df:.2e}, |anchorTorque - tau_1| {dt:.2e} of the load {weight:.4f} N; "
          f"FMU drift over the last 5 s {fmu['drift']:.1e} m, speed {fmu['speed']:.1e} m/s; "
          f"reference: {eq.iterations} Newton iterations, residual {eq.residual:.1e}, stable {eq.stable}")
    assert eq.residual <= 1e-12
    assert eq.stable == (name != "3d-no-aux-flat")
    assert fmu["drift"] < 1e-9 and fmu["speed"] < 1e-9, "not settled"
    assert dx < 1e-6
    assert df < 1e-6
    assert dt < 1e-6
    if dim == 2:
        assert fmu["force"][2] == fmu["torque"][0] == fmu["torque"][1] == 0.0


def pad3(v):
    v = np.atleast_1d(np.asarray(v, dtype=float))
    return np.array([0.0, 0.0, v[0]]) if v.size == 1 else np.pad(v, (0, 3 - v.size))


@pytest.mark.parametrize("inter", [True, False], ids=["springs-between-holders", "none-between-holders"])
@pytest.mark.parametrize("dim", [2, 3])
def test_several_holders_balance_the_weight_and_its_moment(dim, inter):
    """Three holders on the top row of a 10 x 6 sheet, the right one moved
    out by a fifth of its width (0.18 m) and turned, the left one moved out
    by half that and turned about a tilted axis, the middle one lifted: the
    solve converges from rest, the holders' forces add up to
    the weight of the free nodes and the load, and their torques, carried
    to one point, to the moment of those about it; with the springs between
    two holders kept (the default) or left out."""
    nx, ny = 10, 6
    held = np.zeros((ny, nx), dtype=int)
    held[0, :3], held[0, 3:7], held[0, 7:] = 1, 2, 3
    placements = {1: ((-0.09, 0.0, 0.0), (0.0, 0.1, 0.3)), 2: ((0.0, 0.02, 0.01), 0.0), 3: ((0.18, -0.03, 0.0), (0.0, 0.0, -0.3))}
    gravity, load, load_node = (0.5, -9.81, 0.3), (0.4, -1.0, 0.6), (2, 3)
    eq = solve_statics(held, dim, placements=placements, gravity=gravity, load=load, load_row=load_node[0], load_column=load_node[1],
                       bending_springs=True, aux_stiffness=0.05 if dim == 3 else 0.0, inter_holder_springs=inter)
    x = np.zeros((ny, nx, 3))
    x[..., :dim] = eq.positions
    g = np.zeros(3)
    g[:dim] = np.asarray(gravity)[:dim]
    p = np.zeros(3)
    p[:dim] = np.asarray(load)[:dim]
    free = held == 0
    weight = 0.01 * free.sum() * g + p
    moment = np.cross(x[free], 0.01 * g).sum(axis=0) + np.cross(x[ny - 1 - load_node[0], load_node[1]], p)
    forces = sum(pad3(eq.forces[k]) for k in eq.forces)
    torques = sum(pad3(eq.torques[k]) + np.cross(pad3(eq.pivots[k]), pad3(eq.forces[k])) for k in eq.forces)
    scale = eq.load_scale
    print(f"{dim}D, 3 holders, springs between them {'kept' if inter else 'left out'}: "
          f"{eq.iterations} Newton iterations, residual {eq.residual:.1e}, stable {eq.stable}; "
          f"|sum F_k - weight - load| {np.abs(forces - weight).max() / scale:.1e}, "
          f"|sum of the moments - moment of weight and load| {np.abs(torques - moment).max() / scale:.1e} of the load {scale:.3f} N; "
          f"forces {[np.round(eq.forces[k], 4).tolist() for k in eq.forces]}")
    assert eq.residual <= 1e-12 and eq.stable
    assert np.abs(forces - weight).max() < 1e-12 * scale
    assert np.abs(torques - moment).max() < 1e-12 * scale
    for k, node in ((1, 0), (2, 3), (3, 7)):  # each holder's first node sits at its pivot, carried by its translation
        assert np.array_equal(eq.positions[0, node], np.array([0.1 * node, 0.0]) + np.asarray(placements[k][0])[:dim] if dim == 2 else
                              np.array([0.1 * node, 0.0, 0.0]) + placements[k][0])
    assert np.allclose(np.linalg.norm(eq.positions[0, 1:3] - eq.positions[0, 0], axis=-1), [0.1, 0.2], atol=1e-14)  # rigid


@pytest.mark.parametrize("dim", [2, 3])
def test_one_holder_split_in_parts_that_move_together(dim):
    """The top row held by two holders placed by the same rigid motion is
    the sheet held by one: the same positions, forces adding up to its
    force, torques about their own pivots adding up to its torque."""
    nx, ny = 6, 5
    one, two = holders("top-row", nx, ny), holders("top-row", nx, ny)
    two[0, 4:] = 2
    a, theta = np.array([0.03, -0.02, 0.01])[:dim], np.array([0.1, -0.15, 0.35])
    pivot2 = np.array([0.4, 0.0, 0.0])[:dim]  # node (0, 4); holder 1's pivot is node (0, 0), at the origin
    a2 = a + rotation(theta, dim) @ pivot2 - pivot2  # the same rigid motion, about holder 2's pivot
    kw = {"load": (0.2, -0.3, 0.1), "load_row": 1, "load_column": 2, "aux_stiffness": 0.05 if dim == 3 else 0.0}
    ref = solve_statics(one, dim, placements={1: (a, theta)}, **kw)
    split = solve_statics(two, dim, placements={1: (a, theta), 2: (a2, theta)}, **kw)
    moved = pad3(split.torques[1]) + pad3(split.torques[2]) + np.cross(pad3(split.pivots[2] - split.pivots[1]), pad3(split.forces[2]))
    dx = np.abs(split.positions - ref.positions).max()
    df = np.abs(split.forces[1] + split.forces[2] - ref.forces[1]).max() / ref.load_scale
    dt = np.abs(moved - pad3(ref.torques[1])).max() / ref.load_scale
    # the springs between the two holders keep their rest length: left out or kept (the default), the same
    kept = solve_statics(two, dim, placements={1: (a, theta), 2: (a2, theta)}, inter_holder_springs=False, **kw)
    dk = max(np.abs(kept.positions - split.positions).max(), *(np.abs(kept.forces[k] - split.forces[k]).max() for k in (1, 2)))
    # started from its own solution, Newton is done at once
    again = solve_statics(two, dim, placements={1: (a, theta), 2: (a2, theta)}, guess=split.positions, **kw)
    print(f"{dim}D split holder: positions {dx:.1e} m, forces {df:.1e}, torques {dt:.1e} of the load; "
          f"springs between the holders left out: {dk:.1e}; from its own solution: {again.iterations} iteration(s)")
    assert dx < 1e-12 and df < 1e-12 and dt < 1e-12 and dk < 1e-12
    assert again.iterations <= 1 and np.abs(again.positions - split.positions).max() < 1e-14

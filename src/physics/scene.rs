//! Scene assembly: the grid of METHOD.md section 5 turned into slots, springs
//! and free degrees of freedom.
//!
//! Positions live in one array of *slots* of `d` coordinates each: first the
//! free nodes (so the free DOFs are the contiguous prefix `0..n_dofs`), then
//! the fixed nodes, then the anchor points of the auxiliary springs. A spring
//! joins two slots; an end in a slot at or past `n_free` is held in place.

use super::params::{FixedNodes, SceneParams};
use super::SimError;

/// Largest grid accepted (nodes); beyond it the arrays alone pass a gigabyte.
pub const MAX_NODES: usize = 4_000_000;

/// One spring between two slots: stiffness `k`, rest length `rest`.
#[derive(Clone, Copy, Debug)]
pub struct Spring {
    pub a: usize,
    pub b: usize,
    pub k: f64,
    pub rest: f64,
}

/// The assembled scene.
#[derive(Clone, Debug)]
pub struct Scene {
    pub dim: usize,
    pub nx: usize,
    pub ny: usize,
    pub n_nodes: usize,
    /// Free nodes; the free DOFs are `n_free * dim`.
    pub n_free: usize,
    /// Slot of every grid node (node order of METHOD.md).
    pub slot_of_node: Vec<usize>,
    /// Rest coordinates of every slot (`dim` per slot).
    pub rest: Vec<f64>,
    /// Mass of each free DOF (the diagonal of M).
    pub dof_mass: Vec<f64>,
    pub springs: Vec<Spring>,
}

impl Scene {
    /// Number of free degrees of freedom.
    pub fn n_dofs(&self) -> usize {
        self.n_free * self.dim
    }

    /// Builds the grid, refusing parameters that cannot make one.
    pub fn build(p: &SceneParams) -> Result<Scene, SimError> {
        validate(p)?;
        let (nx, ny, d, h) = (p.nx, p.ny, p.dimension, p.spacing);
        let n_nodes = nx * ny;
        let is_fixed = |node: usize| {
            let (row, col) = (node / nx, node % nx);
            row == 0
                && match p.fixed_nodes {
                    FixedNodes::TopRow => true,
                    FixedNodes::TopCorners => col == 0 || col == nx - 1,
                }
        };
        // Free nodes first, in node order, then fixed nodes.
        let mut slot_of_node = vec![0; n_nodes];
        let mut next = 0;
        for pass_fixed in [false, true] {
            for (node, slot) in slot_of_node.iter_mut().enumerate() {
                if is_fixed(node) == pass_fixed {
                    *slot = next;
                    next += 1;
                }
            }
        }
        let n_free = (0..n_nodes).filter(|&n| !is_fixed(n)).count();
        let aux = d == 3 && p.aux_stiffness > 0.0;
        let n_slots = n_nodes + if aux { n_free } else { 0 };
        let mut rest = vec![0.0; n_slots * d];
        for node in 0..n_nodes {
            let s = slot_of_node[node];
            rest[s * d] = (node % nx) as f64 * h;
            rest[s * d + 1] = -((node / nx) as f64) * h;
        }
        let mut springs = Vec::new();
        let mut join = |r0: usize, c0: usize, r1: usize, c1: usize| {
            let (a, b) = (slot_of_node[r0 * nx + c0], slot_of_node[r1 * nx + c1]);
            if a >= n_free && b >= n_free {
                return; // both ends fixed: it never moves, never acts
            }
            let len = (0..d).map(|i| (rest[b * d + i] - rest[a * d + i]).powi(2)).sum::<f64>().sqrt();
            springs.push(Spring { a, b, k: p.spring_stiffness, rest: len });
        };
        for r in 0..ny {
            for c in 0..nx {
                if c + 1 < nx {
                    join(r, c, r, c + 1);
                }
                if r + 1 < ny {
                    join(r, c, r + 1, c);
                }
                if p.shear_springs && r + 1 < ny && c + 1 < nx {
                    join(r, c, r + 1, c + 1);
                    join(r, c + 1, r + 1, c);
                }
                if p.bending_springs {
                    if c + 2 < nx {
                        join(r, c, r, c + 2);
                    }
                    if r + 2 < ny {
                        join(r, c, r + 2, c);
                    }
                }
            }
        }
        if aux {
            // Each free node tied to its rest position + (0, 0, h), rest length h.
            for s in 0..n_free {
                let anchor = n_nodes + s;
                for i in 0..d {
                    rest[anchor * d + i] = rest[s * d + i];
                }
                rest[anchor * d + 2] += h;
                springs.push(Spring { a: s, b: anchor, k: p.aux_stiffness, rest: h });
            }
        }
        Ok(Scene { dim: d, nx, ny, n_nodes, n_free, slot_of_node, rest, dof_mass: vec![p.node_mass; n_free * d], springs })
    }
}

fn validate(p: &SceneParams) -> Result<(), SimError> {
    let bad = |m: String| Err(SimError { message: m });
    if p.dimension != 2 && p.dimension != 3 {
        return bad(format!("dimension must be 2 or 3, got {}", p.dimension));
    }
    if p.nx == 0 || p.ny == 0 {
        return bad(format!("nx and ny must be at least 1, got nx = {}, ny = {}", p.nx, p.ny));
    }
    match p.nx.checked_mul(p.ny) {
        Some(n) if n <= MAX_NODES => {}
        _ => return bad(format!("nx * ny = {} x {} exceeds the limit of {MAX_NODES} nodes", p.nx, p.ny)),
    }
    if !(p.spacing.is_finite() && p.spacing > 0.0) {
        return bad(format!("spacing must be finite and positive, got {}", p.spacing));
    }
    if !(p.node_mass.is_finite() && p.node_mass > 0.0) {
        return bad(format!("nodeMass must be finite and positive, got {}", p.node_mass));
    }
    if !(p.spring_stiffness.is_finite() && p.spring_stiffness > 0.0) {
        return bad(format!("springStiffness must be finite and positive, got {}", p.spring_stiffness));
    }
    if !(p.aux_stiffness.is_finite() && p.aux_stiffness >= 0.0) {
        return bad(format!("auxStiffness must be finite and non-negative, got {}", p.aux_stiffness));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_grid_counts() {
        let s = Scene::build(&SceneParams::canonical("paper-2d-top-row").unwrap()).unwrap();
        assert_eq!(s.n_free, 90);
        assert_eq!(s.n_dofs(), 180);
        // structural 9*10*2 + shear 2*81, minus the 9 top-row springs between fixed nodes
        assert_eq!(s.springs.len(), 180 + 162 - 9);
        let c = Scene::build(&SceneParams::canonical("paper-2d-top-corners").unwrap()).unwrap();
        assert_eq!(c.n_free, 98);
        let s3 = Scene::build(&SceneParams::canonical("paper-3d-sheet").unwrap()).unwrap();
        assert_eq!(s3.n_free, 42);
        assert_eq!(s3.springs.len(), 6 * 7 * 2 + 2 * 36 - 6 + 42);
    }

    #[test]
    fn rest_lengths_are_rest_distances() {
        let s = Scene::build(&SceneParams::canonical("paper-3d-sheet").unwrap()).unwrap();
        for sp in &s.springs {
            let l: f64 = (0..3).map(|i| (s.rest[sp.b * 3 + i] - s.rest[sp.a * 3 + i]).powi(2)).sum::<f64>().sqrt();
            assert!((l - sp.rest).abs() < 1e-15);
        }
    }

    #[test]
    fn refuses_bad_parameters_by_name() {
        let mut p = SceneParams::default();
        p.spacing = -1.0;
        assert!(Scene::build(&p).unwrap_err().message.contains("spacing"));
        let mut p = SceneParams::default();
        p.dimension = 4;
        assert!(Scene::build(&p).unwrap_err().message.contains("dimension"));
    }
}

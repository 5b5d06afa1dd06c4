//! The grid builder: a rectangular sheet of nodes joined by structural,
//! shear and bending springs, hung from its top row or its top corners,
//! with optional auxiliary springs out of its plane (`docs/method.md`,
//! section 5). It turns grid parameters into a [`Scene`]; the solver only
//! ever sees the scene.

pub use crate::options::FixedNodes;
use crate::physics::error::{non_negative, positive, Expected, PhysicsError, Quantity};
use crate::physics::setup::scene::{Scene, Spring};

/// Largest grid accepted (nodes); beyond it the arrays alone pass a gigabyte.
pub const MAX_NODES: usize = 4_000_000;

/// A grid of `columns` x `rows` nodes. Node `(row, col)` has index
/// `row * columns + col` and rests at `(col * spacing, -row * spacing[, 0])`.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Nodes per row.
    pub columns: usize,
    /// Rows; row 0 is the top edge.
    pub rows: usize,
    /// 2 or 3.
    pub dim: usize,
    /// Rest distance between neighbouring nodes [m].
    pub spacing: f64,
    /// Mass of every node [kg].
    pub node_mass: f64,
    /// Stiffness of every grid spring [N/m].
    pub spring_stiffness: f64,
    /// Diagonal springs (r,c)-(r+1,c+1) and (r,c+1)-(r+1,c).
    pub shear_springs: bool,
    /// Springs (r,c)-(r,c+2) and (r,c)-(r+2,c).
    pub bending_springs: bool,
    /// Stiffness of the auxiliary springs tying each free node to a point
    /// `spacing` out of the plane (3D only; 0 leaves them out) [N/m].
    pub aux_stiffness: f64,
    /// Which nodes are held in place.
    pub fixed_nodes: FixedNodes,
}

impl Grid {
    /// Builds the scene, refusing parameters that cannot make one.
    pub fn build(&self) -> Result<Scene, PhysicsError> {
        self.validate()?;
        let (cols, rows, d, h) = (self.columns, self.rows, self.dim, self.spacing);
        let n_nodes = cols * rows;
        let is_fixed = |node: usize| self.is_held(node);
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
        let aux = d == 3 && self.aux_stiffness > 0.0;
        let n_slots = n_nodes + if aux { n_free } else { 0 };
        let mut rest = vec![0.0; n_slots * d];
        for node in 0..n_nodes {
            let s = slot_of_node[node];
            rest[s * d] = (node % cols) as f64 * h;
            rest[s * d + 1] = -((node / cols) as f64) * h;
        }
        let mut springs = Vec::new();
        let mut join = |r0: usize, c0: usize, r1: usize, c1: usize| {
            let (a, b) = (slot_of_node[r0 * cols + c0], slot_of_node[r1 * cols + c1]);
            if a >= n_free && b >= n_free {
                return; // both ends fixed: it never moves, never acts
            }
            let len = (0..d).map(|i| (rest[b * d + i] - rest[a * d + i]).powi(2)).sum::<f64>().sqrt();
            springs.push(Spring { a, b, k: self.spring_stiffness, rest: len });
        };
        for r in 0..rows {
            for c in 0..cols {
                if c + 1 < cols {
                    join(r, c, r, c + 1);
                }
                if r + 1 < rows {
                    join(r, c, r + 1, c);
                }
                if self.shear_springs && r + 1 < rows && c + 1 < cols {
                    join(r, c, r + 1, c + 1);
                    join(r, c + 1, r + 1, c);
                }
                if self.bending_springs {
                    if c + 2 < cols {
                        join(r, c, r, c + 2);
                    }
                    if r + 2 < rows {
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
                springs.push(Spring { a: s, b: anchor, k: self.aux_stiffness, rest: h });
            }
        }
        let scene = Scene { dim: d, n_nodes, n_free, slot_of_node, rest, dof_mass: vec![self.node_mass; n_free * d], springs };
        scene.check()?;
        Ok(scene)
    }

    /// The index of node (`row`, `col`), if it is in the grid.
    pub fn node(&self, row: usize, col: usize) -> Option<usize> {
        (row < self.rows && col < self.columns).then(|| row * self.columns + col)
    }

    /// Node `node` is held in place.
    pub fn is_held(&self, node: usize) -> bool {
        let (row, col) = (node / self.columns, node % self.columns);
        row == 0
            && match self.fixed_nodes {
                FixedNodes::TopRow => true,
                FixedNodes::TopCorners => col == 0 || col == self.columns - 1,
            }
    }

    fn validate(&self) -> Result<(), PhysicsError> {
        if self.dim != 2 && self.dim != 3 {
            return Err(PhysicsError::Invalid { quantity: Quantity::Dimension, value: self.dim as f64, expected: Expected::TwoOrThree });
        }
        for (quantity, n) in [(Quantity::Columns, self.columns), (Quantity::Rows, self.rows)] {
            if n == 0 {
                return Err(PhysicsError::Invalid { quantity, value: 0.0, expected: Expected::AtLeast(1.0) });
            }
        }
        match self.columns.checked_mul(self.rows) {
            Some(n) if n <= MAX_NODES => {}
            _ => return Err(PhysicsError::TooManyNodes { nodes: self.columns as f64 * self.rows as f64, limit: MAX_NODES }),
        }
        positive(Quantity::Spacing, self.spacing)?;
        positive(Quantity::NodeMass, self.node_mass)?;
        positive(Quantity::SpringStiffness, self.spring_stiffness)?;
        non_negative(Quantity::AuxStiffness, self.aux_stiffness)
    }
}

/// The paper's sheet of `columns` x `rows` nodes (spacing 0.1 m, 0.01 kg,
/// 50 N/m, shear springs; auxiliary springs of 0.05 N/m in 3D), for tests.
#[cfg(test)]
pub(crate) fn paper(columns: usize, rows: usize, dim: usize, fixed_nodes: FixedNodes) -> Grid {
    Grid {
        columns,
        rows,
        dim,
        spacing: 0.1,
        node_mass: 0.01,
        spring_stiffness: 50.0,
        shear_springs: true,
        bending_springs: false,
        aux_stiffness: if dim == 3 { 0.05 } else { 0.0 },
        fixed_nodes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::paper as grid;

    #[test]
    fn paper_grid_counts() {
        let s = grid(10, 10, 2, FixedNodes::TopRow).build().unwrap();
        assert_eq!(s.n_free, 90);
        assert_eq!(s.n_dofs(), 180);
        // structural 9*10*2 + shear 2*81, minus the 9 top-row springs between fixed nodes
        assert_eq!(s.springs.len(), 180 + 162 - 9);
        let c = grid(10, 10, 2, FixedNodes::TopCorners).build().unwrap();
        assert_eq!(c.n_free, 98);
        let s3 = grid(7, 7, 3, FixedNodes::TopRow).build().unwrap();
        assert_eq!(s3.n_free, 42);
        assert_eq!(s3.springs.len(), 6 * 7 * 2 + 2 * 36 - 6 + 42);
    }

    #[test]
    fn rest_lengths_are_rest_distances() {
        let s = grid(7, 7, 3, FixedNodes::TopRow).build().unwrap();
        for sp in &s.springs {
            let l: f64 = (0..3).map(|i| (s.rest[sp.b * 3 + i] - s.rest[sp.a * 3 + i]).powi(2)).sum::<f64>().sqrt();
            assert!((l - sp.rest).abs() < 1e-15);
        }
    }

    #[test]
    fn refuses_bad_parameters_by_quantity() {
        let mut g = grid(10, 10, 2, FixedNodes::TopRow);
        g.spacing = -1.0;
        assert!(matches!(g.build(), Err(PhysicsError::Invalid { quantity: Quantity::Spacing, .. })));
        let mut g = grid(10, 10, 2, FixedNodes::TopRow);
        g.dim = 4;
        assert!(matches!(g.build(), Err(PhysicsError::Invalid { quantity: Quantity::Dimension, .. })));
        assert_eq!(grid(10, 1, 2, FixedNodes::TopRow).build().unwrap_err(), PhysicsError::NoFreeNode);
        assert!(grid(10, 1, 2, FixedNodes::TopCorners).build().is_ok());
    }
}

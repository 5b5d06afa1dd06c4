//! The grid builder: a rectangular sheet of nodes joined by structural,
//! shear and bending springs, hung from its top row or its top corners,
//! with optional auxiliary springs out of its plane (`docs/method.md`,
//! section 5). It turns grid parameters into a [`Scene`]; the solver only
//! ever sees the scene.

pub use crate::options::FixedNodes;
use crate::physics::error::{non_negative, positive, Expected, HolderProblem, PhysicsError, Quantity};
use crate::physics::setup::scene::{Holder, Scene, Spring, MAX_HOLDERS};

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
    /// Holders the held nodes are split among (1 to [`MAX_HOLDERS`]).
    pub holders: usize,
    /// With [`FixedNodes::Custom`]: per node (row-major) its holder, 1 to
    /// `holders`, or 0 for a free node.
    pub holder_of_node: Vec<usize>,
}

impl Grid {
    /// Builds the scene, refusing parameters that cannot make one.
    pub fn build(&self) -> Result<Scene, PhysicsError> {
        self.validate()?;
        let (cols, rows, d, h) = (self.columns, self.rows, self.dim, self.spacing);
        let n_nodes = cols * rows;
        let holder_of: Vec<Option<usize>> = (0..n_nodes).map(|node| self.holder_of(node)).collect();
        let is_fixed = |node: usize| holder_of[node].is_some();
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
            let (n0, n1) = (r0 * cols + c0, r1 * cols + c1);
            let (a, b) = (slot_of_node[n0], slot_of_node[n1]);
            if a >= n_free && b >= n_free && holder_of[n0] == holder_of[n1] {
                return; // both ends on one holder: it never moves, never acts
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
        let mut holders: Vec<Holder> = (0..self.holders).map(|_| Holder { slots: Vec::new(), pivot: [0.0; 3] }).collect();
        for (node, h) in holder_of.iter().enumerate() {
            if let Some(h) = *h {
                let slot = slot_of_node[node];
                if holders[h].slots.is_empty() {
                    holders[h].pivot = std::array::from_fn(|i| if i < d { rest[slot * d + i] } else { 0.0 });
                }
                holders[h].slots.push(slot);
            }
        }
        let scene = Scene { dim: d, n_nodes, n_free, slot_of_node, rest, dof_mass: vec![self.node_mass; n_free * d], springs, holders };
        scene.check()?;
        Ok(scene)
    }

    /// The index of node (`row`, `col`), if it is in the grid.
    pub fn node(&self, row: usize, col: usize) -> Option<usize> {
        (row < self.rows && col < self.columns).then(|| row * self.columns + col)
    }

    /// Node `node` is held in place.
    pub fn is_held(&self, node: usize) -> bool {
        self.holder_of(node).is_some()
    }

    /// The holder of node `node` (counted from 0), if it is held: the
    /// custom pattern's, or with the top row or corners the held columns
    /// split among the holders left to right (holder k takes the held
    /// columns j, counted from the left among the m held ones, with
    /// floor(j holders / m) = k).
    pub fn holder_of(&self, node: usize) -> Option<usize> {
        let (row, col) = (node / self.columns, node % self.columns);
        let n = self.holders.max(1);
        match self.fixed_nodes {
            FixedNodes::Custom => self.holder_of_node.get(node).copied().filter(|&k| k > 0).map(|k| k - 1),
            FixedNodes::TopRow => (row == 0).then(|| col * n / self.columns),
            FixedNodes::TopCorners => {
                let m = if self.columns > 1 { 2 } else { 1 };
                (row == 0 && (col == 0 || col == self.columns - 1)).then(|| if col == 0 { 0 } else { (m - 1) * n / m })
            }
        }
    }

    /// Refuses a split of the held nodes that leaves a holder without a
    /// node, names a holder that does not exist, or holds nothing.
    fn validate_holders(&self) -> Result<(), PhysicsError> {
        let n = self.holders;
        if !(1..=MAX_HOLDERS).contains(&n) {
            return Err(PhysicsError::Invalid { quantity: Quantity::Holders, value: n as f64, expected: Expected::Within(MAX_HOLDERS as f64) });
        }
        let nodes = self.columns * self.rows;
        match self.fixed_nodes {
            FixedNodes::Custom => {
                if self.holder_of_node.len() != nodes {
                    return Err(PhysicsError::Holders(HolderProblem::PatternLength { len: self.holder_of_node.len(), expected: nodes }));
                }
                if let Some(node) = self.holder_of_node.iter().position(|&k| k > n) {
                    let (row, col, id) = (node / self.columns, node % self.columns, self.holder_of_node[node]);
                    return Err(PhysicsError::Holders(HolderProblem::IdTooLarge { row, col, id, holders: n }));
                }
                if self.holder_of_node.iter().all(|&k| k == 0) {
                    return Err(PhysicsError::Holders(HolderProblem::NoHeldNode));
                }
                if let Some(holder) = (1..=n).find(|k| !self.holder_of_node.contains(k)) {
                    return Err(PhysicsError::Holders(HolderProblem::NoNode { holder }));
                }
            }
            FixedNodes::TopRow | FixedNodes::TopCorners => {
                let columns = if self.fixed_nodes == FixedNodes::TopRow || self.columns == 1 { self.columns } else { 2 };
                if n > columns {
                    return Err(PhysicsError::Holders(HolderProblem::TooFewColumns { holders: n, columns }));
                }
            }
        }
        Ok(())
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
        self.validate_holders()?;
        positive(Quantity::Spacing, self.spacing)?;
        positive(Quantity::NodeMass, self.node_mass)?;
        positive(Quantity::SpringStiffness, self.spring_stiffness)?;
        non_negative(Quantity::AuxStiffness, self.aux_stiffness)
    }
}

/// The paper's sheet of `columns` x `rows` nodes (spacing 0.1 m, 0.01 kg,
/// 50 N/m, shear springs; auxiliary springs of 0.05 N/m in 3D) on one
/// holder, for tests and benchmarks.
pub fn paper(columns: usize, rows: usize, dim: usize, fixed_nodes: FixedNodes) -> Grid {
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
        holders: 1,
        holder_of_node: Vec::new(),
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

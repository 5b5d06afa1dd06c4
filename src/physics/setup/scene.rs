//! A mass-spring scene as the solver sees it: slots, springs and free
//! degrees of freedom, whatever built it (`docs/method.md`, section 2).
//!
//! Positions live in one array of *slots* of `dim` coordinates each: first
//! the free nodes (so the free DOFs are the contiguous prefix `0..n_dofs`),
//! then every slot that is held in place (fixed nodes, anchor points of
//! auxiliary springs). A spring joins two slots; an end at or past `n_free`
//! does not move. The outputs list `n_nodes` nodes in the order of
//! `slot_of_node`. [`crate::physics::setup::grid`] builds the canonical scenes; nothing else
//! in the core knows there is a grid.

use crate::physics::error::{Expected, PhysicsError, Quantity};

/// Most holders a scene may have.
pub const MAX_HOLDERS: usize = 4;

/// A holder: the held slots it moves together, and its pivot.
///
/// The sheet is integrated in the frame of the first holder (holder 1 of
/// the model description), which carries every held slot it does not list
/// too (the auxiliary springs' points). Every other holder places its slots
/// in that frame as it moves (`docs/method.md`, section 9).
#[derive(Clone, Debug, PartialEq)]
pub struct Holder {
    /// Its held slots, in node order (row-major).
    pub slots: Vec<usize>,
    /// The rest position of its first node, about which it turns (z 0 in 2D) [m].
    pub pivot: [f64; 3],
}

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
    /// Space dimension d (2 or 3).
    pub dim: usize,
    /// Nodes reported in the outputs.
    pub n_nodes: usize,
    /// Free nodes; the free DOFs are `n_free * dim`.
    pub n_free: usize,
    /// Slot of every reported node, in output order.
    pub slot_of_node: Vec<usize>,
    /// Rest coordinates of every slot (`dim` per slot).
    pub rest: Vec<f64>,
    /// Mass of each free DOF (the diagonal of M).
    pub dof_mass: Vec<f64>,
    pub springs: Vec<Spring>,
    /// The holders, the first one's frame the frame of the equations; may
    /// be empty (scenes not built from a grid), which is one holder of
    /// every held slot with its pivot at node 0.
    pub holders: Vec<Holder>,
}

impl Scene {
    /// Number of free degrees of freedom.
    pub fn n_dofs(&self) -> usize {
        self.n_free * self.dim
    }

    /// Refuses a scene the solver cannot run: a dimension other than 2 or
    /// 3, no free node, or springs and nodes that point outside the slots.
    pub fn check(&self) -> Result<(), PhysicsError> {
        if self.dim != 2 && self.dim != 3 {
            return Err(PhysicsError::Invalid { quantity: Quantity::Dimension, value: self.dim as f64, expected: Expected::TwoOrThree });
        }
        if self.n_dofs() == 0 {
            return Err(PhysicsError::NoFreeNode);
        }
        let slots = self.rest.len() / self.dim;
        assert!(
            self.rest.len() == slots * self.dim
                && self.dof_mass.len() == self.n_dofs()
                && self.slot_of_node.len() == self.n_nodes
                && self.slot_of_node.iter().all(|&s| s < slots)
                && self.springs.iter().all(|s| s.a < slots && s.b < slots),
            "inconsistent scene"
        );
        Ok(())
    }

    /// The pivot X0 of the first holder, about which it turns and its
    /// torque is taken (`docs/method.md`, section 8): the rest position of
    /// its first node (node 0 for the grid's top row and top corners; z 0 in 2D).
    pub fn pivot(&self) -> [f64; 3] {
        if let Some(h) = self.holders.first() {
            return h.pivot;
        }
        let (d, slot) = (self.dim, self.slot_of_node[0]);
        std::array::from_fn(|i| if i < d { self.rest[slot * d + i] } else { 0.0 })
    }

    /// Holders that move on their own: every holder but the first.
    pub fn moving_holders(&self) -> &[Holder] {
        self.holders.get(1..).unwrap_or(&[])
    }

    /// Total mass of the free nodes [kg].
    pub fn free_mass(&self) -> f64 {
        self.dof_mass.iter().step_by(self.dim).sum()
    }

    /// Largest distance a node can travel before the springs stop it: the
    /// diagonal of the rest positions' bounding box plus the longest spring.
    pub fn reach(&self) -> f64 {
        let d = self.dim;
        let diagonal = (0..d)
            .map(|i| {
                let (lo, hi) = self.rest.iter().skip(i).step_by(d).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
                (hi - lo).powi(2)
            })
            .sum::<f64>()
            .sqrt();
        diagonal + self.springs.iter().fold(0.0f64, |m, s| m.max(s.rest))
    }

    /// Largest coordinate of a rest position, the length scale of the scene [m].
    pub fn length_scale(&self) -> f64 {
        self.rest.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// Stiffest spring over the lightest node [1/s^2], for messages.
    pub fn stiffness_per_mass(&self) -> f64 {
        let k = self.springs.iter().fold(0.0f64, |m, s| m.max(s.k));
        let m = self.dof_mass.iter().fold(f64::INFINITY, |m, &x| m.min(x));
        k / m
    }
}

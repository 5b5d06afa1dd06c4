//! What each mode of a basis looks like, as two numbers a user can choose
//! mode weights by: how much of it moves out of the sheet's rest plane, and
//! whether it is symmetric or antisymmetric about the sheet's vertical
//! mid-line.
//!
//! For mode i with shape phi (one vector phi_k per free node k, masses m_k):
//!
//! - out of plane: o_i = sum_k m_k phi_kz^2 / sum_k m_k |phi_k|^2, in [0, 1]
//!   (the rest plane is z = 0; 0 in 2D);
//! - symmetry: s_i = sum_k sqrt(m_k m_k') phi_k . R phi_k' / sum_k m_k |phi_k|^2,
//!   in [-1, 1], where k' is the free node resting at the mirror image of
//!   k's rest position about the mid-line x = (x_min + x_max) / 2 of the
//!   nodes (x -> x_min + x_max - x) and R flips the x component: the
//!   mass-weighted correlation of the mode with its mirror image. +1 is a
//!   symmetric mode, -1 an antisymmetric one. A node whose mirror image is
//!   held (or is no node) adds 0 to the sum. On a scene that is mirror
//!   symmetric every mode of a simple frequency is +1 or -1; a scene that
//!   is not (held nodes, masses or, where the basis depends on the loads, a
//!   point load off the middle) mixes the two, and s_i says by how much.
//!   The modes of a repeated frequency are any basis of their eigenspace,
//!   so their s_i can be anything in between even on a symmetric scene.
//!
//! The weighting sqrt(m_k m_k') keeps |s_i| <= 1 by Cauchy-Schwarz whatever
//! the masses.

use std::collections::HashMap;

use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;

/// Rest positions closer than this fraction of the scene's length scale
/// are one position (a grid's mirror images differ from its nodes by
/// round-off, some 1e-16 of it).
const SAME_POSITION: f64 = 1e-9;

/// The class of every mode of a basis, in the basis's order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModeClasses {
    /// Share of the mass-weighted amplitude out of the rest plane, in [0, 1].
    pub out_of_plane: Vec<f64>,
    /// Mass-weighted correlation with the mirror image, in [-1, 1].
    pub symmetry: Vec<f64>,
}

/// A symmetry at least this far from 0 names a mode symmetric or antisymmetric; closer, mixed.
pub const SYMMETRY_CLASS: f64 = 0.9;

impl ModeClasses {
    /// A name for mode `i`: "out-of-plane" where more than half of its
    /// mass-weighted amplitude leaves the plane, "in-plane" otherwise; then
    /// "symmetric", "antisymmetric" or "mixed" by [`SYMMETRY_CLASS`].
    pub fn label(&self, i: usize) -> String {
        let plane = if self.out_of_plane[i] > 0.5 { "out-of-plane" } else { "in-plane" };
        let s = self.symmetry[i];
        let mirror = if s >= SYMMETRY_CLASS {
            "symmetric"
        } else if s <= -SYMMETRY_CLASS {
            "antisymmetric"
        } else {
            "mixed"
        };
        format!("{plane} {mirror}")
    }
}

/// The classes of the `basis.r` modes of `basis` (shapes over the free DOFs of `scene`).
pub fn classify(scene: &Scene, basis: &ModalBasis) -> ModeClasses {
    let (d, r) = (scene.dim, basis.r);
    let mirror = mirror_nodes(scene);
    let mut out = ModeClasses { out_of_plane: Vec::with_capacity(r), symmetry: Vec::with_capacity(r) };
    for i in 0..r {
        let phi = |dof: usize| basis.phi[dof * r + i];
        let (mut norm, mut plane, mut mirrored) = (0.0, 0.0, 0.0);
        for k in 0..scene.n_free {
            for a in 0..d {
                let (dof, m) = (k * d + a, scene.dof_mass[k * d + a]);
                norm += m * phi(dof).powi(2);
                if a == 2 {
                    plane += m * phi(dof).powi(2);
                }
                if let Some(j) = mirror[k] {
                    let flip = if a == 0 { -1.0 } else { 1.0 };
                    mirrored += (m * scene.dof_mass[j * d + a]).sqrt() * phi(dof) * flip * phi(j * d + a);
                }
            }
        }
        let share = |x: f64| if norm > 0.0 { x / norm } else { 0.0 };
        out.out_of_plane.push(share(plane));
        out.symmetry.push(share(mirrored));
    }
    out
}

/// Every mode of `basis` laid out on the grid as the node outputs are:
/// `[r][n_nodes][dim]`, mode after mode, nodes in the scene's order (row by row), the
/// shape phi_k of each free node and 0 on a held one. The modes are
/// mass-normalized (sum_k m_k |phi_k|^2 = 1), so a drawing scales them.
/// O(n r) once.
pub fn grid_shapes(scene: &Scene, basis: &ModalBasis) -> Vec<f64> {
    let (d, r, n) = (scene.dim, basis.r, scene.n_nodes);
    let mut out = vec![0.0; r * n * d];
    for i in 0..r {
        for (node, &slot) in scene.slot_of_node.iter().enumerate() {
            if slot < scene.n_free {
                for a in 0..d {
                    out[(i * n + node) * d + a] = basis.phi[(slot * d + a) * r + i];
                }
            }
        }
    }
    out
}

/// For each free node, the free node resting at its mirror image about the
/// nodes' mid-line x = (x_min + x_max) / 2, if there is one.
fn mirror_nodes(scene: &Scene) -> Vec<Option<usize>> {
    let d = scene.dim;
    let at = |slot: usize| -> [f64; 3] { std::array::from_fn(|a| if a < d { scene.rest[slot * d + a] } else { 0.0 }) };
    let (lo, hi) = scene.slot_of_node.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &s| (lo.min(at(s)[0]), hi.max(at(s)[0])));
    let tol = (SAME_POSITION * scene.length_scale()).max(f64::MIN_POSITIVE);
    let cell = |x: &[f64; 3]| -> [i64; 3] { std::array::from_fn(|a| (x[a] / tol).floor() as i64) };
    let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for k in 0..scene.n_free {
        cells.entry(cell(&at(k))).or_default().push(k);
    }
    (0..scene.n_free)
        .map(|k| {
            let mut image = at(k);
            image[0] = lo + hi - image[0];
            let c = cell(&image);
            // The image may fall in a cell next to the one its node is in.
            let near = (0..27).flat_map(|n| cells.get(&[c[0] + n % 3 - 1, c[1] + n / 3 % 3 - 1, c[2] + n / 9 - 1]).into_iter().flatten());
            near.copied().find(|&j| (0..3).all(|a| (at(j)[a] - image[a]).abs() <= tol))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::setup::grid::{paper, FixedNodes};

    /// A basis whose columns are the given displacement vectors of the free DOFs.
    fn basis_of(n: usize, vectors: &[Vec<f64>]) -> ModalBasis {
        let r = vectors.len();
        let phi = (0..n).flat_map(|k| vectors.iter().map(move |v| v[k])).collect();
        ModalBasis { n, r, lambda: vec![1.0; r], phi }
    }

    /// A displacement with no pattern: a different value at every DOF.
    fn rough(n: usize) -> Vec<f64> {
        (0..n).map(|k| (1.0 + k as f64).sin() + 0.3).collect()
    }

    #[test]
    fn out_of_plane_is_the_z_share() {
        let s = paper(5, 4, 3, FixedNodes::TopRow).build().unwrap();
        let n = s.n_dofs();
        let v = rough(n);
        let only = |axes: &[usize]| -> Vec<f64> { (0..n).map(|k| if axes.contains(&(k % 3)) { v[k] } else { 0.0 }).collect() };
        let c = classify(&s, &basis_of(n, &[only(&[2]), only(&[0, 1]), only(&[0, 1, 2])]));
        assert_eq!(c.out_of_plane[..2], [1.0, 0.0]);
        let z: f64 = (0..n).filter(|k| k % 3 == 2).map(|k| v[k] * v[k]).sum();
        let all: f64 = v.iter().map(|x| x * x).sum();
        assert!((c.out_of_plane[2] - z / all).abs() < 1e-15);
        let flat = paper(5, 4, 2, FixedNodes::TopRow).build().unwrap();
        assert_eq!(classify(&flat, &basis_of(flat.n_dofs(), &[rough(flat.n_dofs())])).out_of_plane, [0.0]);
    }

    /// u + P u reads +1, u - P u reads -1, u itself in between, on grids
    /// of odd and even width (the middle column is its own mirror image).
    #[test]
    fn mirrored_pairs_read_plus_and_minus_one() {
        for (cols, dim, fixed) in [(5, 2, FixedNodes::TopRow), (6, 3, FixedNodes::TopCorners), (4, 3, FixedNodes::TopRow)] {
            let g = paper(cols, 3, dim, fixed);
            let s = g.build().unwrap();
            let n = s.n_dofs();
            let u = rough(n);
            // P u: node (row, col) takes the mirrored displacement of (row, cols - 1 - col).
            let slot = |node: usize| s.slot_of_node[node];
            let mut pu = vec![0.0; n];
            for node in 0..cols * 3 {
                let (row, col) = (node / cols, node % cols);
                let image = row * cols + cols - 1 - col;
                if slot(node) < s.n_free && slot(image) < s.n_free {
                    for a in 0..dim {
                        pu[slot(node) * dim + a] = if a == 0 { -1.0 } else { 1.0 } * u[slot(image) * dim + a];
                    }
                }
            }
            let plus: Vec<f64> = (0..n).map(|k| u[k] + pu[k]).collect();
            let minus: Vec<f64> = (0..n).map(|k| u[k] - pu[k]).collect();
            let c = classify(&s, &basis_of(n, &[plus, minus, u]));
            let what = format!("{cols} columns, {dim}D");
            assert!((c.symmetry[0] - 1.0).abs() < 1e-14, "{what}: {:?}", c.symmetry);
            assert!((c.symmetry[1] + 1.0).abs() < 1e-14, "{what}: {:?}", c.symmetry);
            assert!(c.symmetry[2].abs() < 0.9, "{what}: {:?}", c.symmetry);
        }
    }

    /// A node whose mirror image is held adds nothing: a mode on that node alone reads 0.
    #[test]
    fn a_held_mirror_image_adds_nothing() {
        let mut s = paper(3, 3, 2, FixedNodes::TopRow).build().unwrap();
        // Hold the last free node (row 2, column 2) by making it a slot past the free ones.
        s.n_free -= 1;
        s.dof_mass.truncate(s.n_free * 2);
        let n = s.n_dofs();
        let mut v = vec![0.0; n];
        let left = s.slot_of_node[6]; // row 2, column 0: its image is the held node
        v[left * 2] = 1.0;
        v[left * 2 + 1] = 1.0;
        assert_eq!(classify(&s, &basis_of(n, &[v])).symmetry, [0.0]);
    }
}

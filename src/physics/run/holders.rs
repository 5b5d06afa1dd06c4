//! Holders that move on their own (`docs/method.md`, section 9).
//!
//! The sheet is integrated in the frame of its first holder: a slot at x
//! in that frame is at X = P1 + a1 + R1 (x - P1) in the ground's
//! ([`crate::physics::run::frame`]). Every other holder k holds its own
//! slots rigidly: slot i at its rest position X_i is at
//!
//! ```text
//!     G_i = P_k + a_k + R_k (X_i - P_k)          (ground)
//!     x_i = P1 + R1^T (G_i - P1 - a1)             (the first holder's frame)
//! ```
//!
//! with P_k its pivot (the rest position of its first node), a_k its
//! displacement and R_k = R(theta_k) its orientation. The equations of the
//! free nodes see those slots only through the springs that end on them,
//! so a holder's motion needs no other term: [`place`] writes x_i where the
//! force evaluations read the held slots. The force the sheet exerts on
//! holder k is the sum of the forces of the springs that end on its slots
//! ([`reaction`]), the generalized force of its constraint modes when they
//! are in the basis; its torque is taken about its current pivot P_k + a_k.

use crate::physics::run::forces::pull;
use crate::physics::run::frame::{apply, apply_transposed, cross, rotation};
use crate::physics::run::state::Motion;
use crate::physics::setup::scene::{Holder, Scene};

/// A rigid placement: displacement a and orientation R (row-major).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub anchor: [f64; 3],
    pub rotation: [f64; 9],
    /// R is the identity (the rotation vector is 0).
    pub still: bool,
}

impl Placement {
    /// The placement of a holder whose rotation vector is `theta`.
    pub fn new(anchor: [f64; 3], theta: &[f64; 3]) -> Self {
        Placement { anchor, rotation: rotation(theta), still: *theta == [0.0; 3] }
    }

    /// Where `motion` puts its holder `tau` after its state's time: a + c tau and R(theta) exp(tau [w]x).
    pub fn after(motion: &Motion, tau: f64) -> Self {
        let anchor = std::array::from_fn(|i| motion.anchor[i] + motion.anchor_rate[i] * tau);
        if tau == 0.0 || motion.spin == [0.0; 3] {
            return Placement::new(anchor, &motion.rotation);
        }
        let r = crate::physics::run::frame::compose(&rotation(&motion.rotation), &rotation(&motion.spin.map(|w| w * tau)));
        Placement { anchor, rotation: r, still: false }
    }
}

/// Writes the positions in the first holder's frame (placed at `first`)
/// of the slots of every other holder (placed at `others`, in order) into
/// the slot positions `x`.
pub fn place(scene: &Scene, first: &Placement, others: &[Placement], x: &mut [f64]) {
    let (d, p1) = (scene.dim, scene.pivot());
    for (holder, at) in scene.moving_holders().iter().zip(others) {
        let shift: [f64; 3] = std::array::from_fn(|i| at.anchor[i] - first.anchor[i]);
        for &slot in &holder.slots {
            let rest = &scene.rest[slot * d..(slot + 1) * d];
            let xi = &mut x[slot * d..(slot + 1) * d];
            if at.still && first.still {
                for i in 0..d {
                    xi[i] = rest[i] + shift[i];
                }
                continue;
            }
            let rho: [f64; 3] = std::array::from_fn(|i| if i < d { rest[i] - holder.pivot[i] } else { 0.0 });
            let turned = apply(&at.rotation, &rho);
            let g: [f64; 3] = std::array::from_fn(|i| holder.pivot[i] - p1[i] + shift[i] + turned[i]);
            let local = apply_transposed(&first.rotation, &g);
            for i in 0..d {
                xi[i] = p1[i] + local[i];
            }
        }
    }
}

/// The ground velocity of a slot of `holder` at rest position `rest`:
/// c + R (w x (X - P)), `motion` giving c, w (in the holder's axes) and R.
pub fn slot_velocity(holder: &Holder, motion: &Motion, at: &Placement, rest: &[f64]) -> [f64; 3] {
    let rho: [f64; 3] = std::array::from_fn(|i| if i < rest.len() { rest[i] - holder.pivot[i] } else { 0.0 });
    let spun = apply(&at.rotation, &cross(&motion.spin, &rho));
    std::array::from_fn(|i| motion.anchor_rate[i] + spun[i])
}

/// The springs that end on a holder's slots: (spring, the held end is its `a`).
pub fn spring_ends(scene: &Scene, holder: &Holder) -> Vec<(usize, bool)> {
    let mut mine = vec![false; scene.rest.len() / scene.dim];
    for &s in &holder.slots {
        mine[s] = true;
    }
    scene
        .springs
        .iter()
        .enumerate()
        .filter_map(|(k, s)| match (mine[s.a], mine[s.b]) {
            (true, false) => Some((k, true)),
            (false, true) => Some((k, false)),
            _ => None,
        })
        .collect()
}

/// The force and the torque about `pivot` (both in the first holder's
/// frame) that the springs `ends` exert on their held ends, the slot
/// positions read through `position`.
pub fn reaction(scene: &Scene, ends: &[(usize, bool)], pivot: &[f64; 3], mut position: impl FnMut(usize) -> [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let (mut force, mut torque) = ([0.0; 3], [0.0; 3]);
    for &(k, held_is_a) in ends {
        let s = &scene.springs[k];
        let (xa, xb) = (position(s.a), position(s.b));
        let on_a = pull::<3>(&std::array::from_fn(|i| xb[i] - xa[i]), s.k, s.rest);
        let (f, at): ([f64; 3], [f64; 3]) = if held_is_a { (on_a, xa) } else { (on_a.map(|c| -c), xb) };
        let arm: [f64; 3] = std::array::from_fn(|i| at[i] - pivot[i]);
        let t = cross(&arm, &f);
        for i in 0..3 {
            force[i] += f[i];
            torque[i] += t[i];
        }
    }
    (force, torque)
}

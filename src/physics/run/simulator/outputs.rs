//! What a host reads of a run: node positions and velocities and those of
//! the load node, in the ground's frame (the sheet is integrated in its
//! holder's, `docs/method.md`, section 8); the force and torque the sheet
//! exerts on its holder; the energies and the force residual ([`Reads`]);
//! and the products of the set-up: the kept modes and their classes, its
//! costly data, the cubature ([`SetUp`]). The costly ones are computed
//! when first asked for after a step and kept until the state changes
//! (the run's `fresh`).

use super::{to_node_order, Reads, Run, SetUp, Steps};
use super::{ReductionStatus, Switch};
use crate::physics::error::PhysicsError;
use crate::physics::run::frame::{apply, apply_transposed, cross, dot, ground_velocity, place, rotation};
use crate::physics::run::holders::{self, Placement};
use crate::physics::run::integrator::Scheme;
use crate::physics::run::space::Readout;
use crate::physics::run::state::Loads;
use crate::physics::setup::mode_classes::{self, ModeClasses};
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::scene::MAX_HOLDERS;
use crate::physics::setup::setup_data::SetupData;

impl<S: Readout, I: Scheme> Run<S, I> {
    /// Node positions of the state (forces evaluated there) into `outputs.positions`, in the holder's frame.
    fn node_positions_now(&mut self) {
        self.forces_current();
        let scene = self.space.scene();
        let x = self.space.positions(&self.state.y, &mut self.work);
        match scene.dim {
            2 => to_node_order::<2>(&scene.slot_of_node, usize::MAX, x, &mut self.outputs.positions),
            _ => to_node_order::<3>(&scene.slot_of_node, usize::MAX, x, &mut self.outputs.positions),
        }
    }

    /// Node velocities of the state into `outputs.velocities` (held nodes at 0), relative to the holder.
    fn node_velocities_now(&mut self) {
        let scene = self.space.scene();
        self.space.dof_velocities(&self.state.v, &mut self.outputs.dof_velocities);
        match scene.dim {
            2 => to_node_order::<2>(&scene.slot_of_node, scene.n_free, &self.outputs.dof_velocities, &mut self.outputs.velocities),
            _ => to_node_order::<3>(&scene.slot_of_node, scene.n_free, &self.outputs.dof_velocities, &mut self.outputs.velocities),
        }
    }

    /// Position of one node of the state (whose forces were evaluated last), without the others; z is 0 in 2D.
    fn node_position_now(&mut self, node: usize) -> [f64; 3] {
        self.space.slot_position(&self.state.y, self.space.scene().slot_of_node[node], &mut self.work)
    }

    /// Velocity of one node of the state (0 for a held node); z is 0 in 2D.
    fn node_velocity_now(&self, node: usize) -> [f64; 3] {
        let scene = self.space.scene();
        let slot = scene.slot_of_node[node];
        if slot < scene.n_free {
            self.space.slot_velocity(&self.state.v, slot)
        } else {
            [0.0; 3]
        }
    }

    /// Each holder's force and torque into the outputs (see [`Reads::holder_force`]):
    /// for every holder k but the first, the springs' pull on its slots in
    /// the first holder's frame about its pivot there, turned into the
    /// ground's; the first holder's, the momentum balance less theirs, its
    /// torque less their moments about its own pivot as well.
    fn holder_reactions(&mut self) {
        if self.fresh.holders {
            return;
        }
        let (mut forces, mut torques) = ([[0.0; 3]; MAX_HOLDERS], [[0.0; 3]; MAX_HOLDERS]);
        let (mut first_force, mut first_torque) = (self.anchor_force(), self.anchor_torque());
        let (moving, d) = (self.space.scene().moving_holders().len(), self.space.scene().dim);
        if moving > 0 {
            self.forces_current();
            let r1 = rotation(&self.state.rotation);
            let p1: [f64; 3] = std::array::from_fn(|i| self.pivot[i] + self.state.anchor[i]);
            for j in 0..moving {
                let pivot = self.space.scene().moving_holders()[j].pivot;
                let g: [f64; 3] = std::array::from_fn(|i| pivot[i] + self.state.holders[j].anchor[i]);
                let local = apply_transposed(&r1, &std::array::from_fn(|i| g[i] - p1[i]));
                let pivot_frame: [f64; 3] = std::array::from_fn(|i| self.pivot[i] + local[i]);
                let (space, work, y) = (&self.space, &mut self.work, &self.state.y);
                let (f, t) = holders::reaction(space.scene(), &self.holder_ends[j], &pivot_frame, |slot| space.slot_position(y, slot, work));
                let (f, t) = (apply(&r1, &f), apply(&r1, &t));
                let arm = cross(&std::array::from_fn(|i| g[i] - p1[i]), &f);
                for i in 0..3 {
                    first_force[i] -= f[i];
                    first_torque[i] -= t[i] + arm[i];
                }
                forces[j + 1] = planar_vector(f, d, false);
                torques[j + 1] = planar_vector(t, d, true);
            }
        }
        forces[0] = planar_vector(first_force, d, false);
        torques[0] = planar_vector(first_torque, d, true);
        self.outputs.holder_forces = forces;
        self.outputs.holder_torques = torques;
        self.fresh.holders = true;
    }

    /// Elastic energy of every spring at the state [J].
    fn elastic_energy_now(&mut self) -> f64 {
        self.forces_current();
        self.space.elastic_energy(&self.state.y, &mut self.work)
    }

    /// Elastic energy of every spring plus gravity potential at the state [J].
    fn potential_energy_now(&mut self) -> f64 {
        self.forces_current();
        self.space.elastic_energy(&self.state.y, &mut self.work) + self.space.gravity_potential(&self.state.y, &self.work)
    }

    /// The force the space cannot represent at the state, relative to the
    /// load, with gravity and the point load as given (see [`Readout::force_residual`]).
    fn force_residual_now(&mut self, gravity: &[f64; 3], point: &[f64; 3]) -> f64 {
        self.forces_current();
        self.space.force_residual(gravity, point, &self.state.y, &mut self.work)
    }
}

impl<S: Readout, I: Scheme> Reads for Run<S, I> {
    fn positions(&mut self) -> &[f64] {
        if !self.fresh.positions {
            self.node_positions_now();
            if self.turned() {
                self.outputs.frame_positions.copy_from_slice(&self.outputs.positions);
                let (r, d, a) = (rotation(&self.state.rotation), self.scene().dim, self.state.anchor);
                for x in self.outputs.positions.chunks_exact_mut(d) {
                    let p = place(&self.pivot, &a, &r, x);
                    x.copy_from_slice(&p[..d]);
                }
            } else {
                shift(&mut self.outputs.positions, &self.state.anchor, self.space.scene().dim);
            }
            // The nodes of the other holders where they put them, G = P + a + R (X - P).
            let (scene, d) = (self.space.scene(), self.space.scene().dim);
            for &(j, node) in &self.holder_nodes {
                let (h, m, slot) = (&scene.moving_holders()[j], &self.state.holders[j], scene.slot_of_node[node]);
                let g = place(&h.pivot, &m.anchor, &rotation(&m.rotation), &scene.rest[slot * d..(slot + 1) * d]);
                self.outputs.positions[node * d..(node + 1) * d].copy_from_slice(&g[..d]);
            }
            self.fresh.positions = true;
        }
        &self.outputs.positions
    }

    fn velocities(&mut self) -> &[f64] {
        if !self.fresh.velocities {
            self.node_velocities_now();
            if self.turned() {
                self.positions();
                let (r, d) = (rotation(&self.state.rotation), self.scene().dim);
                let (c, w) = (self.state.anchor_rate, self.state.spin);
                for (v, x) in self.outputs.velocities.chunks_exact_mut(d).zip(self.outputs.frame_positions.chunks_exact(d)) {
                    let u = ground_velocity(&self.pivot, &c, &w, &r, v, x);
                    v.copy_from_slice(&u[..d]);
                }
            } else {
                shift(&mut self.outputs.velocities, &self.state.anchor_rate, self.space.scene().dim);
            }
            let (scene, d) = (self.space.scene(), self.space.scene().dim);
            for &(j, node) in &self.holder_nodes {
                let (h, m, slot) = (&scene.moving_holders()[j], &self.state.holders[j], scene.slot_of_node[node]);
                let v = holders::slot_velocity(h, m, &Placement::new(m.anchor, &m.rotation), &scene.rest[slot * d..(slot + 1) * d]);
                self.outputs.velocities[node * d..(node + 1) * d].copy_from_slice(&v[..d]);
            }
            self.fresh.velocities = true;
        }
        &self.outputs.velocities
    }

    fn load_node_position(&mut self) -> Option<[f64; 3]> {
        let (node, d) = (self.loads().load_node.filter(|&n| n < self.scene().n_nodes)?, self.scene().dim);
        if self.fresh.positions {
            return Some(std::array::from_fn(|i| if i < d { self.outputs.positions[node * d + i] } else { 0.0 }));
        }
        let x = self.node_position_now(node);
        if self.turned() {
            return Some(place(&self.pivot, &self.state.anchor, &rotation(&self.state.rotation), &x[..d]));
        }
        Some(std::array::from_fn(|i| if i < d { x[i] + self.state.anchor[i] } else { 0.0 }))
    }

    fn load_node_velocity(&mut self) -> Option<[f64; 3]> {
        let (node, d) = (self.loads().load_node.filter(|&n| n < self.scene().n_nodes)?, self.scene().dim);
        if self.fresh.velocities {
            return Some(std::array::from_fn(|i| if i < d { self.outputs.velocities[node * d + i] } else { 0.0 }));
        }
        let v = self.node_velocity_now(node);
        if self.turned() {
            let x = self.node_position_now(node);
            let (c, w) = (self.state.anchor_rate, self.state.spin);
            return Some(ground_velocity(&self.pivot, &c, &w, &rotation(&self.state.rotation), &v[..d], &x[..d]));
        }
        Some(std::array::from_fn(|i| if i < d { v[i] + self.state.anchor_rate[i] } else { 0.0 }))
    }

    fn anchor_force(&mut self) -> [f64; 3] {
        if !self.fresh.anchor {
            let driven = self.momentum_rate_now();
            let turned = self.turned();
            let felt = self.felt_loads();
            let (d, g, f) = (self.scene().dim, felt.gravity, point_load(self.loads(), &felt.point_load, self.scene()));
            let mut force: [f64; 3] = std::array::from_fn(|i| if i < d { self.free_mass * g[i] + f[i] - driven[i] } else { 0.0 });
            if turned {
                // In the holder's frame, less the Coriolis and centrifugal parts of dP/dt: 2 w x P + w x (w x S).
                let (w, p, s) = (self.state.spin, self.space.momentum(&self.state.v), self.space.first_moment(&self.state.y));
                let (coriolis, centrifugal) = (cross(&w, &p), cross(&w, &cross(&w, &s)));
                let local: [f64; 3] = std::array::from_fn(|i| force[i] - 2.0 * coriolis[i] - centrifugal[i]);
                force = apply(&rotation(&self.state.rotation), &local);
            }
            self.outputs.anchor_force = force;
            self.fresh.anchor = true;
        }
        self.outputs.anchor_force
    }

    fn anchor_torque(&mut self) -> [f64; 3] {
        if !self.fresh.torque {
            let driven = self.acceleration_moments_now();
            let turned = self.turned();
            let felt = self.felt_loads();
            let d = self.scene().dim;
            let g: [f64; 3] = std::array::from_fn(|i| if i < d { felt.gravity[i] } else { 0.0 });
            let mut t = cross(&driven.first, &g);
            let f = point_load(self.loads(), &felt.point_load, self.scene());
            if let Some(node) = self.loads().load_node.filter(|_| f != [0.0; 3]) {
                let x = self.node_position_now(node);
                let arm = cross(&std::array::from_fn(|i| x[i] - self.pivot[i]), &f);
                t = std::array::from_fn(|i| t[i] + arm[i]);
            }
            let inertial = driven.angular();
            t = std::array::from_fn(|i| t[i] - inertial[i]);
            if turned {
                let (w, motion) = (self.state.spin, self.space.moments(&self.state.y, &self.state.v));
                let n = &motion.flux;
                let (nw, jw) = (apply(n, &w), apply(&motion.second, &w));
                let gyro = cross(&w, &jw);
                let trace = n[0] + n[4] + n[8];
                t = std::array::from_fn(|i| t[i] - 2.0 * (w[i] * trace - nw[i]) + gyro[i]);
                t = apply(&rotation(&self.state.rotation), &t);
            }
            self.outputs.anchor_torque = std::array::from_fn(|i| if d == 3 || i == 2 { t[i] } else { 0.0 });
            self.fresh.torque = true;
        }
        self.outputs.anchor_torque
    }

    fn holder_force(&mut self, k: usize) -> [f64; 3] {
        self.holder_reactions();
        self.outputs.holder_forces.get(k).copied().unwrap_or_default()
    }

    fn holder_torque(&mut self, k: usize) -> [f64; 3] {
        self.holder_reactions();
        self.outputs.holder_torques.get(k).copied().unwrap_or_default()
    }

    fn kinetic_energy(&self) -> f64 {
        self.outputs.kinetic
    }

    fn potential_energy(&mut self) -> f64 {
        if !self.fresh.potential && self.turned() {
            // Elastic energy, and -g . sum m (X - X_rest) = -g . (m a + R S - S_rest), and -f_p . (X_p - X_p,rest).
            let (d, point) = (self.scene().dim, point_load(self.loads(), &self.loads().point_load, self.scene()));
            let elastic = self.elastic_energy_now();
            let s = apply(&rotation(&self.state.rotation), &self.space.first_moment(&self.state.y));
            let g: [f64; 3] = std::array::from_fn(|i| if i < d { self.loads().gravity[i] } else { 0.0 });
            let lowered: [f64; 3] = std::array::from_fn(|i| self.free_mass * self.state.anchor[i] + s[i] - self.rest_moment[i]);
            let mut potential = elastic - dot(&g, &lowered);
            if let (Some(node), true) = (self.loads().load_node, point != [0.0; 3]) {
                let x = self.load_node_position().expect("a point load acts on a node of the scene");
                let slot = self.scene().slot_of_node[node];
                potential -= (0..d).map(|i| point[i] * (x[i] - self.scene().rest[slot * d + i])).sum::<f64>();
            }
            self.outputs.potential = potential;
            self.fresh.potential = true;
        }
        if !self.fresh.potential {
            // The anchor's displacement a moves every free node: -(m g + f_p) . a more.
            let (d, point) = (self.scene().dim, point_load(self.loads(), &self.loads().point_load, self.scene()));
            let shifted: f64 = (0..d).map(|i| (self.free_mass * self.loads().gravity[i] + point[i]) * self.state.anchor[i]).sum();
            self.outputs.potential = self.potential_energy_now() - shifted;
            self.fresh.potential = true;
        }
        self.outputs.potential
    }

    fn force_residual(&mut self) -> f64 {
        if !self.fresh.residual {
            let felt = self.felt_loads();
            self.outputs.force_residual = self.force_residual_now(&felt.gravity, &felt.point_load);
            self.fresh.residual = true;
        }
        self.outputs.force_residual
    }

    fn modal_coordinates(&mut self) -> &[f64] {
        if !self.fresh.coordinates {
            self.space.modal_coordinates(&self.state.y, &mut self.outputs.modal_coordinates);
            self.fresh.coordinates = true;
        }
        &self.outputs.modal_coordinates
    }

    fn spring_force(&mut self, y: &[f64]) -> Result<Vec<f64>, PhysicsError> {
        let n = self.state.len();
        if y.len() != n {
            return Err(PhysicsError::SnapshotLength { len: y.len(), expected: n });
        }
        let mut out = vec![0.0; n];
        self.space.spring_force(y, &mut self.work, &mut out);
        self.evaluate_forces();
        Ok(out)
    }

    fn training_range(&self) -> f64 {
        self.space.layout().trained.map_or(0.0, |t| t.distance(&self.state.y))
    }
}

impl<S: Readout, I: Scheme> SetUp for Run<S, I> {
    fn mode_frequencies(&self) -> &[f64] {
        // The full space's reported modes are made when first asked for.
        let _ = self.space.modes_made();
        self.space.layout().frequencies
    }

    fn modes_made(&self) -> Result<(), &PhysicsError> {
        self.space.modes_made()
    }

    fn mode_shapes(&self) -> Option<&ModalBasis> {
        self.space.modes()
    }

    fn mode_classes(&self) -> ModeClasses {
        self.space.modes().map_or_else(ModeClasses::default, |b| mode_classes::classify(self.space.scene(), b))
    }

    fn mode_grid_shapes(&self) -> Vec<f64> {
        self.space.modes().map_or_else(Vec::new, |b| mode_classes::grid_shapes(self.space.scene(), b))
    }

    fn setup_data(&self) -> Option<SetupData> {
        self.space.setup_data()
    }

    fn cubature_springs(&self) -> usize {
        self.space.layout().springs
    }

    fn reduction_status(&self) -> ReductionStatus {
        let kept = self.space.layout().kept_modes;
        ReductionStatus {
            error_estimate: 0.0,
            reduced_fraction: if kept.is_some() { 1.0 } else { 0.0 },
            basis_size: kept.unwrap_or(self.space.scene().n_dofs()),
            chosen_size: kept.unwrap_or(self.space.scene().n_dofs()),
            reduces: kept.is_some(),
            why_full: None,
            error_directions: 0,
            switches: 0,
            last_switch: Switch::None,
        }
    }
}

/// A force (`torque` false: no z in 2D) or a torque (only z in 2D) as the scene's dimension `d` has it.
fn planar_vector(v: [f64; 3], d: usize, torque: bool) -> [f64; 3] {
    match (d, torque) {
        (3, _) => v,
        (_, false) => [v[0], v[1], 0.0],
        (_, true) => [0.0, 0.0, v[2]],
    }
}

/// Adds the anchor's displacement (or velocity) `a` to every node of
/// `values` (`d` per node).
fn shift(values: &mut [f64], a: &[f64; 3], d: usize) {
    if a[..d].iter().any(|&x| x != 0.0) {
        for node in values.chunks_exact_mut(d) {
            for (x, ai) in node.iter_mut().zip(a) {
                *x += ai;
            }
        }
    }
}

/// The point load `point` where it acts, on the free load node of `loads` (z 0 in 2D), else 0 [N].
fn point_load(loads: &Loads, point: &[f64; 3], scene: &Scene) -> [f64; 3] {
    loads.point_force_as(point, scene).map_or([0.0; 3], |(_, f)| std::array::from_fn(|i| f.get(i).copied().unwrap_or(0.0)))
}

//! What a host reads of the simulator: node positions and velocities and
//! those of the load node, in the ground's frame (the sheet is integrated
//! in its holder's, `docs/method.md`, section 8); the force and torque the
//! sheet exerts on its holder; the energies and the force residual; the
//! kept modes and their classes; and the diagnostics of the set-up (spring
//! force at given coordinates, its costly products, the trained range, the
//! cubature). The costly ones are computed when first asked for after a
//! step and kept until the state changes (the [`Simulator`]'s `fresh`).

use super::Simulator;
use crate::physics::error::PhysicsError;
use crate::physics::run::frame::{apply, cross, dot, ground_velocity, place, rotation};
use crate::physics::run::state::Loads;
use crate::physics::setup::mode_classes::{self, ModeClasses};
use crate::physics::setup::modes::ModalBasis;
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SetupData;

impl Simulator {
    /// Node positions, `dim` per node in the scene's output order, held
    /// nodes included [m]. The modal space expands them from q when first
    /// asked after a step.
    pub fn positions(&mut self) -> &[f64] {
        if !self.fresh.positions {
            self.engine.node_positions(&self.state, &mut self.outputs);
            if self.turned() {
                self.outputs.frame_positions.copy_from_slice(&self.outputs.positions);
                let (r, d, a) = (rotation(&self.state.rotation), self.scene().dim, self.state.anchor);
                for x in self.outputs.positions.chunks_exact_mut(d) {
                    let p = place(&self.pivot, &a, &r, x);
                    x.copy_from_slice(&p[..d]);
                }
            } else {
                shift(&mut self.outputs.positions, &self.state.anchor, self.engine.scene().dim);
            }
            self.fresh.positions = true;
        }
        &self.outputs.positions
    }
    /// Node velocities, same layout as positions [m/s].
    pub fn velocities(&mut self) -> &[f64] {
        if !self.fresh.velocities {
            self.engine.node_velocities(&self.state, &mut self.outputs);
            if self.turned() {
                self.positions();
                let (r, d) = (rotation(&self.state.rotation), self.scene().dim);
                let (c, w) = (self.state.anchor_rate, self.state.spin);
                for (v, x) in self.outputs.velocities.chunks_exact_mut(d).zip(self.outputs.frame_positions.chunks_exact(d)) {
                    let u = ground_velocity(&self.pivot, &c, &w, &r, v, x);
                    v.copy_from_slice(&u[..d]);
                }
            } else {
                shift(&mut self.outputs.velocities, &self.state.anchor_rate, self.engine.scene().dim);
            }
            self.fresh.velocities = true;
        }
        &self.outputs.velocities
    }
    /// Position of the load node (z 0 in 2D), if the node is in the scene
    /// [m]: read from the node positions when they are computed, else
    /// computed for this node alone.
    pub fn load_node_position(&mut self) -> Option<[f64; 3]> {
        let (node, d) = (self.loads().load_node.filter(|&n| n < self.scene().n_nodes)?, self.scene().dim);
        if self.fresh.positions {
            return Some(std::array::from_fn(|i| if i < d { self.outputs.positions[node * d + i] } else { 0.0 }));
        }
        let x = self.engine.node_position(&self.state, node);
        if self.turned() {
            return Some(place(&self.pivot, &self.state.anchor, &rotation(&self.state.rotation), &x[..d]));
        }
        Some(std::array::from_fn(|i| if i < d { x[i] + self.state.anchor[i] } else { 0.0 }))
    }
    /// Velocity of the load node (z 0 in 2D), if the node is in the scene [m/s].
    pub fn load_node_velocity(&mut self) -> Option<[f64; 3]> {
        let (node, d) = (self.loads().load_node.filter(|&n| n < self.scene().n_nodes)?, self.scene().dim);
        if self.fresh.velocities {
            return Some(std::array::from_fn(|i| if i < d { self.outputs.velocities[node * d + i] } else { 0.0 }));
        }
        let v = self.engine.node_velocity(&self.state, node);
        if self.turned() {
            let x = self.engine.node_position(&self.state, node);
            let (c, w) = (self.state.anchor_rate, self.state.spin);
            return Some(ground_velocity(&self.pivot, &c, &w, &rotation(&self.state.rotation), &v[..d], &x[..d]));
        }
        Some(std::array::from_fn(|i| if i < d { v[i] + self.state.anchor_rate[i] } else { 0.0 }))
    }
    /// The force the sheet exerts on its holder, from the momentum balance
    /// of the free nodes (`docs/method.md`, section 8):
    /// F = m_free g + f_p - sum M y'', y'' of the motion the scheme
    /// integrates, so the damping's reaction (it acts on the motion
    /// relative to the holder) is the holder's and, in 3D, so is what the
    /// auxiliary springs carry (their points ride with the holder). O(r) in
    /// the modal space; z is 0 in 2D [N].
    pub fn anchor_force(&mut self) -> [f64; 3] {
        if !self.fresh.anchor {
            let driven = self.engine.momentum_rate(&self.state);
            let turned = self.turned();
            let felt = self.felt_loads();
            let (d, g, f) = (self.scene().dim, felt.gravity, point_load(self.loads(), &felt.point_load, self.scene()));
            let mut force: [f64; 3] = std::array::from_fn(|i| if i < d { self.free_mass * g[i] + f[i] - driven[i] } else { 0.0 });
            if turned {
                // In the holder's frame, less the Coriolis and centrifugal parts of dP/dt: 2 w x P + w x (w x S).
                let (w, p, s) = (self.state.spin, self.engine.momentum(&self.state), self.engine.first_moment(&self.state));
                let (coriolis, centrifugal) = (cross(&w, &p), cross(&w, &cross(&w, &s)));
                let local: [f64; 3] = std::array::from_fn(|i| force[i] - 2.0 * coriolis[i] - centrifugal[i]);
                force = apply(&rotation(&self.state.rotation), &local);
            }
            self.outputs.anchor_force = force;
            self.fresh.anchor = true;
        }
        self.outputs.anchor_force
    }
    /// The torque the sheet exerts on its holder about the pivot, from the
    /// balance of angular momentum (`docs/method.md`, section 8):
    /// S x g + rho_p x f_p - sum m rho x y'', less, while the holder turns at w,
    /// 2 (w tr N - N w) - w x (J w); only z in 2D. O(r^2) in the modal space [N m].
    pub fn anchor_torque(&mut self) -> [f64; 3] {
        if !self.fresh.torque {
            let driven = self.engine.acceleration_moments(&self.state);
            let turned = self.turned();
            let felt = self.felt_loads();
            let d = self.scene().dim;
            let g: [f64; 3] = std::array::from_fn(|i| if i < d { felt.gravity[i] } else { 0.0 });
            let mut t = cross(&driven.first, &g);
            let f = point_load(self.loads(), &felt.point_load, self.scene());
            if let Some(node) = self.loads().load_node.filter(|_| f != [0.0; 3]) {
                let x = self.engine.node_position(&self.state, node);
                let arm = cross(&std::array::from_fn(|i| x[i] - self.pivot[i]), &f);
                t = std::array::from_fn(|i| t[i] + arm[i]);
            }
            let inertial = driven.angular();
            t = std::array::from_fn(|i| t[i] - inertial[i]);
            if turned {
                let (w, motion) = (self.state.spin, self.engine.motion(&self.state));
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
    /// Coordinates of the kept (modal) or reported (full) modes.
    pub fn modal_coordinates(&self) -> &[f64] {
        &self.outputs.modal_coordinates
    }
    /// omega_i of the kept or reported modes, ascending [rad/s].
    pub fn mode_frequencies(&self) -> &[f64] {
        self.engine.layout().frequencies
    }
    /// The kept (modal) or reported (full) modes: shapes Phi (row-major n x r over the free DOFs), lambda_i.
    pub fn mode_shapes(&self) -> Option<&ModalBasis> {
        self.engine.modes()
    }
    /// Out-of-plane share and mirror symmetry of each mode of [`Self::mode_shapes`] (empty without). O(n r).
    pub fn mode_classes(&self) -> ModeClasses {
        self.engine.modes().map_or_else(ModeClasses::default, |b| mode_classes::classify(self.engine.scene(), b))
    }
    /// Every mode of [`Self::mode_shapes`] laid out on the grid as the node
    /// outputs are, `[r][n_nodes][dim]`, 0 on held nodes (empty without). O(n r).
    pub fn mode_grid_shapes(&self) -> Vec<f64> {
        self.engine.modes().map_or_else(Vec::new, |b| mode_classes::grid_shapes(self.engine.scene(), b))
    }
    /// The spring force at generalized coordinates `y` as the space
    /// evaluates it: Phi^T f(x* + Phi y) in the modal space (every spring,
    /// or the cubature), f(x_rest + y) in full space. For diagnostics; the
    /// run is not affected.
    pub fn spring_force(&mut self, y: &[f64]) -> Result<Vec<f64>, PhysicsError> {
        let n = self.state.len();
        if y.len() != n {
            return Err(PhysicsError::SnapshotLength { len: y.len(), expected: n });
        }
        let mut out = vec![0.0; n];
        self.engine.spring_force(&self.state, y, &mut out);
        Ok(out)
    }
    /// The costly products of the set-up (modal space only), to store and
    /// pass to [`Self::with_setup`] later.
    pub fn setup_data(&self) -> Option<SetupData> {
        self.engine.setup_data()
    }
    /// How far the state is from the range a trained basis was trained
    /// for ([`crate::physics::TrainedRange::distance`] of the modal
    /// coordinates: at most 1 inside); 0 for other bases and in full
    /// space. O(r).
    pub fn training_range(&self) -> f64 {
        self.engine.layout().trained.map_or(0.0, |t| t.distance(&self.state.y))
    }
    /// Springs one force evaluation visits: every spring, or the cubature set.
    pub fn cubature_springs(&self) -> usize {
        self.engine.layout().springs
    }
    /// 1/2 v^T M v [J].
    pub fn kinetic_energy(&self) -> f64 {
        self.outputs.kinetic
    }
    /// Elastic energy of the springs plus gravitational energy relative to
    /// rest [J]: every spring, whatever the force model; computed when first
    /// asked after a step.
    pub fn potential_energy(&mut self) -> f64 {
        if !self.fresh.potential && self.turned() {
            // Elastic energy, and -g . sum m (X - X_rest) = -g . (m a + R S - S_rest), and -f_p . (X_p - X_p,rest).
            let (d, point) = (self.scene().dim, point_load(self.loads(), &self.loads().point_load, self.scene()));
            let elastic = self.engine.elastic_energy(&self.state);
            let s = apply(&rotation(&self.state.rotation), &self.engine.first_moment(&self.state));
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
            self.outputs.potential = self.engine.potential_energy(&self.state) - shifted;
            self.fresh.potential = true;
        }
        self.outputs.potential
    }
    /// The part of the physical force the basis cannot represent, relative
    /// to the load (0 in full space); computed when first asked after a step.
    pub fn force_residual(&mut self) -> f64 {
        if !self.fresh.residual {
            let felt = self.felt_loads();
            self.outputs.force_residual = self.engine.force_residual(&felt.gravity, &felt.point_load, &self.state);
            self.fresh.residual = true;
        }
        self.outputs.force_residual
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

//! What the values of the variables mean to the physics: the grid, the
//! solver settings, the loads and the load node, the start of a twin, and
//! the canonical scenes' start values.

use crate::fmi::params::Params;
use crate::fmi::variables::{index_of, vr, SCENES};
use crate::measures::twin_offset;
use crate::options::{FixedNodes, ForceEvaluation, Integrator, Linearization, ModeSelection, Reduction};
use crate::physics::{Grid, Loads, PhysicsError, Settings, SetupData, Simulator, TrainingProgram};

/// Holders 2, 3, 4: their displacement x, y, z and rotation vector x, y, z.
pub const HOLDER_INPUTS: [[u32; 6]; 3] = [
    [vr::ANCHOR2_X, vr::ANCHOR2_Y, vr::ANCHOR2_Z, vr::ANCHOR2_R_X, vr::ANCHOR2_R_Y, vr::ANCHOR2_R_Z],
    [vr::ANCHOR3_X, vr::ANCHOR3_Y, vr::ANCHOR3_Z, vr::ANCHOR3_R_X, vr::ANCHOR3_R_Y, vr::ANCHOR3_R_Z],
    [vr::ANCHOR4_X, vr::ANCHOR4_Y, vr::ANCHOR4_Z, vr::ANCHOR4_R_X, vr::ANCHOR4_R_Y, vr::ANCHOR4_R_Z],
];

/// Per holder (1 to 4): the force x, y, z and the torque x, y, z the sheet exerts on it.
pub const HOLDER_OUTPUTS: [[u32; 6]; 4] = [
    [vr::ANCHOR_FORCE_X, vr::ANCHOR_FORCE_Y, vr::ANCHOR_FORCE_Z, vr::ANCHOR_TORQUE_X, vr::ANCHOR_TORQUE_Y, vr::ANCHOR_TORQUE_Z],
    [vr::ANCHOR2_FORCE_X, vr::ANCHOR2_FORCE_Y, vr::ANCHOR2_FORCE_Z, vr::ANCHOR2_TORQUE_X, vr::ANCHOR2_TORQUE_Y, vr::ANCHOR2_TORQUE_Z],
    [vr::ANCHOR3_FORCE_X, vr::ANCHOR3_FORCE_Y, vr::ANCHOR3_FORCE_Z, vr::ANCHOR3_TORQUE_X, vr::ANCHOR3_TORQUE_Y, vr::ANCHOR3_TORQUE_Z],
    [vr::ANCHOR4_FORCE_X, vr::ANCHOR4_FORCE_Y, vr::ANCHOR4_FORCE_Z, vr::ANCHOR4_TORQUE_X, vr::ANCHOR4_TORQUE_Y, vr::ANCHOR4_TORQUE_Z],
];

impl Params {
    /// The start values of the canonical scene `name` (the `[scenes.NAME]`
    /// tables of `modelDescription/variables.toml`).
    pub fn canonical(name: &str) -> Option<Self> {
        let scene = SCENES.iter().find(|s| s.name == name)?;
        let mut p = Params::start();
        for (vr, values) in scene.values {
            p.values[index_of(*vr).expect("scene variables exist")] = values.to_vec();
        }
        p.fit_arrays();
        Some(p)
    }

    fn enumeration<T>(&self, vr: u32, from_value: fn(i64) -> Option<T>) -> T {
        from_value(self.scalar(vr) as i64).expect("enumeration values are range-checked")
    }

    /// The grid of `nx` x `ny` nodes these values describe.
    pub fn grid(&self) -> Grid {
        Grid {
            columns: self.count(vr::NX),
            rows: self.count(vr::NY),
            dim: self.count(vr::DIMENSION),
            spacing: self.scalar(vr::SPACING),
            node_mass: self.scalar(vr::NODE_MASS),
            spring_stiffness: self.scalar(vr::SPRING_STIFFNESS),
            shear_springs: self.scalar(vr::SHEAR_SPRINGS) != 0.0,
            bending_springs: self.scalar(vr::BENDING_SPRINGS) != 0.0,
            aux_stiffness: self.scalar(vr::AUX_STIFFNESS),
            fixed_nodes: self.enumeration(vr::FIXED_NODES, FixedNodes::from_value),
            holders: self.count(vr::N_HOLDERS),
            holder_of_node: self.get(vr::HOLDER_OF_NODE).iter().map(|&k| k as usize).collect(),
        }
    }

    /// The solver settings: the one place the model builds them.
    pub fn settings(&self) -> Settings {
        Settings {
            reduction: self.enumeration(vr::REDUCTION, Reduction::from_value),
            integrator: self.enumeration(vr::INTEGRATOR, Integrator::from_value),
            n_modes: self.count(vr::N_MODES),
            mode_selection: self.enumeration(vr::MODE_SELECTION, ModeSelection::from_value),
            static_correction: self.scalar(vr::STATIC_CORRECTION) != 0.0,
            linearization: self.enumeration(vr::LINEARIZATION, Linearization::from_value),
            anchor_motion: self.scalar(vr::ANCHOR_MOTION) != 0.0,
            anchor_rotation: self.scalar(vr::ANCHOR_ROTATION) != 0.0,
            force_evaluation: self.enumeration(vr::FORCE_EVALUATION, ForceEvaluation::from_value),
            cubature_tolerance: self.scalar(vr::CUBATURE_TOLERANCE),
            error_tolerance: self.scalar(vr::ERROR_TOLERANCE),
            max_internal_step: self.scalar(vr::MAX_INTERNAL_STEP),
            substepping: true,
            constraint_modes: true,
            threads: self.count(vr::THREADS),
            training: TrainingProgram { scale: self.scalar(vr::TRAINING_SCALE), tilt: self.scalar(vr::TRAINING_TILT), time: self.scalar(vr::TRAINING_TIME) },
        }
    }

    pub fn loads(&self) -> Loads {
        // fill_loads writes every field.
        let mut loads = Loads::physical(0);
        self.fill_loads(&mut loads);
        loads
    }

    /// Writes the loads these values describe into `loads`, reusing its
    /// weights' buffer (a change in Step Mode allocates nothing).
    pub fn fill_loads(&self, loads: &mut Loads) {
        let g = self.get(vr::GRAVITY);
        loads.gravity = [g[0], g[1], g[2]];
        loads.point_load = [self.scalar(vr::LOAD_X), self.scalar(vr::LOAD_Y), self.scalar(vr::LOAD_Z)];
        loads.load_node = self.load_node();
        loads.anchor = [self.scalar(vr::ANCHOR_X), self.scalar(vr::ANCHOR_Y), self.scalar(vr::ANCHOR_Z)];
        loads.rotation = [self.scalar(vr::ANCHOR_R_X), self.scalar(vr::ANCHOR_R_Y), self.scalar(vr::ANCHOR_R_Z)];
        for (pose, vrs) in loads.holders.iter_mut().zip(&HOLDER_INPUTS) {
            pose.anchor = std::array::from_fn(|i| self.scalar(vrs[i]));
            pose.rotation = std::array::from_fn(|i| self.scalar(vrs[3 + i]));
        }
        loads.damping_alpha = self.scalar(vr::DAMPING_ALPHA);
        loads.damping_beta = self.scalar(vr::DAMPING_BETA);
        loads.mode_weights.clear();
        loads.mode_weights.extend_from_slice(self.get(vr::MODE_WEIGHTS));
    }

    /// The load node (loadRow counted from the bottom edge, loadColumn
    /// from x = 0) as a node index in output order, if it is in the grid.
    pub fn load_node(&self) -> Option<usize> {
        // Without building the grid: a Set in Step Mode allocates nothing.
        let (columns, rows) = (self.count(vr::NX), self.count(vr::NY));
        let (row, col) = (self.count(vr::LOAD_ROW), self.count(vr::LOAD_COLUMN));
        (row < rows && col < columns).then(|| (rows - 1 - row) * columns + col)
    }

    /// Why the load node (loadRow, loadColumn) cannot carry the point load
    /// in the grid these values describe: outside it, or held.
    pub fn load_node_problem(&self) -> Option<String> {
        let (row, col) = (self.count(vr::LOAD_ROW), self.count(vr::LOAD_COLUMN));
        let grid = self.grid();
        match self.load_node() {
            None => Some(format!(
                "loadRow = {row}, loadColumn = {col} is outside the grid of ny = {} rows and nx = {} columns (rows count from the bottom edge; set nx and ny first, or in the same call)",
                grid.rows, grid.columns
            )),
            Some(node) if grid.is_held(node) => {
                Some(format!("loadRow = {row}, loadColumn = {col} is a held node (fixedNodes = {}); choose a free node", grid.fixed_nodes.name()))
            }
            Some(_) => None,
        }
    }

    /// The load node's column follows the middle of the bottom row,
    /// nx / 2 rounded down, until the host chooses it.
    pub(super) fn follow_middle_column(&mut self) {
        let middle = (self.scalar(vr::NX) / 2.0).floor();
        self.set(vr::LOAD_COLUMN, &[middle]);
    }

    /// Set-up: the grid, then the simulator (assembly, eigen decomposition).
    pub fn build(&self) -> Result<Simulator, PhysicsError> {
        self.build_with(None)
    }

    /// Set-up with the costly part taken from a baked `prebuilt` when given;
    /// a twin (startOffset > 0) starts with every free node moved by
    /// startOffset in the direction [`twin_offset`] draws from startSeed
    /// (`docs/method.md`, section 6; [`Simulator::displace_dofs`]).
    pub fn build_with(&self, prebuilt: Option<&SetupData>) -> Result<Simulator, PhysicsError> {
        let scene = self.grid().build()?;
        if self.load_node_problem().is_some() {
            return Err(PhysicsError::LoadNode { node: self.load_node(), held: self.load_node().is_some() });
        }
        let (dofs, dim) = (scene.n_dofs(), scene.dim);
        let mut sim = Simulator::with_setup(scene, &self.settings(), &self.loads(), prebuilt)?;
        let size = self.scalar(vr::START_OFFSET);
        if size != 0.0 {
            sim.displace_dofs(&twin_offset(dofs, dim, size, self.scalar(vr::START_SEED) as u64))?;
        }
        Ok(sim)
    }
}

//! The model side of the FMU: variable values -> physics (grid, solver,
//! loads, simulator), simulator -> output values. Everything FMI-generic
//! (state machine, checks, logging, serialization) lives elsewhere in
//! [`super`].

use super::variables::{index_of, vr, Dim, Variability, Variable, SCENES, VARIABLES};
use crate::options::{FixedNodes, ForceEvaluation, Integrator, Linearization, ModeSelection, Reduction};
use crate::physics::{Grid, Loads, PhysicsError, Settings, SetupData, Simulator};

/// Current values of the parameters and inputs, indexed like [`VARIABLES`]
/// (empty for the other variables). Booleans are 0/1, integers exact
/// (range-checked), enumerations their item values.
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    pub values: Vec<Vec<f64>>,
}

impl Params {
    /// Start values, arrays fitted to the start values of their structural parameters.
    pub fn start() -> Self {
        let mut p = Params { values: VARIABLES.iter().map(|v| if v.holds_value() { v.start.to_vec() } else { Vec::new() }).collect() };
        p.fit_arrays();
        p
    }

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

    /// Start values from `resources/startValues.txt` (`name value...` per
    /// line, written by `cargo xtask fmu`); variables not listed keep their
    /// compiled start value. Every value is range-checked.
    pub fn from_text(text: &str) -> Result<Self, String> {
        let mut p = Params::start();
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
            let mut words = line.split_whitespace();
            let name = words.next().unwrap();
            let i = VARIABLES.iter().position(|v| v.name == name && v.holds_value()).ok_or(format!("{name} is not a parameter or input"))?;
            let values = words.map(|w| w.parse::<f64>().map_err(|_| format!("{name}: {w} is not a number"))).collect::<Result<Vec<_>, _>>()?;
            for x in &values {
                super::values::check_value(&VARIABLES[i], Some(*x)).map_err(|m| format!("{name} = {x}: {m}"))?;
            }
            p.values[i] = values;
        }
        for (i, v) in VARIABLES.iter().enumerate().filter(|(_, v)| v.holds_value() && v.dims.is_empty()) {
            if p.values[i].len() != 1 {
                return Err(format!("{} needs one value", v.name));
            }
        }
        for (i, v) in VARIABLES.iter().enumerate().filter(|(_, v)| v.holds_value() && !v.dims.is_empty()) {
            if p.values[i].len() != p.size_of(v) {
                if v.dims.iter().any(|d| matches!(d, Dim::Param(_))) && !text.lines().any(|l| l.split_whitespace().next() == Some(v.name)) {
                    continue; // fitted below
                }
                return Err(format!("{} needs {} values, got {}", v.name, p.size_of(v), p.values[i].len()));
            }
        }
        p.fit_arrays();
        Ok(p)
    }

    pub fn get(&self, vr: u32) -> &[f64] {
        &self.values[index_of(vr).expect("known value reference")]
    }

    /// Sets the values of `vr` (unchecked; for tests and the study) and
    /// fits the arrays a structural parameter sizes.
    pub fn set(&mut self, vr: u32, values: &[f64]) {
        self.values[index_of(vr).expect("known value reference")] = values.to_vec();
        self.fit_arrays();
    }

    pub fn scalar(&self, vr: u32) -> f64 {
        self.get(vr)[0]
    }

    fn count(&self, vr: u32) -> usize {
        self.scalar(vr) as usize
    }

    /// Current number of elements of `v`.
    pub fn size_of(&self, v: &Variable) -> usize {
        v.dims
            .iter()
            .map(|d| match *d {
                Dim::Fixed(n) => n,
                Dim::Param(p) => self.count(p),
            })
            .product()
    }

    /// Resizes parameter arrays after a structural parameter changed: the
    /// existing prefix is kept, new elements repeat the first start value.
    pub fn fit_arrays(&mut self) {
        for (i, v) in VARIABLES.iter().enumerate() {
            if v.holds_value() && !v.dims.is_empty() {
                let n = self.size_of(v);
                if self.values[i].len() != n {
                    let fill = v.start.first().copied().unwrap_or(0.0);
                    self.values[i].resize(n, fill);
                }
            }
        }
    }

    /// True if the fixed values (structural and fixed parameters: what the
    /// set-up depends on) of the two are the same.
    pub fn same_fixed(&self, other: &Params) -> bool {
        VARIABLES.iter().enumerate().filter(|(_, v)| v.holds_value() && v.variability == Variability::Fixed).all(|(i, _)| self.values[i] == other.values[i])
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
        }
    }

    pub fn settings(&self) -> Settings {
        Settings {
            reduction: self.enumeration(vr::REDUCTION, Reduction::from_value),
            integrator: self.enumeration(vr::INTEGRATOR, Integrator::from_value),
            n_modes: self.count(vr::N_MODES),
            mode_selection: self.enumeration(vr::MODE_SELECTION, ModeSelection::from_value),
            static_correction: self.scalar(vr::STATIC_CORRECTION) != 0.0,
            linearization: self.enumeration(vr::LINEARIZATION, Linearization::from_value),
            anchor_motion: self.scalar(vr::ANCHOR_MOTION) != 0.0,
            force_evaluation: self.enumeration(vr::FORCE_EVALUATION, ForceEvaluation::from_value),
            cubature_tolerance: self.scalar(vr::CUBATURE_TOLERANCE),
            max_internal_step: self.scalar(vr::MAX_INTERNAL_STEP),
            substepping: true,
        }
    }

    pub fn loads(&self) -> Loads {
        let g = self.get(vr::GRAVITY);
        let f = [self.scalar(vr::LOAD_X), self.scalar(vr::LOAD_Y), self.scalar(vr::LOAD_Z)];
        Loads {
            gravity: [g[0], g[1], g[2]],
            point_load: f,
            load_node: self.load_node(),
            anchor: [self.scalar(vr::ANCHOR_X), self.scalar(vr::ANCHOR_Y), self.scalar(vr::ANCHOR_Z)],
            damping_alpha: self.scalar(vr::DAMPING_ALPHA),
            damping_beta: self.scalar(vr::DAMPING_BETA),
            mode_weights: self.get(vr::MODE_WEIGHTS).to_vec(),
        }
    }

    /// The load node (loadRow counted from the bottom edge, loadColumn
    /// from x = 0) as a node index in output order, if it is in the grid.
    pub fn load_node(&self) -> Option<usize> {
        let grid = self.grid();
        let (row, col) = (self.count(vr::LOAD_ROW), self.count(vr::LOAD_COLUMN));
        (row < grid.rows).then(|| grid.node(grid.rows - 1 - row, col)).flatten()
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

    /// Set-up: the grid, then the simulator (assembly, eigen decomposition).
    pub fn build(&self) -> Result<Simulator, PhysicsError> {
        self.build_with(None)
    }

    /// Set-up with the costly part taken from a baked `prebuilt` when given.
    pub fn build_with(&self, prebuilt: Option<&SetupData>) -> Result<Simulator, PhysicsError> {
        let scene = self.grid().build()?;
        if self.load_node_problem().is_some() {
            return Err(PhysicsError::LoadNode { node: self.load_node(), held: self.load_node().is_some() });
        }
        Simulator::with_setup(scene, &self.settings(), &self.loads(), prebuilt)
    }
}

/// Value of a variable that is computed by the simulator.
pub enum Computed<'a> {
    Scalar(f64),
    Array(&'a [f64]),
}

/// Outputs and calculated parameters; `time0` is the start time of the run.
pub fn computed(sim: &mut Simulator, vr: u32, time0: f64) -> Computed<'_> {
    match vr {
        vr::TIME => Computed::Scalar(time0 + sim.time()),
        vr::POSITIONS => Computed::Array(sim.positions()),
        vr::VELOCITIES => Computed::Array(sim.velocities()),
        vr::MODAL_COORDINATES => Computed::Array(sim.modal_coordinates()),
        vr::KINETIC_ENERGY => Computed::Scalar(sim.kinetic_energy()),
        vr::POTENTIAL_ENERGY => Computed::Scalar(sim.potential_energy()),
        vr::MODE_FREQUENCIES => Computed::Array(sim.mode_frequencies()),
        vr::FORCE_RESIDUAL => Computed::Scalar(sim.force_residual()),
        vr::CUBATURE_SPRINGS => Computed::Scalar(sim.cubature_springs() as f64),
        vr::LOAD_NODE_X | vr::LOAD_NODE_Y | vr::LOAD_NODE_Z => Computed::Scalar(component(sim.load_node_position(), (vr - vr::LOAD_NODE_X) as usize)),
        vr::LOAD_NODE_V_X | vr::LOAD_NODE_V_Y | vr::LOAD_NODE_V_Z => Computed::Scalar(component(sim.load_node_velocity(), (vr - vr::LOAD_NODE_V_X) as usize)),
        vr::ANCHOR_FORCE_X | vr::ANCHOR_FORCE_Y | vr::ANCHOR_FORCE_Z => Computed::Scalar(sim.anchor_force()[(vr - vr::ANCHOR_FORCE_X) as usize]),
        _ => unreachable!("value reference {vr} is not computed"),
    }
}

/// Component `i` of a node vector (z is 0 in 2D); NaN when there is no
/// such node (set-up refuses a load node outside the grid).
fn component(v: Option<[f64; 3]>, i: usize) -> f64 {
    v.map_or(f64::NAN, |v| v[i])
}

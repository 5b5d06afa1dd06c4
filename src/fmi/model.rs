//! The model side of the FMU: parameter values -> [`Simulator`], simulator ->
//! output values. Everything FMI-generic (state machine, checks, logging,
//! serialization) lives in [`super::instance`].

use super::variables::{index_of, vr, Dim, Variable, VARIABLES};
use crate::physics::{FixedNodes, Integrator, Reduction, SceneParams, SimError, Simulator, SolverParams, Tunables};

/// Current values of the parameters, indexed like [`VARIABLES`] (empty for
/// the other variables). Booleans are 0/1, integers exact (range-checked).
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    pub values: Vec<Vec<f64>>,
}

impl Params {
    /// Start values, arrays fitted to the start values of their structural parameters.
    pub fn start() -> Self {
        let mut p = Params { values: VARIABLES.iter().map(|v| if v.is_parameter() { v.start.to_vec() } else { Vec::new() }).collect() };
        p.fit_arrays();
        p
    }

    /// Start values from `resources/startValues.txt` (`name value...` per
    /// line, written by `cargo xtask fmu`); parameters not listed keep their
    /// compiled start value. Every value is range-checked.
    pub fn from_text(text: &str) -> Result<Self, String> {
        let mut p = Params::start();
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
            let mut words = line.split_whitespace();
            let name = words.next().unwrap();
            let i = VARIABLES.iter().position(|v| v.name == name && v.is_parameter()).ok_or(format!("{name} is not a parameter"))?;
            let values = words.map(|w| w.parse::<f64>().map_err(|_| format!("{name}: {w} is not a number"))).collect::<Result<Vec<_>, _>>()?;
            for x in &values {
                super::instance::check_value(&VARIABLES[i], Some(*x)).map_err(|m| format!("{name} = {x}: {m}"))?;
            }
            p.values[i] = values;
        }
        for (i, v) in VARIABLES.iter().enumerate().filter(|(_, v)| v.is_parameter() && v.dims.is_empty()) {
            if p.values[i].len() != 1 {
                return Err(format!("{} needs one value", v.name));
            }
        }
        for (i, v) in VARIABLES.iter().enumerate().filter(|(_, v)| v.is_parameter() && !v.dims.is_empty()) {
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
            if v.is_parameter() && !v.dims.is_empty() {
                let n = self.size_of(v);
                if self.values[i].len() != n {
                    let fill = v.start.first().copied().unwrap_or(0.0);
                    self.values[i].resize(n, fill);
                }
            }
        }
    }

    /// True if the scene or solver of the two differ (tunables aside).
    pub fn same_fixed(&self, other: &Params) -> bool {
        VARIABLES
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_parameter() && v.variability != super::variables::Variability::Tunable)
            .all(|(i, _)| self.values[i] == other.values[i])
    }

    pub fn scene(&self) -> SceneParams {
        SceneParams {
            nx: self.count(vr::NX),
            ny: self.count(vr::NY),
            dimension: self.count(vr::DIMENSION),
            spacing: self.scalar(vr::SPACING),
            node_mass: self.scalar(vr::NODE_MASS),
            spring_stiffness: self.scalar(vr::SPRING_STIFFNESS),
            shear_springs: self.scalar(vr::SHEAR_SPRINGS) != 0.0,
            bending_springs: self.scalar(vr::BENDING_SPRINGS) != 0.0,
            aux_stiffness: self.scalar(vr::AUX_STIFFNESS),
            fixed_nodes: if self.scalar(vr::FIXED_NODES) == 2.0 { FixedNodes::TopCorners } else { FixedNodes::TopRow },
        }
    }

    pub fn solver(&self) -> SolverParams {
        SolverParams {
            reduction: if self.scalar(vr::REDUCTION) == 2.0 { Reduction::Full } else { Reduction::Modal },
            integrator: if self.scalar(vr::INTEGRATOR) == 2.0 { Integrator::NewmarkImplicit } else { Integrator::NewmarkExplicit },
            n_modes: self.count(vr::N_MODES),
            max_internal_step: self.scalar(vr::MAX_INTERNAL_STEP),
            substepping: true,
        }
    }

    pub fn tunables(&self) -> Tunables {
        let g = self.get(vr::GRAVITY);
        Tunables {
            gravity: [g[0], g[1], g[2]],
            damping_alpha: self.scalar(vr::DAMPING_ALPHA),
            damping_beta: self.scalar(vr::DAMPING_BETA),
            mode_weights: self.get(vr::MODE_WEIGHTS).to_vec(),
        }
    }

    /// Set-up (assembly, eigen decomposition); the error names the parameter.
    pub fn build(&self) -> Result<Simulator, SimError> {
        Simulator::new(&self.scene(), &self.solver(), &self.tunables())
    }
}

/// Value of a variable that is computed by the simulator.
pub enum Computed<'a> {
    Scalar(f64),
    Array(&'a [f64]),
}

/// Outputs and calculated parameters; `time0` is the start time of the run.
pub fn computed(sim: &Simulator, vr: u32, time0: f64) -> Computed<'_> {
    match vr {
        vr::TIME => Computed::Scalar(time0 + sim.time()),
        vr::POSITIONS => Computed::Array(sim.positions()),
        vr::VELOCITIES => Computed::Array(sim.velocities()),
        vr::MODAL_COORDINATES => Computed::Array(sim.modal_coordinates()),
        vr::KINETIC_ENERGY => Computed::Scalar(sim.kinetic_energy()),
        vr::POTENTIAL_ENERGY => Computed::Scalar(sim.potential_energy()),
        vr::MODE_FREQUENCIES => Computed::Array(sim.mode_frequencies()),
        _ => unreachable!("value reference {vr} is not computed"),
    }
}

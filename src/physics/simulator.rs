use super::params::*;

/// Why a scene was refused or a step failed. The message names the parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct SimError {
    pub message: String,
}

impl std::fmt::Display for SimError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
impl std::error::Error for SimError {}

/// Everything needed to resume a run: time, integrator state, tunables.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub time: f64,
    /// Integrator state (layout private to the reduction; length checked on restore).
    pub state: Vec<f64>,
    pub tunables: Tunables,
}

pub struct Simulator {}

impl Simulator {
    pub fn new(_scene: &SceneParams, _solver: &SolverParams, _tunables: &Tunables) -> Result<Self, SimError> { todo!() }
    pub fn do_step(&mut self, _h: f64) -> Result<(), SimError> { todo!() }
    pub fn time(&self) -> f64 { todo!() }
    pub fn n_nodes(&self) -> usize { todo!() }
    pub fn dimension(&self) -> usize { todo!() }
    pub fn positions(&self) -> &[f64] { todo!() }
    pub fn velocities(&self) -> &[f64] { todo!() }
    pub fn modal_coordinates(&self) -> &[f64] { todo!() }
    pub fn mode_frequencies(&self) -> &[f64] { todo!() }
    pub fn kinetic_energy(&self) -> f64 { todo!() }
    pub fn potential_energy(&self) -> f64 { todo!() }
    pub fn tunables(&self) -> &Tunables { todo!() }
    pub fn set_tunables(&mut self, _t: &Tunables) -> Result<(), SimError> { todo!() }
    pub fn snapshot(&self) -> Snapshot { todo!() }
    pub fn restore(&mut self, _s: &Snapshot) -> Result<(), SimError> { todo!() }
    pub fn internal_steps_last(&self) -> usize { todo!() }
}

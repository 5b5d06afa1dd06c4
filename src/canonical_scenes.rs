//! The canonical scenes of `modelDescription/variables.toml` (`docs/method.md`,
//! section 5) as physics set-ups, for the study, the benchmarks and the
//! tests: the same start values the FMU baked for a scene starts from.

use crate::fmi::variables::{scene_names, vr};
use crate::model::Params;
use crate::physics::{Grid, Loads, PhysicsError, Settings, Simulator};

/// Grid, settings and loads of one set-up.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    pub grid: Grid,
    pub settings: Settings,
    pub loads: Loads,
}

impl Setup {
    /// The set-up of the FMU with these variable values.
    pub fn from_params(p: &Params) -> Self {
        Setup { grid: p.grid(), settings: p.settings(), loads: p.loads() }
    }

    /// The same set-up with `settings`, and loads sized to its modes (every weight 1).
    pub fn with_settings(&self, settings: Settings) -> Self {
        let loads = Loads { mode_weights: vec![1.0; settings.n_modes], ..self.loads.clone() };
        Setup { grid: self.grid.clone(), settings, loads }
    }

    /// Builds the scene and the simulator.
    pub fn simulator(&self) -> Result<Simulator, PhysicsError> {
        Simulator::new(self.grid.build()?, &self.settings, &self.loads)
    }
}

/// Names of the canonical scenes.
pub fn names() -> Vec<&'static str> {
    scene_names().collect()
}

/// The canonical scene `name` as the FMU baked for it starts.
pub fn canonical(name: &str) -> Option<Setup> {
    Params::canonical(name).map(|p| Setup::from_params(&p))
}

/// `cloth-3d` on a grid of `nx` x `ny` nodes.
pub fn cloth(nx: usize, ny: usize) -> Setup {
    let mut p = Params::canonical("cloth-3d").expect("cloth-3d is a canonical scene");
    p.set(vr::NX, &[nx as f64]);
    p.set(vr::NY, &[ny as f64]);
    Setup::from_params(&p)
}

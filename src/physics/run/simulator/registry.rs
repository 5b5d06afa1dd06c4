//! The registry: which run the settings name ([`build`]), and
//! [`Simulator`], that run behind [`Sheet`].

use std::ops::{Deref, DerefMut};

use super::adaptive::Adaptive;
use super::{Run, Sheet};
use crate::physics::error::{positive, Expected, PhysicsError, Quantity};
use crate::physics::run::integrator::{NewmarkExplicit, NewmarkImplicit, Trigonometric};
use crate::physics::run::space::{Cubature, Exact, Full, Modal, Readout};
use crate::physics::run::state::Loads;
use crate::physics::settings::{ForceEvaluation, Integrator, ModeSelection, Reduction, Settings};
use crate::physics::setup::scene::Scene;
use crate::physics::setup::setup_data::SetupData;
use crate::physics::setup::{adaptive_basis, cubature_training, trained_basis};
use crate::physics::vector_unit;

/// The run the settings chose, behind [`Sheet`]: every method of
/// [`Steps`], [`Reads`] and [`SetUp`] is called on it directly.
pub struct Simulator(Box<dyn Sheet>);

impl Simulator {
    /// Set-up: builds the space the settings names on `scene` (assembly,
    /// eigen decomposition, factorizations), binds its scheme and bounds
    /// its step. Refuses what it cannot run, naming the quantity.
    pub fn new(scene: Scene, settings: &Settings, loads: &Loads) -> Result<Self, PhysicsError> {
        Self::with_setup(scene, settings, loads, None)
    }

    /// [`Self::new`], with the costly part of a modal set-up taken from
    /// `prebuilt` (see [`SetupData`]) when given: the run is then bit for
    /// bit that of a simulator that computed it for the same parameters.
    pub fn with_setup(scene: Scene, settings: &Settings, loads: &Loads, prebuilt: Option<&SetupData>) -> Result<Self, PhysicsError> {
        scene.check()?;
        positive(Quantity::MaxInternalStep, settings.max_internal_step)?;
        if settings.reduction == Reduction::Modal && settings.n_modes == 0 {
            return Err(PhysicsError::Invalid { quantity: Quantity::Modes, value: 0.0, expected: Expected::AtLeast(1.0) });
        }
        loads.validate(settings.n_modes)?;
        loads.validate_on(&scene)?;
        let sheet = build(scene, settings, loads, prebuilt)?;
        // The set-up's faer kernels leave the vector unit's upper state dirty: clean for the host and the steps.
        vector_unit::clean();
        Ok(Simulator(sheet))
    }

    /// New loads, effective from now (see [`Steps::edit_loads`]).
    pub fn set_loads(&mut self, loads: &Loads) -> Result<(), PhysicsError> {
        self.0.edit_loads(&mut |l| l.clone_from(loads))
    }
}

impl Deref for Simulator {
    type Target = dyn Sheet;
    fn deref(&self) -> &(dyn Sheet + 'static) {
        &*self.0
    }
}

impl DerefMut for Simulator {
    fn deref_mut(&mut self) -> &mut (dyn Sheet + 'static) {
        &mut *self.0
    }
}

/// The registry: builds the space `settings.reduction` names on `scene`
/// (with the force model `settings.force_evaluation` names in the modal
/// space) and binds it to the scheme `settings.integrator` names, or
/// refuses a pair the scheme cannot integrate. `loads` are those at
/// set-up: the basis options that depend on the loads use them.
/// `prebuilt` (modal space; adaptive, with its adaptive section) replaces
/// the costly part of the set-up.
fn build(scene: Scene, settings: &Settings, loads: &Loads, prebuilt: Option<&SetupData>) -> Result<Box<dyn Sheet>, PhysicsError> {
    // A trained basis (and its cubature) comes from its training program unless it is stored.
    let trained_basis;
    let prebuilt = match prebuilt {
        None if settings.reduction == Reduction::Modal && settings.mode_selection == ModeSelection::Trained => {
            trained_basis = trained_basis::train(scene.clone(), loads, settings)?;
            Some(&trained_basis)
        }
        given => given,
    };
    match settings.reduction {
        Reduction::Modal => match settings.force_evaluation {
            ForceEvaluation::Exact => bind(Modal::<Exact>::new(scene, loads, settings, prebuilt)?, settings, loads),
            ForceEvaluation::Cubature => {
                // The spring set is trained on the exact reduced model unless it is stored.
                let trained;
                let prebuilt = match prebuilt {
                    Some(data) if data.cubature.is_some() => Some(data),
                    _ => {
                        trained = cubature_training::train(scene.clone(), loads, settings, prebuilt, None)?;
                        Some(&trained)
                    }
                };
                bind(Modal::<Cubature>::new(scene, loads, settings, prebuilt)?, settings, loads)
            }
        },
        Reduction::Full => bind(Full::new(scene, loads, settings)?, settings, loads),
        Reduction::Adaptive => {
            positive(Quantity::ErrorTolerance, settings.error_tolerance)?;
            // The choice is rebuilt from its stored form unless it must be computed.
            let chosen = match prebuilt {
                Some(data) => adaptive_basis::choose_from(&scene, settings, data)?,
                None => adaptive_basis::choose(&scene, loads, settings)?,
            };
            let c = chosen.settings.force_evaluation == ForceEvaluation::Cubature;
            Ok(match (settings.integrator, c) {
                (Integrator::NewmarkExplicit, false) => Box::new(Adaptive::<Exact, NewmarkExplicit, NewmarkExplicit>::new(scene, settings, loads, chosen)?),
                (Integrator::NewmarkImplicit, false) => Box::new(Adaptive::<Exact, NewmarkImplicit, NewmarkImplicit>::new(scene, settings, loads, chosen)?),
                (Integrator::Trigonometric, false) => Box::new(Adaptive::<Exact, Trigonometric, NewmarkExplicit>::new(scene, settings, loads, chosen)?),
                (Integrator::NewmarkExplicit, true) => Box::new(Adaptive::<Cubature, NewmarkExplicit, NewmarkExplicit>::new(scene, settings, loads, chosen)?),
                (Integrator::NewmarkImplicit, true) => Box::new(Adaptive::<Cubature, NewmarkImplicit, NewmarkImplicit>::new(scene, settings, loads, chosen)?),
                (Integrator::Trigonometric, true) => Box::new(Adaptive::<Cubature, Trigonometric, NewmarkExplicit>::new(scene, settings, loads, chosen)?),
            })
        }
    }
}

/// Binds `space` to the scheme `settings.integrator` names.
fn bind<S: Readout>(space: S, settings: &Settings, loads: &Loads) -> Result<Box<dyn Sheet>, PhysicsError> {
    Ok(match settings.integrator {
        Integrator::NewmarkExplicit => Box::new(Run::<S, NewmarkExplicit>::new(space, settings, loads)?),
        Integrator::NewmarkImplicit => Box::new(Run::<S, NewmarkImplicit>::new(space, settings, loads)?),
        Integrator::Trigonometric => Box::new(Run::<S, Trigonometric>::new(space, settings, loads)?),
    })
}

//! Parameters of a scene, of the solver and of the tunable loads.
//!
//! These are plain data: the FMI layer fills them from its variables, tests
//! and benchmarks build them directly. Validation lives in [`super::Simulator::new`].

/// Which nodes of the grid are held in place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FixedNodes {
    /// Every node of row 0 (the top edge).
    TopRow,
    /// The two ends of row 0.
    TopCorners,
}

/// Space in which the equations of motion are integrated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reduction {
    /// Generalized coordinates of the kept vibration modes (the paper's method).
    Modal,
    /// All free degrees of freedom (the reference).
    Full,
}

/// Newmark-beta family member used for the internal steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// beta = 0, gamma = 1/2: the paper's explicit scheme, stable for dt * omega_max < 2.
    NewmarkExplicit,
    /// beta = 1/4, gamma = 1/2: average acceleration, Newton iterations per step.
    NewmarkImplicit,
}

/// The mass-spring grid of METHOD.md section 5.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneParams {
    /// Nodes per row.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// 2 or 3.
    pub dimension: usize,
    /// Rest distance between neighbouring nodes [m].
    pub spacing: f64,
    /// Mass of every node [kg].
    pub node_mass: f64,
    /// Stiffness of every grid spring [N/m].
    pub spring_stiffness: f64,
    /// Diagonal springs (r,c)-(r+1,c+1) and (r,c+1)-(r+1,c).
    pub shear_springs: bool,
    /// Springs (r,c)-(r,c+2) and (r,c)-(r+2,c).
    pub bending_springs: bool,
    /// Stiffness of the auxiliary springs tying each free node to a point `spacing`
    /// out of the plane (3D only; 0 leaves them out) [N/m].
    pub aux_stiffness: f64,
    /// Which nodes are fixed.
    pub fixed_nodes: FixedNodes,
}

/// How the scene is integrated.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverParams {
    pub reduction: Reduction,
    pub integrator: Integrator,
    /// Modes kept by `Reduction::Modal`; with `Reduction::Full`, the number of modes
    /// whose frequencies and coordinates are reported (0 skips the eigen decomposition).
    pub n_modes: usize,
    /// Upper bound on one internal step [s].
    pub max_internal_step: f64,
    /// Split a communication step into internal steps that keep the explicit
    /// integrator stable. Only tests switch this off, to show why it exists.
    pub substepping: bool,
}

/// Loads and gains that may change between communication steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Tunables {
    /// Gravitational acceleration [m/s^2]; z is ignored in 2D.
    pub gravity: [f64; 3],
    /// Rayleigh mass-proportional damping [1/s].
    pub damping_alpha: f64,
    /// Rayleigh stiffness-proportional damping [s].
    pub damping_beta: f64,
    /// Gain per kept mode (METHOD.md section 3); length `n_modes`.
    pub mode_weights: Vec<f64>,
}

/// Names of the canonical scenes of METHOD.md section 5.
pub const SCENE_NAMES: [&str; 4] = ["paper-2d-top-row", "paper-2d-top-corners", "paper-3d-sheet", "cloth-3d"];

impl SceneParams {
    /// The defaults of METHOD.md section 5 on an `nx` x `ny` grid in `dimension` D.
    pub fn grid(nx: usize, ny: usize, dimension: usize, fixed_nodes: FixedNodes) -> Self {
        let spring_stiffness = 50.0;
        SceneParams {
            nx,
            ny,
            dimension,
            spacing: 0.1,
            node_mass: 0.01,
            spring_stiffness,
            shear_springs: true,
            bending_springs: false,
            aux_stiffness: if dimension == 3 { spring_stiffness / 1000.0 } else { 0.0 },
            fixed_nodes,
        }
    }

    /// A canonical scene by name; `cloth-3d` is 30 x 30 with the top row fixed.
    pub fn canonical(name: &str) -> Option<Self> {
        Some(match name {
            "paper-2d-top-row" => Self::grid(10, 10, 2, FixedNodes::TopRow),
            "paper-2d-top-corners" => Self::grid(10, 10, 2, FixedNodes::TopCorners),
            "paper-3d-sheet" => Self::grid(7, 7, 3, FixedNodes::TopRow),
            "cloth-3d" => Self::grid(30, 30, 3, FixedNodes::TopRow),
            _ => return None,
        })
    }
}

impl Default for SceneParams {
    /// `paper-2d-top-row`, the paper's Fig. 7.
    fn default() -> Self {
        Self::grid(10, 10, 2, FixedNodes::TopRow)
    }
}

impl Default for SolverParams {
    /// Two modes, explicit Newmark, internal steps of at most 10 ms.
    fn default() -> Self {
        SolverParams { reduction: Reduction::Modal, integrator: Integrator::NewmarkExplicit, n_modes: 2, max_internal_step: 0.01, substepping: true }
    }
}

impl Tunables {
    /// Earth gravity along -y, no damping, every weight 1 (the physical model).
    pub fn physical(n_modes: usize) -> Self {
        Tunables { gravity: [0.0, -9.81, 0.0], damping_alpha: 0.0, damping_beta: 0.0, mode_weights: vec![1.0; n_modes] }
    }
}

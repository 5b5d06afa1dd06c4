//! The fmi3 functions the fuzz targets call, as a table of C function
//! pointers: loaded from the FMU's release library (default), or taken from
//! the FMU crate linked into the fuzz target (feature `linked`).

#![allow(non_snake_case, non_camel_case_types, clippy::too_many_arguments, clippy::missing_safety_doc)]

use std::ffi::{c_char, c_void};
use std::sync::OnceLock;

pub type fmi3Status = i32;
pub type fmi3Instance = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3ValueReference = u32;
pub type fmi3String = *const c_char;
pub type fmi3LogMessageCallback = Option<unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String)>;
pub type fmi3IntermediateUpdateCallback = Option<unsafe extern "C" fn()>;

macro_rules! api {
    ($($name:ident($($a:ident: $t:ty),*) $(-> $r:ty)?;)*) => {
        pub struct Api {
            $($name: unsafe extern "C" fn($($t),*) $(-> $r)?,)*
        }

        impl Api {
            $(
                #[inline]
                pub unsafe fn $name(&self, $($a: $t),*) $(-> $r)? {
                    (self.$name)($($a),*)
                }
            )*

            #[cfg(not(feature = "linked"))]
            fn load(lib: &'static libloading::Library) -> Api {
                unsafe {
                    Api {
                        $($name: *lib
                            .get(concat!(stringify!($name), "\0").as_bytes())
                            .unwrap_or_else(|e| panic!("{}: {e}", stringify!($name))),)*
                    }
                }
            }

            #[cfg(feature = "linked")]
            fn linked() -> Api {
                use modal_mass_spring::fmi::exports as x;
                // Same C signatures, spelled with fmi-sys's type aliases there.
                unsafe { Api { $($name: std::mem::transmute(x::$name as *const ()),)* } }
            }
        }
    };
}

api! {
    fmi3InstantiateCoSimulation(
        instanceName: fmi3String, instantiationToken: fmi3String, resourcePath: fmi3String, visible: bool,
        loggingOn: bool, eventModeUsed: bool, earlyReturnAllowed: bool,
        requiredIntermediateVariables: *const fmi3ValueReference, nRequiredIntermediateVariables: usize,
        instanceEnvironment: fmi3InstanceEnvironment, logMessage: fmi3LogMessageCallback,
        intermediateUpdate: fmi3IntermediateUpdateCallback
    ) -> fmi3Instance;
    fmi3FreeInstance(instance: fmi3Instance);
    fmi3SetDebugLogging(instance: fmi3Instance, loggingOn: bool, nCategories: usize, categories: *const fmi3String) -> fmi3Status;
    fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status;
    fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status;
    fmi3EnterInitializationMode(instance: fmi3Instance, toleranceDefined: bool, tolerance: f64, startTime: f64, stopTimeDefined: bool, stopTime: f64) -> fmi3Status;
    fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status;
    fmi3DoStep(
        instance: fmi3Instance, currentCommunicationPoint: f64, communicationStepSize: f64, noSetFMUStatePriorToCurrentPoint: bool,
        eventHandlingNeeded: *mut bool, terminateSimulation: *mut bool, earlyReturn: *mut bool, lastSuccessfulTime: *mut f64
    ) -> fmi3Status;
    fmi3Terminate(instance: fmi3Instance) -> fmi3Status;
    fmi3Reset(instance: fmi3Instance) -> fmi3Status;
    fmi3GetFloat64(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *mut f64, nValues: usize) -> fmi3Status;
    fmi3SetFloat64(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *const f64, nValues: usize) -> fmi3Status;
    fmi3GetUInt64(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *mut u64, nValues: usize) -> fmi3Status;
    fmi3SetUInt64(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *const u64, nValues: usize) -> fmi3Status;
    fmi3GetInt64(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *mut i64, nValues: usize) -> fmi3Status;
    fmi3SetInt64(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *const i64, nValues: usize) -> fmi3Status;
    fmi3GetBoolean(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *mut bool, nValues: usize) -> fmi3Status;
    // Declared with bytes: a host may pass any byte for an fmi3Boolean.
    fmi3SetBoolean(instance: fmi3Instance, vrs: *const fmi3ValueReference, nvrs: usize, values: *const u8, nValues: usize) -> fmi3Status;
    fmi3GetFMUState(instance: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status;
    fmi3SetFMUState(instance: fmi3Instance, state: fmi3FMUState) -> fmi3Status;
    fmi3FreeFMUState(instance: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status;
    fmi3SerializedFMUStateSize(instance: fmi3Instance, state: fmi3FMUState, size: *mut usize) -> fmi3Status;
    fmi3SerializeFMUState(instance: fmi3Instance, state: fmi3FMUState, bytes: *mut u8, size: usize) -> fmi3Status;
    fmi3DeserializeFMUState(instance: fmi3Instance, bytes: *const u8, size: usize, state: *mut fmi3FMUState) -> fmi3Status;
    fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status;
    fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status;
    fmi3SetTime(instance: fmi3Instance, time: f64) -> fmi3Status;
    fmi3GetDirectionalDerivative(
        instance: fmi3Instance, unknowns: *const fmi3ValueReference, nUnknowns: usize, knowns: *const fmi3ValueReference, nKnowns: usize,
        seed: *const f64, nSeed: usize, sensitivity: *mut f64, nSensitivity: usize
    ) -> fmi3Status;
}

/// Where the release library is: `$MMS_FMU_LIBRARY`, else `target/release` of the repository.
#[cfg(not(feature = "linked"))]
fn library_path() -> std::path::PathBuf {
    std::env::var_os("MMS_FMU_LIBRARY")
        .map(Into::into)
        .unwrap_or_else(|| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/release/libmodal_mass_spring.so"))
}

/// The fmi3 functions of the FMU under test.
pub fn fmi() -> &'static Api {
    static API: OnceLock<Api> = OnceLock::new();
    API.get_or_init(|| {
        #[cfg(not(feature = "linked"))]
        {
            static LIB: OnceLock<libloading::Library> = OnceLock::new();
            let lib = LIB.get_or_init(|| {
                let path = library_path();
                unsafe { libloading::Library::new(&path) }
                    .unwrap_or_else(|e| panic!("{}: {e} (build it with cargo xtask fmu, or set MMS_FMU_LIBRARY)", path.display()))
            });
            Api::load(lib)
        }
        #[cfg(feature = "linked")]
        Api::linked()
    })
}

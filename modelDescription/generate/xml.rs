//! modelDescription.xml (FMI 3.0, Co-Simulation): the table as an
//! `Fmi3ModelDescription` of the `fmi-schema` crate, serialized by it.
//!
//! Not declared by `generate.rs`: it needs `fmi-schema` (feature `fmi3`),
//! which the build script does not have. The includers that write the XML
//! (the xtask and `tests/fmi_model_description.rs`) include this file beside
//! `generate.rs`, which they must include as the crate-root module `generate`.
//!
//! What fmi-schema 0.8 cannot express, and is therefore done by hand here:
//! - `Enumeration` variables: fmi-schema has no such variable. Each is built
//!   as an `Int64` variable, whose attributes in the FMI 3.0 schema are the
//!   same (`fmi3ArrayableVariable` with `declaredType`, `start`, `min`,
//!   `max`, `quantity`, and `Dimension` children), and its element renamed
//!   to `Enumeration` in the serialized text. The parser admits no `Int64`
//!   variable, so every `Int64` element is one of them.
//! - the exponents `A` and `K` of `BaseUnit`: fmi-schema writes them as `a`
//!   and `k`, which the schema does not know; a unit using them is refused.

use std::collections::BTreeMap;

use fmi_schema::fmi3 as md;
use fmi_schema::utils::AttrList;

use crate::generate::{Dim, Spec, Variable};

impl Spec {
    /// modelDescription.xml (FMI 3.0, Co-Simulation) with the given start values.
    pub fn model_description_xml(&self, overrides: &BTreeMap<String, Vec<f64>>) -> Result<String, String> {
        let starts = self.starts(overrides)?;
        let d = &self.default_experiment;
        let description = md::Fmi3ModelDescription {
            fmi_version: "3.0".into(),
            model_name: self.model_name.clone(),
            instantiation_token: self.instantiation_token.clone(),
            description: Some(self.description.clone()),
            generation_tool: Some(self.generation_tool.clone()),
            variable_naming_convention: Some("flat".into()),
            co_simulation: Some(self.co_simulation_element()?),
            unit_definitions: Some(md::UnitDefinitions { units: self.units.iter().map(unit).collect::<Result<_, _>>()? }),
            type_definitions: Some(self.type_definitions()),
            log_categories: Some(md::LogCategories {
                categories: self
                    .log_categories
                    .iter()
                    .map(|c| md::Category { name: c.name.clone(), description: Some(c.description.clone()), annotations: None })
                    .collect(),
            }),
            default_experiment: Some(md::DefaultExperiment {
                start_time: Some(d.start_time),
                stop_time: Some(d.stop_time),
                step_size: Some(d.step_size),
                ..Default::default()
            }),
            model_variables: md::ModelVariables {
                variables: self.variables.iter().map(|v| self.model_variable(v, starts.get(&v.name))).collect::<Result<_, _>>()?,
            },
            model_structure: self.model_structure(),
            ..Default::default()
        };
        let xml = fmi_schema::serialize(&description, false).map_err(|e| format!("modelDescription.xml: {e}"))?;
        // Enumeration variables, written as Int64 (see the module documentation).
        Ok(xml.replace("<Int64 ", "<Enumeration ").replace("</Int64>", "</Enumeration>") + "\n")
    }

    /// The `CoSimulation` element: the model identifier and the flags of the table.
    fn co_simulation_element(&self) -> Result<md::Fmi3CoSimulation, String> {
        let mut cs = md::Fmi3CoSimulation { model_identifier: self.model_identifier.clone(), ..Default::default() };
        for (name, &on) in &self.co_simulation {
            let flag = match name.as_str() {
                "needsExecutionTool" => &mut cs.needs_execution_tool,
                "canBeInstantiatedOnlyOncePerProcess" => &mut cs.can_be_instantiated_only_once_per_process,
                "canGetAndSetFMUState" => &mut cs.can_get_and_set_fmu_state,
                "canSerializeFMUState" => &mut cs.can_serialize_fmu_state,
                "providesDirectionalDerivatives" => &mut cs.provides_directional_derivatives,
                "providesAdjointDerivatives" => &mut cs.provides_adjoint_derivatives,
                "providesPerElementDependencies" => &mut cs.provides_per_element_dependencies,
                "canHandleVariableCommunicationStepSize" => &mut cs.can_handle_variable_communication_step_size,
                "providesIntermediateUpdate" => &mut cs.provides_intermediate_update,
                "mightReturnEarlyFromDoStep" => &mut cs.might_return_early_from_do_step,
                "canReturnEarlyAfterIntermediateUpdate" => &mut cs.can_return_early_after_intermediate_update,
                "hasEventMode" => &mut cs.has_event_mode,
                "providesEvaluateDiscreteStates" => &mut cs.provides_evaluate_discrete_states,
                other => return Err(format!("co_simulation: {other} is not a capability flag of FMI 3.0 CoSimulation")),
            };
            *flag = Some(on);
        }
        Ok(cs)
    }

    /// One `Float64Type` per unit (named after its quantity), then the enumeration types.
    fn type_definitions(&self) -> md::TypeDefinitions {
        let floats = self.units.iter().map(|u| {
            md::TypeDefinition::Float64(md::Float64Type {
                name: u.quantity.clone(),
                quantity: Some(u.quantity.clone()),
                unit: Some(u.name.clone()),
                ..Default::default()
            })
        });
        let enumerations = self.enumerations.iter().map(|e| {
            md::TypeDefinition::Enumeration(md::EnumerationType {
                name: e.name.clone(),
                description: Some(e.description.clone()),
                annotations: None,
                quantity: None,
                items: e
                    .items
                    .iter()
                    .map(|i| md::EnumerationItem { name: i.name.clone(), value: i.value, description: Some(i.description.clone()), annotations: None })
                    .collect(),
            })
        });
        md::TypeDefinitions { type_definitions: floats.chain(enumerations).collect() }
    }

    /// The variable's element; a Float64 variable with a unit takes the
    /// type definition of that unit.
    fn model_variable(&self, v: &Variable, start: Option<&Vec<f64>>) -> Result<md::Variable, String> {
        let causality: md::Causality = v.causality.parse().map_err(|e| format!("{}: {e}", v.name))?;
        let variability: md::Variability = v.variability.parse().map_err(|e| format!("{}: {e}", v.name))?;
        let unit_type =
            v.unit.as_ref().map(|u| self.units.iter().find(|x| &x.name == u).map(|x| x.quantity.clone()).ok_or(format!("{}: unit {u} is not defined", v.name)));
        let declared_type = v.declared_type.clone().or(unit_type.transpose()?);
        let mut dimensions = Vec::new();
        for d in v.dims() {
            dimensions.push(match d {
                Dim::Fixed(n) => md::Dimension::Fixed(n),
                Dim::Param(p) => md::Dimension::Variable(self.variable(&p).ok_or(format!("{}: dimension {p} is not a variable", v.name))?.vr),
            });
        }
        // The fields every variable element has, then those of its type.
        macro_rules! element {
            ($ty:ident { $($field:ident: $value:expr),* $(,)? }) => {
                md::$ty {
                    name: v.name.clone(),
                    value_reference: v.vr,
                    description: Some(v.description.clone()),
                    causality: Some(causality),
                    variability: Some(variability),
                    declared_type,
                    dimensions,
                    $($field: $value,)*
                    ..Default::default()
                }
            };
        }
        Ok(match v.ty.as_str() {
            "Float64" => md::Variable::Float64(element!(FmiFloat64 { start: start.map(|s| AttrList(s.clone())), min: v.min, max: v.max })),
            // Whole numbers below 2^53 (the parser checks the range), exact as f64.
            "UInt64" => md::Variable::UInt64(element!(FmiUInt64 {
                start: start.map(|s| AttrList(s.iter().map(|&x| x as u64).collect())),
                min: v.min.map(|x| x as u64),
                max: v.max.map(|x| x as u64),
            })),
            "Boolean" => md::Variable::Boolean(element!(FmiBoolean { start: start.map(|s| AttrList(s.iter().map(|&x| x != 0.0).collect())) })),
            "Enumeration" => md::Variable::Int64(element!(FmiInt64 { start: start.map(|s| AttrList(s.iter().map(|&x| x as i64).collect())) })),
            other => return Err(format!("{}: no element for type {other}", v.name)),
        })
    }

    /// Every output, then every initial unknown (outputs and calculated
    /// parameters), each in the order of the value references.
    fn model_structure(&self) -> md::ModelStructure {
        let unknowns = |keep: fn(&Variable) -> bool| {
            let mut vs: Vec<&Variable> = self.variables.iter().filter(|v| keep(v)).collect();
            vs.sort_by_key(|v| v.vr);
            vs.into_iter().map(|v| md::Fmi3Unknown { value_reference: v.vr, dependencies: self.dependencies(v), ..Default::default() }).collect::<Vec<_>>()
        };
        let outputs = unknowns(|v| v.causality == "output").into_iter().map(md::VariableDependency::Output);
        let initial = unknowns(|v| v.causality == "output" || v.causality == "calculatedParameter").into_iter().map(md::VariableDependency::InitialUnknown);
        md::ModelStructure { unknowns: outputs.chain(initial).collect() }
    }

    /// The `dependencies` attribute of an output in ModelStructure: the
    /// inputs it declares in `depends_on` (none: it depends on the inputs
    /// only through the state, so chained FMUs form no algebraic loop). No
    /// attribute (every known) where the table declares nothing or has no input.
    fn dependencies(&self, v: &Variable) -> Option<AttrList<u32>> {
        match &v.depends_on {
            Some(deps) if self.variables.iter().any(|x| x.causality == "input") => {
                Some(AttrList(deps.iter().filter_map(|d| self.variable(d)).map(|x| x.vr).collect()))
            }
            _ => None,
        }
    }
}

/// A `Unit` element with its `BaseUnit` exponents.
fn unit(u: &crate::generate::Unit) -> Result<md::Fmi3Unit, String> {
    let mut base = md::BaseUnit::default();
    for (name, &exponent) in &u.base {
        let slot = match name.as_str() {
            "kg" => &mut base.kg,
            "m" => &mut base.m,
            "s" => &mut base.s,
            "mol" => &mut base.mol,
            "cd" => &mut base.cd,
            "rad" => &mut base.rad,
            // See the module documentation.
            "A" | "K" => return Err(format!("unit {}: fmi-schema 0.8 cannot write the base unit {name}", u.name)),
            other => return Err(format!("unit {}: {other} is not a base unit", u.name)),
        };
        *slot = Some(exponent);
    }
    Ok(md::Fmi3Unit { name: u.name.clone(), base_unit: Some(base), ..Default::default() })
}

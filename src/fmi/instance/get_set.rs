//! fmi3Get/Set of every type on an instance, marshalled between the host's
//! arrays and the variable table, with the NULL, size, type, state and
//! range checks of [`crate::fmi::values`]. A Set stores every value or none.

use fmi_sys::fmi3::fmi3Status;

use super::{Instance, R};
use crate::fmi::functions::Function;
use crate::fmi::model::{Computed, Model};
use crate::fmi::ptr::{slice, slice_mut, too_many};
use crate::fmi::state_machine::Mode;
use crate::fmi::values::{check_value, settable_in};
use crate::fmi::variables::{index_of, Causality, Type, Variable, VARIABLES};
use crate::status::OK;

impl Instance {
    /// The value references of a Get/Set call, after the NULL and size checks
    /// of both arrays.
    ///
    /// # Safety
    /// `vrs` must point to `n_vrs` elements unless it is NULL or `n_vrs` is 0.
    unsafe fn value_references<'a, T>(&self, f: Function, vrs: *const u32, n_vrs: usize, values: *const T, n_values: usize) -> Result<&'a [u32], fmi3Status> {
        let f = f.name();
        if n_vrs > 0 && vrs.is_null() {
            return Err(self.log.fail(&format!("{f}: valueReferences is NULL but nValueReferences = {n_vrs}")));
        }
        if n_values > 0 && values.is_null() {
            return Err(self.log.fail(&format!("{f}: values is NULL but nValues = {n_values}")));
        }
        if too_many::<u32>(n_vrs) || too_many::<T>(n_values) {
            return Err(self.log.fail(&format!("{f}: nValueReferences = {n_vrs} or nValues = {n_values} cannot be an array size")));
        }
        Ok(slice(vrs, n_vrs))
    }

    /// Looks up every value reference, checks its type and counts the values.
    fn resolve(&self, f: Function, ty: Type, vrs: &[u32], n_values: usize) -> Result<(), fmi3Status> {
        let f = f.name();
        let mut total = 0usize;
        for &r in vrs {
            let Some(i) = index_of(r) else {
                return Err(self.log.fail(&format!("{f}: unknown value reference {r}")));
            };
            let v = &VARIABLES[i];
            if v.ty != ty {
                return Err(self.log.fail(&format!("{f}: {} (value reference {r}) is accessed with fmi3Get/Set{}", v.name, v.ty.name())));
            }
            total = total.saturating_add(self.params.size_of(v));
        }
        if total != n_values {
            return Err(self.log.fail(&format!("{f}: nValues = {n_values}, but the {} value references hold {total} values", vrs.len())));
        }
        Ok(())
    }

    /// fmi3Get of variables of type `ty`, converted by `conv`.
    ///
    /// # Safety
    /// `vrs` and `values` must point to `n_vrs` / `n_values` elements (or be null when that is 0).
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn get<T>(&mut self, f: Function, ty: Type, vrs: *const u32, n_vrs: usize, values: *mut T, n_values: usize, conv: impl Fn(f64) -> T) -> R {
        let vrs = self.value_references(f, vrs, n_vrs, values as *const T, n_values)?;
        // nValues is checked against the variables before `values` is touched.
        self.resolve(f, ty, vrs, n_values)?;
        let needs_sim = vrs.iter().any(|&r| {
            let v = &VARIABLES[index_of(r).unwrap()];
            !v.holds_value() && v.causality != Causality::Independent
        });
        if needs_sim {
            self.ensure_set_up()?;
        }
        let out = slice_mut(values, n_values);
        let mut k = 0;
        for &r in vrs {
            let i = index_of(r).unwrap();
            let v = &VARIABLES[i];
            let n = self.params.size_of(v);
            if v.holds_value() {
                for (o, x) in out[k..k + n].iter_mut().zip(&self.params.values[i]) {
                    *o = conv(*x);
                }
            } else if v.causality == Causality::Independent {
                out[k] = conv(self.time());
            } else {
                match self.model.output(r, self.start_time) {
                    Computed::Scalar(x) => out[k] = conv(x),
                    Computed::Refused(why) => return Err(self.log.fail(&format!("{}: {}: {why}", f.name(), v.name))),
                    Computed::Array(a) => {
                        if a.len() != n {
                            return Err(self.log.fail(&format!("{}: {} holds {} values, expected {n}", f.name(), v.name, a.len())));
                        }
                        for (o, x) in out[k..k + n].iter_mut().zip(a) {
                            *o = conv(*x);
                        }
                    }
                }
            }
            k += n;
        }
        Ok(OK)
    }

    fn settable(&self, v: &Variable) -> Result<(), String> {
        let Some(allowed) = settable_in(v.causality, v.variability) else {
            return Err(format!("{} is a {:?} and cannot be set", v.name, v.causality));
        };
        if allowed & self.mode.bit() == 0 {
            return Err(format!("{} ({:?}, {:?}) cannot be set in {:?}", v.name, v.causality, v.variability, self.mode));
        }
        Ok(())
    }

    /// fmi3Set of variables of type `ty`, converted by `conv` (`None`: not
    /// representable). Either every value is stored or none: the glue checks
    /// and stores, then the model applies its own rules ([`Model::set`]); a
    /// change of a tunable parameter or an input in Step Mode reaches the
    /// running model at once, and is undone if the model refuses it.
    ///
    /// # Safety
    /// As for [`Instance::get`].
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn set<T: Copy + std::fmt::Debug>(
        &mut self,
        f: Function,
        ty: Type,
        vrs: *const u32,
        n_vrs: usize,
        values: *const T,
        n_values: usize,
        conv: impl Fn(T) -> Option<f64>,
    ) -> R {
        let vrs = self.value_references(f, vrs, n_vrs, values, n_values)?;
        // nValues is checked against the variables before `values` is read.
        self.resolve(f, ty, vrs, n_values)?;
        let values = slice(values, n_values);
        let mut k = 0;
        for &r in vrs {
            let v = &VARIABLES[index_of(r).unwrap()];
            if let Err(m) = self.settable(v) {
                return Err(self.log.fail(&format!("{}: {m}", f.name())));
            }
            let n = self.params.size_of(v);
            for (j, &raw) in values[k..k + n].iter().enumerate() {
                if let Err(m) = check_value(v, conv(raw)) {
                    let at = if v.dims.is_empty() { String::new() } else { format!("[{j}]") };
                    return Err(self.log.fail(&format!("{}: {}{at} = {raw:?} refused: {m}", f.name(), v.name)));
                }
            }
            k += n;
        }
        // The values before, in a copy kept in place: allocates nothing unless the sizes changed.
        self.before_set.values.clone_from(&self.params.values);
        let mut k = 0;
        let mut structure = false;
        for &r in vrs {
            let i = index_of(r).unwrap();
            let v = &VARIABLES[i];
            let n = self.before_set.size_of(v);
            for (dst, &raw) in self.params.values[i].iter_mut().zip(&values[k..k + n]) {
                *dst = conv(raw).unwrap();
            }
            structure |= v.causality == Causality::StructuralParameter;
            k += n;
        }
        if structure {
            self.params.fit_arrays();
        }
        if let Err(m) = self.model.set(&mut self.params, &self.before_set, vrs, self.mode == Mode::StepMode) {
            std::mem::swap(&mut self.params, &mut self.before_set);
            return Err(self.log.fail(&format!("{}: {m}", f.name())));
        }
        Ok(OK)
    }

    /// Get/Set of a type no variable of this FMU has: only an empty request succeeds.
    ///
    /// # Safety
    /// `vrs` must point to `n` elements unless it is NULL or `n` is 0.
    pub unsafe fn no_variables(&self, f: Function, type_name: &str, vrs: *const u32, n: usize) -> R {
        let name = f.name();
        if n > 0 && vrs.is_null() {
            return Err(self.log.fail(&format!("{name}: valueReferences is NULL")));
        }
        if too_many::<u32>(n) {
            return Err(self.log.fail(&format!("{name}: nValueReferences = {n} cannot be an array size")));
        }
        if let Some(&r) = slice(vrs, n).first() {
            return Err(match index_of(r) {
                Some(i) => self.log.fail(&format!("{name}: {} (value reference {r}) is a {}, not a {type_name}", VARIABLES[i].name, VARIABLES[i].ty.name())),
                None => self.log.fail(&format!("{name}: unknown value reference {r}")),
            });
        }
        Ok(OK)
    }
}

//! The JSON form of [`Params`]: which fields a file must give, may give, or leaves
//! out, by topology and axis (docs/model.md §1, §11).
//!
//! A field that applies to the file's topology is required unless it has a default
//! (`Jw`, `Cw`, `fw`, `theta_bw`, `W`, `fluct_order`, `fluct_phase`, the unbalance,
//! `encoder_delay`, `Tload`, the Stribeck law's `fsm` … `stribeck_shape`); a field that does not apply is left out when written, and
//! if a file gives it, [`Params::validate`] refuses it by name (values equal to the
//! registry's `unused` value, e.g. `Rw: 1` on a two-mass drive, are harmless and
//! accepted). Files of the `spur_gear` and `direct` topologies written before the other
//! topologies existed read and write exactly as they did; `axis` is written only for
//! a linear axis, `Tload` and the Stribeck parameters only when they differ from their
//! defaults.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::params::{Axis, ControllerParams, HeldRange, ParamError, Params, Topology};
use super::registry::spec;

/// [`Params`] as it is written: every field that may be absent is an `Option`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamsJson {
    #[serde(default)]
    name: String,
    topology: Topology,
    #[serde(default, skip_serializing_if = "is_rotary")]
    axis: Axis,
    #[serde(rename = "Jm", default, skip_serializing_if = "Option::is_none")]
    jm: Option<f64>,
    #[serde(rename = "Jw", default, skip_serializing_if = "Option::is_none")]
    jw: Option<f64>,
    #[serde(rename = "Jt")]
    jt: f64,
    #[serde(rename = "Mw", default, skip_serializing_if = "Option::is_none")]
    mw: Option<f64>,
    #[serde(rename = "Cm", default, skip_serializing_if = "Option::is_none")]
    cm: Option<f64>,
    #[serde(rename = "Cw", default, skip_serializing_if = "Option::is_none")]
    cw: Option<f64>,
    #[serde(rename = "Cb", default, skip_serializing_if = "Option::is_none")]
    cb: Option<f64>,
    #[serde(rename = "Ct")]
    ct: f64,
    #[serde(rename = "Cig", default, skip_serializing_if = "Option::is_none")]
    cig: Option<f64>,
    #[serde(rename = "Ciw", default, skip_serializing_if = "Option::is_none")]
    ciw: Option<f64>,
    #[serde(rename = "fm", default, skip_serializing_if = "Option::is_none")]
    fm: Option<f64>,
    #[serde(rename = "fw", default, skip_serializing_if = "Option::is_none")]
    fw: Option<f64>,
    #[serde(rename = "ft")]
    ft: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fsm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fsw: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fst: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    vsm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    vsw: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    vst: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stribeck_shape: Option<f64>,
    #[serde(rename = "Kg", default, skip_serializing_if = "Option::is_none")]
    kg: Option<f64>,
    #[serde(rename = "Kw", default, skip_serializing_if = "Option::is_none")]
    kw: Option<f64>,
    #[serde(rename = "Kb", default, skip_serializing_if = "Option::is_none")]
    kb: Option<f64>,
    #[serde(rename = "Rg", default, skip_serializing_if = "Option::is_none")]
    rg: Option<f64>,
    #[serde(rename = "Rw", default, skip_serializing_if = "Option::is_none")]
    rw: Option<f64>,
    #[serde(rename = "r", default, skip_serializing_if = "Option::is_none")]
    r: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    theta_bg: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    theta_bw: Option<f64>,
    #[serde(rename = "W", default, skip_serializing_if = "Option::is_none")]
    w: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fluct_order: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fluct_phase: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    unbalance_mass: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    unbalance_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    unbalance_phase: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    encoder_delay: Option<f64>,
    #[serde(rename = "Tload", default, skip_serializing_if = "Option::is_none")]
    tload: Option<f64>,
    controller: ControllerParams,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    notes: BTreeMap<String, String>,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    ranges: BTreeMap<String, HeldRange>,
}

fn is_rotary(axis: &Axis) -> bool {
    *axis == Axis::Rotary
}

/// Which fields a file of one topology and axis takes.
struct Form {
    topology: Topology,
    axis: Axis,
}

impl Form {
    /// The value of a field a file must give where it applies: the given one, the
    /// registry's `unused` value where it does not apply, or the error naming it.
    fn required(&self, name: &'static str, given: Option<f64>) -> Result<f64, ParamError> {
        let s = spec(name).expect("the file form names registered parameters");
        match given {
            Some(v) => Ok(v),
            None if s.applies_to(self.topology, self.axis) => Err(ParamError::Required {
                name: s.name,
                topology: self.topology,
                meaning: s.meaning,
            }),
            None => Ok(s.unused),
        }
    }

    /// The value of a field with a default (its registry `unused` value).
    fn optional(&self, name: &'static str, given: Option<f64>) -> f64 {
        given.unwrap_or_else(|| {
            spec(name)
                .expect("the file form names registered parameters")
                .unused
        })
    }

    /// An optional field as written: present where it applies and differs from its
    /// default, so that files without it (every Coulomb drive) read and write as before.
    fn unless_default(&self, name: &'static str, value: f64) -> Option<f64> {
        let s = spec(name).expect("the file form names registered parameters");
        self.written(name, value).filter(|v| *v != s.unused)
    }

    /// The field as written: present where it applies.
    fn written(&self, name: &'static str, value: f64) -> Option<f64> {
        let s = spec(name).expect("the file form names registered parameters");
        s.applies_to(self.topology, self.axis).then_some(value)
    }
}

impl TryFrom<ParamsJson> for Params {
    type Error = ParamError;

    fn try_from(j: ParamsJson) -> Result<Self, ParamError> {
        let f = Form {
            topology: j.topology,
            axis: j.axis,
        };
        Ok(Params {
            name: j.name,
            topology: j.topology,
            axis: j.axis,
            jm: f.required("Jm", j.jm)?,
            jw: f.optional("Jw", j.jw),
            jt: j.jt,
            mw: f.required("Mw", j.mw)?,
            cm: f.required("Cm", j.cm)?,
            cw: f.optional("Cw", j.cw),
            cb: f.required("Cb", j.cb)?,
            ct: j.ct,
            cig: j.cig,
            ciw: f.required("Ciw", j.ciw)?,
            fm: f.required("fm", j.fm)?,
            fw: f.optional("fw", j.fw),
            ft: j.ft,
            fsm: f.optional("fsm", j.fsm),
            fsw: f.optional("fsw", j.fsw),
            fst: f.optional("fst", j.fst),
            vsm: f.optional("vsm", j.vsm),
            vsw: f.optional("vsw", j.vsw),
            vst: f.optional("vst", j.vst),
            stribeck_shape: f.optional("stribeck_shape", j.stribeck_shape),
            kg: j.kg,
            kw: f.required("Kw", j.kw)?,
            kb: f.required("Kb", j.kb)?,
            rg: j.rg,
            rw: f.required("Rw", j.rw)?,
            r: f.required("r", j.r)?,
            theta_bg: j.theta_bg,
            theta_bw: f.optional("theta_bw", j.theta_bw),
            w: f.optional("W", j.w),
            fluct_order: f.optional("fluct_order", j.fluct_order),
            fluct_phase: f.optional("fluct_phase", j.fluct_phase),
            unbalance_mass: f.optional("unbalance_mass", j.unbalance_mass),
            unbalance_radius: f.optional("unbalance_radius", j.unbalance_radius),
            unbalance_phase: f.optional("unbalance_phase", j.unbalance_phase),
            encoder_delay: f.optional("encoder_delay", j.encoder_delay),
            tload: f.optional("Tload", j.tload),
            controller: j.controller,
            notes: j.notes,
            ranges: j.ranges,
        })
    }
}

impl From<Params> for ParamsJson {
    fn from(p: Params) -> Self {
        let f = Form {
            topology: p.topology,
            axis: p.axis,
        };
        ParamsJson {
            name: p.name,
            topology: p.topology,
            axis: p.axis,
            jm: f.written("Jm", p.jm),
            jw: f.written("Jw", p.jw),
            jt: p.jt,
            mw: f.written("Mw", p.mw),
            cm: f.written("Cm", p.cm),
            cw: f.written("Cw", p.cw),
            cb: f.written("Cb", p.cb),
            ct: p.ct,
            cig: p.cig,
            ciw: f.written("Ciw", p.ciw),
            fm: f.written("fm", p.fm),
            fw: f.written("fw", p.fw),
            ft: p.ft,
            fsm: f.unless_default("fsm", p.fsm),
            fsw: f.unless_default("fsw", p.fsw),
            fst: f.unless_default("fst", p.fst),
            vsm: f.unless_default("vsm", p.vsm),
            vsw: f.unless_default("vsw", p.vsw),
            vst: f.unless_default("vst", p.vst),
            stribeck_shape: f.unless_default("stribeck_shape", p.stribeck_shape),
            kg: p.kg,
            kw: f.written("Kw", p.kw),
            kb: f.written("Kb", p.kb),
            rg: p.rg,
            rw: f.written("Rw", p.rw),
            r: f.written("r", p.r),
            theta_bg: p.theta_bg,
            theta_bw: f.written("theta_bw", p.theta_bw),
            w: f.written("W", p.w),
            fluct_order: f.written("fluct_order", p.fluct_order),
            fluct_phase: f.written("fluct_phase", p.fluct_phase),
            unbalance_mass: f.written("unbalance_mass", p.unbalance_mass),
            unbalance_radius: f.written("unbalance_radius", p.unbalance_radius),
            unbalance_phase: f.written("unbalance_phase", p.unbalance_phase),
            encoder_delay: f.written("encoder_delay", p.encoder_delay),
            tload: (p.tload != 0.0).then_some(p.tload),
            controller: p.controller,
            notes: p.notes,
            ranges: p.ranges,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::model::params::{ParamError, Params, Topology};
    use crate::model::presets;

    #[test]
    fn the_shipped_presets_write_exactly_their_files() {
        // Every field of the existing presets is written as before; nothing new.
        for name in ["worm-gear", "roller-gear-cam"] {
            let p = presets::load(name).unwrap();
            let v = serde_json::to_value(&p).unwrap();
            assert!(
                v.get("axis").is_none() && v.get("Tload").is_none(),
                "{name}"
            );
            let back: Params = serde_json::from_value(v).unwrap();
            assert_eq!(back, p, "{name}");
        }
    }

    #[test]
    fn a_missing_required_field_is_named_with_the_topology() {
        let mut v = serde_json::to_value(presets::load("two-mass").unwrap()).unwrap();
        v.as_object_mut().unwrap().remove("Kw");
        let err = serde_json::from_value::<Params>(v).unwrap_err().to_string();
        assert!(
            err.contains("missing field `Kw`") && err.contains("two_mass"),
            "{err}"
        );
    }

    #[test]
    fn fields_that_do_not_apply_are_not_written_and_are_refused_when_given() {
        let p = presets::load("direct-drive").unwrap();
        let v = serde_json::to_value(&p).unwrap();
        for absent in ["Jm", "Kw", "Mw", "Rw", "r", "theta_bw", "W"] {
            assert!(v.get(absent).is_none(), "{absent} written: {v}");
        }
        let mut given = v.clone();
        given["Kw"] = serde_json::json!(3.0e5);
        let q: Params = serde_json::from_value(given).unwrap();
        assert_eq!(q.validate(), Err(ParamError::NotApplicable { name: "Kw" }));
        assert_eq!(q.topology, Topology::DirectDrive);
    }
}

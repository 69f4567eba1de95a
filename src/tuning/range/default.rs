//! The range a tuning holds on by default (docs/tuning.md, "Tuning over a range"):
//! the machine as the data leave it — each fitted parameter over the fit's interval
//! ([`crate::identify::result::interval`]), each held parameter over its held range
//! (the fit's, or the parameter set's own: a preset's uncertain values, a parameter
//! file's `ranges`).
//!
//! **What the range keeps.** The margins are the targets, so a quantity is varied
//! where it moves them: today's cascade is analysed at both ends of each quantity, and
//! the [`MAX_DEFAULT`] that move a margin most, by at least [`MIN_EFFECT`], make the
//! range (the grid over four quantities is 81 machines, its corners 16). The others
//! are left at their value, each with the reason, in the range's `origins`: a backlash,
//! a Coulomb friction or a fluctuation does not enter the linearised loop (their effect
//! on positioning is what `rtid predict` carries).

use serde::Serialize;

use super::{Range, Vary};
use crate::model::modes::LinearModel;
use crate::model::{Params, Spread};
use crate::tuning::margins::GRID_POINTS;
use crate::tuning::sampled::{Closure, DiscretePlant, SampledLoop};
use crate::tuning::stability::{analyse_on, LoopMargins};

/// The most quantities the default range varies.
pub const MAX_DEFAULT: usize = 4;
/// The least change of a margin (° of phase, dB of gain) at a quantity's ends that
/// puts it in the default range.
pub const MIN_EFFECT: f64 = 0.5;
/// The effect of a quantity that makes the loop invalid at an end.
pub const MAX_EFFECT: f64 = 180.0;
/// The margin grid the effects are measured on (coarser than the tuning's: the
/// effect ranks quantities, the range's own analysis decides).
const EFFECT_GRID: usize = GRID_POINTS / 4;

/// A quantity the default range considered, and what it did with it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Origin {
    #[serde(flatten)]
    pub spread: Spread,
    /// The largest change of today's cascade margins at its ends (° or dB; a margin
    /// that appears or vanishes counts its whole size, an unstable end
    /// [`MAX_EFFECT`]); `None` where it does not enter the linearised loop or
    /// today's loop is unstable (then the range keeps the first four, unranked).
    pub effect: Option<f64>,
    /// Why it is held at its value (`None`: it is in the range).
    pub left_out: Option<String>,
}

/// The default range of `p`: `given` (the fit's intervals and held ranges, first
/// come first), then `p`'s own held ranges of the parameters `given` does not name;
/// the [`MAX_DEFAULT`] that move today's margins most by at least [`MIN_EFFECT`].
/// `left` are quantities known to be out already (a fitted parameter without an
/// interval), listed with their reason.
pub fn default_range(p: &Params, given: &[Spread], left: &[(String, String)]) -> Range {
    let mut all: Vec<Spread> = given.to_vec();
    for (name, r) in &p.ranges {
        if !all.iter().any(|q| &q.name == name) && !left.iter().any(|l| &l.0 == name) {
            all.push(Spread::held(name, r.percent, &r.reason));
        }
    }
    let Ok(today) = margins_of(p) else {
        return Range::nominal();
    };
    let mut origins: Vec<Origin> = all
        .into_iter()
        .map(|q| {
            let (effect, left_out) = weigh(p, &today, &q);
            Origin {
                spread: q,
                effect,
                left_out,
            }
        })
        .collect();
    let rank = |o: &Origin| o.effect.unwrap_or(-1.0);
    origins.sort_by(|a, b| rank(b).total_cmp(&rank(a)));
    let mut kept = 0;
    for o in origins.iter_mut().filter(|o| o.left_out.is_none()) {
        kept += 1;
        if kept > MAX_DEFAULT {
            o.left_out = Some(format!(
                "the range keeps the {MAX_DEFAULT} that move the margins most"
            ));
        }
    }
    origins.extend(left.iter().map(|(name, why)| Origin {
        spread: Spread {
            name: name.clone(),
            low: 1.0,
            high: 1.0,
            from: "the fit".into(),
        },
        effect: None,
        left_out: Some(why.clone()),
    }));
    Range {
        vary: origins
            .iter()
            .filter(|o| o.left_out.is_none())
            .map(|o| Vary {
                name: o.spread.name.clone(),
                low: o.spread.low,
                high: o.spread.high,
            })
            .collect(),
        delay_periods: 0,
        origins,
    }
}

/// The range a tuning asks for on `p`: `vary` and `delay_periods` where either is
/// given; the nominal machine with `nominal`; else [`default_range`] with a fit's
/// spreads and the parameters it left without (`rtid tune`'s `--vary`,
/// `--delay-periods`, `--nominal`).
pub fn asked(
    vary: Vec<Vary>,
    delay_periods: u32,
    nominal: bool,
    p: &Params,
    (spreads, without): (&[Spread], &[(String, String)]),
) -> Range {
    if nominal {
        Range::nominal()
    } else if vary.is_empty() && delay_periods == 0 {
        default_range(p, spreads, without)
    } else {
        Range {
            vary,
            delay_periods,
            ..Range::default()
        }
    }
}

/// `q`'s effect on today's margins `today` (`None` where it does not enter the
/// linearised loop, or today's loop is unstable and has no margins to move), and
/// why it is left out if it is.
fn weigh(p: &Params, today: &LoopMargins, q: &Spread) -> (Option<f64>, Option<String>) {
    let probe = Range {
        vary: vec![Vary {
            name: q.name.clone(),
            low: q.low,
            high: q.high,
        }],
        ..Range::default()
    };
    if let Err(e) = probe.check(p) {
        let why = e.to_string();
        let why = why
            .strip_prefix(&format!("--vary {}: ", q.name))
            .unwrap_or(&why);
        return (None, Some(why.to_string()));
    }
    let ends: Result<Vec<Params>, _> = [q.low, q.high]
        .into_iter()
        .map(|ratio| {
            let point = super::Point {
                ratios: vec![ratio],
                delay_periods: 0,
            };
            probe.apply(p, &point)
        })
        .collect();
    let Ok(ends) = ends else {
        return (None, Some("the drive is not valid at its ends".into()));
    };
    if !ends.iter().any(|at| enters(p, at)) {
        return (None, Some("does not enter the linearised loop".into()));
    }
    if !today.stability.stable {
        return (None, None);
    }
    let effect = ends
        .iter()
        .map(|at| margins_of(at).map_or(f64::INFINITY, |m| change(today, &m)))
        .fold(0.0, f64::max);
    let left_out = (effect < MIN_EFFECT)
        .then(|| format!("moves today's margins by less than {MIN_EFFECT}° / {MIN_EFFECT} dB"));
    (Some(effect.min(MAX_EFFECT)), left_out)
}

/// Whether `at` differs from `p` in the linearised drive (its matrices, the
/// encoder's dead time).
fn enters(p: &Params, at: &Params) -> bool {
    let linear = |x: &Params| LinearModel::new(x).ok();
    linear(p) != linear(at) || p.encoder_delay != at.encoder_delay
}

/// Today's cascade on `p`'s drive.
fn margins_of(p: &Params) -> Result<LoopMargins, crate::model::ParamError> {
    let plant = DiscretePlant::new(p)?;
    let l = SampledLoop::new(&plant, &p.controller, Closure::Cascade);
    Ok(analyse_on(&l, EFFECT_GRID))
}

/// The largest change between two loops' margins (° and dB alike; one that appears
/// or vanishes counts its whole size; an unstable loop loses them all).
fn change(a: &LoopMargins, b: &LoopMargins) -> f64 {
    let each = |m: &LoopMargins| {
        let stable = m.stability.stable;
        [
            m.margins.phase_margin_deg,
            m.margins.gain_margin_db,
            m.stability.gain_reduction_margin_db,
        ]
        .map(|v| v.filter(|_| stable))
    };
    each(a)
        .iter()
        .zip(each(b))
        .map(|(x, y)| match (*x, y) {
            (Some(x), Some(y)) => (x - y).abs(),
            (Some(v), None) | (None, Some(v)) => v.abs(),
            (None, None) => 0.0,
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn named<'a>(r: &'a Range, name: &str) -> &'a Origin {
        r.origins
            .iter()
            .find(|o| o.spread.name == name)
            .unwrap_or_else(|| panic!("{name} in {:?}", r.origins))
    }

    #[test]
    fn the_worm_gears_held_ranges_that_move_its_margins_make_its_range() {
        let p = presets::load("worm-gear").unwrap();
        let r = default_range(&p, &[], &[]);
        assert_eq!(r.origins.len(), p.ranges.len(), "{:?}", r.origins);
        // The backlashes and the fluctuation do not enter the linearised loop.
        for name in ["theta_bw", "theta_bg", "W"] {
            let o = named(&r, name);
            assert_eq!(o.effect, None, "{o:?}");
            let why = o.left_out.as_deref();
            assert_eq!(why, Some("does not enter the linearised loop"), "{o:?}");
        }
        // The spur gears' inertia on the motor's side does, by its held 50 %; the
        // table's, behind the worm's ratio, hardly (0.04° at ±25 %).
        let jw = named(&r, "Jw");
        assert!(
            jw.left_out.is_none() && jw.effect >= Some(MIN_EFFECT),
            "{jw:?}"
        );
        assert_eq!(
            r.vary
                .iter()
                .find(|v| v.name == "Jw")
                .map(|v| (v.low, v.high)),
            Some((0.5, 1.5))
        );
        let jt = named(&r, "Jt");
        assert!(jt.effect > Some(0.0) && jt.left_out.is_some(), "{jt:?}");
        assert!(r.vary.len() <= MAX_DEFAULT);
        r.check(&p).unwrap();
    }

    #[test]
    fn a_fits_interval_replaces_the_held_range_and_a_missing_one_is_named() {
        let p = presets::load("two-mass").unwrap();
        let jt = Spread::fitted("Jt", p.jt, 0.5 * p.jt, 1.5 * p.jt, "bootstrap").unwrap();
        let left = [("Jm".to_string(), "not determined".to_string())];
        let r = default_range(&p, &[jt], &left);
        let v = r.vary.iter().find(|v| v.name == "Jt").expect("Jt varied");
        assert_eq!((v.low, v.high), (0.5, 1.5));
        assert!(named(&r, "Jt").spread.from.contains("fit's interval"));
        assert_eq!(named(&r, "Jm").left_out.as_deref(), Some("not determined"));
        assert!(!r.vary.iter().any(|v| v.name == "Jm"));
    }

    #[test]
    fn with_todays_loop_unstable_the_quantities_that_enter_it_are_kept_unranked() {
        let mut p = presets::load("two-mass").unwrap();
        p.controller.kvp *= 1000.0;
        assert!(!margins_of(&p).unwrap().stability.stable);
        let r = default_range(&p, &[], &[]);
        let mut varied: Vec<&str> = r.vary.iter().map(|v| v.name.as_str()).collect();
        varied.sort();
        assert_eq!(varied, ["Cm", "Ct", "Jm", "Jt"], "{:?}", r.origins);
        assert!(r.origins.iter().all(|o| o.effect.is_none()));
    }

    #[test]
    fn a_set_without_held_ranges_is_the_nominal_machine() {
        let mut p = presets::load("direct-drive").unwrap();
        p.ranges.clear();
        let r = default_range(&p, &[], &[]);
        assert!(r.is_nominal() && r.origins.is_empty());
    }
}

//! Each warning's text for people: one short function per variant, chosen by
//! [`text`]. The texts say what the data cannot tell and what to change.

use super::{Side, Warning};
use crate::names::Num;

/// The message of `w`.
pub(super) fn text(w: &Warning) -> String {
    match w {
        Warning::MethodSwitched {
            residuals,
            parameters,
        } => method_switched(*residuals, *parameters),
        Warning::CheckpointNotWritten { path, error } => {
            format!("the checkpoint {path} could not be written: {error}")
        }
        Warning::Interrupted { evaluations } => interrupted(*evaluations),
        Warning::EvaluationFailures { example } => {
            format!("some trial parameter sets could not be evaluated, e.g. {example}")
        }
        Warning::DistinctSolution { start, solution } => distinct_solution(*start, solution),
        Warning::AtBound { name, side } => at_bound(name, *side),
        Warning::PhaseDelay { source, delay_s } => phase_delay(source, *delay_s),
        Warning::ResonanceMiss {
            source,
            max_miss_hz,
        } => resonance_miss(source, *max_miss_hz),
        Warning::NotFollowed {
            source,
            position_rms,
            position_span,
        } => not_followed(source, *position_rms, *position_span),
        Warning::NotDetermined { names } => not_determined(names),
        Warning::BootstrapAtBound {
            name,
            side,
            replicates,
            of,
        } => format!(
            "{name}: {replicates} of {of} bootstrap replicates ran to its {side} bound: the records do not bound it there, and where the fit stopped says little — not determined, no interval (state it with --set, or add a record that determines it)"
        ),
        Warning::NoEffect { name } => {
            format!("{name} has no effect on the residuals: the data say nothing about it")
        }
        Warning::TooFewResiduals {
            residuals,
            parameters,
        } => format!(
            "{residuals} residuals for {parameters} parameters: the data cannot determine them all"
        ),
        Warning::Singular {
            conditioning,
            names,
        } => singular(*conditioning, names),
        Warning::Correlated { a, b, correlation } => correlated(a, b, *correlation),
        Warning::RoughCost => ROUGH_COST.to_string(),
        Warning::EstimateUnused { source, values } => estimate_unused(source, values),
        Warning::Escalated {
            source,
            model_hz,
            measured_hz,
            linear_hz,
            max_miss_hz,
            max_miss_percent,
            linear_misfit_db,
            assumed,
        } => {
            escalated(
                source,
                (model_hz, measured_hz, linear_hz),
                (*max_miss_hz, *max_miss_percent),
                *linear_misfit_db,
            ) + &assumed_note(assumed)
        }
        Warning::CorrectionsNotConverged {
            corrections,
            moved,
            widened,
            undetermined,
        } => corrections_not_converged(*corrections, moved, widened, undetermined),
        Warning::LinearStands {
            source,
            linear_misfit_db,
            noise_db,
            max_miss_percent,
            assumed,
        } => linear_stands(
            source,
            *linear_misfit_db,
            *noise_db,
            *max_miss_percent,
            assumed,
        ),
        Warning::ProfileOpen {
            name,
            side,
            bound,
            family,
        } => profile_open(name, *side, *bound, family),
        Warning::ProfileBetterFit {
            name,
            value,
            cost,
            fit_cost,
        } => profile_better_fit(name, *value, *cost, *fit_cost),
    }
}

fn phase_delay(source: &str, delay_s: f64) -> String {
    format!(
        "{source}: the phase error grows with frequency like a delay of {:.1} µs that the \
         manifest does not state — a measurement chain's delay (filters, a recorder)? \
         State it as conditions.delay_s (seconds), or \"unknown\" to fit it",
        1e6 * delay_s
    )
}

fn not_followed(source: &str, position_rms: f64, position_span: f64) -> String {
    format!(
        "{source}: the replay does not follow the record (position error {position_rms:.4e} \
         RMS over a span of {position_span:.4e}, SI): the fitted values do not describe this \
         drive — check the controller's settings, the loop and the frame (ratio)"
    )
}

fn not_determined(names: &[String]) -> String {
    let them = if names.len() == 1 { "it" } else { "them" };
    format!(
        "{} not determined: no record moves {them} apart from the other fitted parameters, nor \
         do all of them together; held at the start value, without an interval (fix {them}, \
         or add a record that moves {them})",
        names.join(", "),
    )
}

fn linear_stands(
    source: &str,
    linear_misfit_db: f64,
    noise_db: f64,
    max_miss_percent: f64,
    assumed: &str,
) -> String {
    let assumed = if assumed.is_empty() {
        String::new()
    } else {
        format!(", with {assumed} assumed,")
    };
    format!(
        "{source}: the linear fit explains the gain curve within its noise (misfit \
         {linear_misfit_db:.3} dB RMS, the curve's own noise {noise_db:.3} dB), so it \
         stands: the nonlinear test at its parameters{assumed} moves the resonances by up to \
         {max_miss_percent:.2} %, but these data do not show it (--model nonlinear \
         corrects all the same)"
    )
}

fn method_switched(residuals: usize, parameters: usize) -> String {
    format!(
        "{residuals} residuals for {parameters} parameters: Gauss–Newton cannot run (JᵀJ singular), Nelder–Mead used instead"
    )
}

fn interrupted(evaluations: usize) -> String {
    format!(
        "the search was stopped after {evaluations} evaluations: this is the best point found so far, not a converged fit (resuming from the checkpoint continues it)"
    )
}

fn distinct_solution(start: usize, solution: &str) -> String {
    format!(
        "start {start} ended at a different solution ({solution}) with the same cost: the data do not determine a unique solution"
    )
}

fn at_bound(name: &str, side: Side) -> String {
    format!(
        "{name} ended at its {side} bound: the data pull it further — widen its bounds, or another parameter (fixed now) must change"
    )
}

fn resonance_miss(source: &str, max_miss_hz: f64) -> String {
    format!(
        "{source}: the fitted model misses the measured resonances by up to {max_miss_hz:.1} Hz — the fitted parameters alone cannot reach them"
    )
}

fn singular(conditioning: f64, names: &[String]) -> String {
    format!(
        "JᵀJ is singular (conditioning {conditioning:.1e}): the data cannot separate {}",
        names.join(", ")
    )
}

fn correlated(a: &str, b: &str, correlation: f64) -> String {
    format!(
        "{a} and {b} are correlated {correlation:+.3}: the data cannot separate them (fix one, or add an experiment that moves them differently)"
    )
}

const ROUGH_COST: &str = "the standard errors of a fit to a closed-loop simulation (torque curve, unbalance test, servo trace) count the residuals' scatter only: the quantised encoders make the cost rough, and the search stops in its local minima (fm +0.67 % against a 0.08 % standard error on the worm fixture from fm 0.2): read them as lower bounds, or run --profile (a bowl fitted to the rough cost: seconds) or --resample (the whole fit repeated) for intervals that hold";

fn estimate_unused(source: &str, values: &str) -> String {
    format!(
        "{source}: its direct estimate ({values}) is not a valid parameter set, so the search starts at the given values instead — check the record (too little motion, a wrong unit or sign)"
    )
}

/// The resonances of the nonlinear test (`model`) against the measured ones, the
/// largest miss in Hz and %, and the linear gain's misfit.
fn escalated(
    source: &str,
    (model_hz, measured_hz, linear_hz): (&[f64], &[f64], &[f64]),
    (max_miss_hz, max_miss_percent): (f64, f64),
    linear_misfit_db: f64,
) -> String {
    format!(
        "{source}: the linear fit does not explain the data — the nonlinear virtual test at its parameters puts the resonances at {} Hz (measured {} Hz{}), up to {max_miss_hz:.2} Hz ({max_miss_percent:.2} %) off, and the linear model's gain misses the measured curve by {linear_misfit_db:.2} dB RMS — beyond 0.5 % (a stiffness biased twice as much) and three standard errors of the measured peak, or 1 dB (a flattened or misplaced peak): backlash or friction at the test's amplitude. So the result is the nonlinear fit, the linear one corrected by the nonlinear test",
        hz(model_hz),
        hz(measured_hz),
        if linear_hz.is_empty() {
            String::new()
        } else {
            format!("; the linear fit's own {} Hz", hz(linear_hz))
        }
    )
}

/// What a correction took as given, said after the escalation.
fn assumed_note(assumed: &str) -> String {
    if assumed.is_empty() {
        String::new()
    } else {
        format!(
            ". It assumes {assumed} as given: this record does not determine them (fit \
             them with --fit, or state them with --set)"
        )
    }
}

fn hz(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn profile_open(name: &str, side: Side, bound: f64, family: &[(String, f64)]) -> String {
    let mut text = format!(
        "{name}'s profile stays below the 95 % level up to its {side} bound {}: the data do not bound it on that side",
        Num(bound)
    );
    if !family.is_empty() {
        let moved: Vec<String> = family.iter().map(|(n, r)| format!("{n} ×{r:.2}")).collect();
        let names: Vec<&str> = family.iter().map(|(n, _)| n.as_str()).collect();
        text += &format!(
            "; along the profile {} moved with it: the data determine a combination of {name}, {}, not each",
            moved.join(", "),
            names.join(", ")
        );
    }
    text
}

fn profile_better_fit(name: &str, value: f64, cost: f64, fit_cost: f64) -> String {
    format!(
        "holding {name} at {} fits better than the result (cost {cost:.4e} against {fit_cost:.4e}): the search stopped short of the optimum — rerun with more --starts, or from there",
        Num(value)
    )
}

fn corrections_not_converged(
    corrections: usize,
    moved: &[(String, f64)],
    widened: &[String],
    undetermined: &[String],
) -> String {
    let moves: Vec<String> = moved
        .iter()
        .map(|(n, step)| format!("{n} {:.2} %", 100.0 * step))
        .collect();
    let mut text = format!(
        "the nonlinear corrections did not converge in {corrections}: the last moved {} — the \
         result is not an optimum of the nonlinear test",
        moves.join(", ")
    );
    if !widened.is_empty() {
        text += &format!(
            "; the standard errors of {} are widened to that move (the corrections' own spread)",
            widened.join(", ")
        );
    }
    if !undetermined.is_empty() {
        text +=
            &format!(
            "; {} moved by more than a quarter of {}: not determined by this record through the \
             nonlinear test (no standard error given; hold {} with --set, or fit on a record \
             that reaches {})",
            undetermined.join(", "),
            if undetermined.len() == 1 { "its value" } else { "their values" },
            if undetermined.len() == 1 { "it" } else { "them" },
            if undetermined.len() == 1 { "its mode" } else { "their modes" },
        );
    }
    text
}

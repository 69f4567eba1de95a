//! The plan of an identification, decided before any evaluation from the
//! configuration and what its objectives declare: what to fit, the stages (a search,
//! then the nonlinear corrections of `--model nonlinear`), each stage's solver,
//! starts and finite-difference step, the step of the uncertainty's Jacobian, and
//! whether the result is checked on the nonlinear test. Pure: no simulation runs.

use crate::identify::config::{Config, FidelityChoice};
use crate::identify::search::settings::Method;
use crate::identify::search::settings::{Settings, SIMPLEX_STEP, SIMPLEX_STEP_NEAR};
use crate::identify::setup::{self, Declared};
use crate::model::Topology;
use crate::objectives::{Fidelity, SetupError, Stage};

/// One stage.
#[derive(Clone, Debug, PartialEq)]
pub struct StagePlan {
    /// A multi-start search, or the corrections of its result by the nonlinear test.
    pub stage: Stage,
    pub fidelity: Fidelity,
    /// The search's settings (for corrections: those of their linear sub-searches).
    pub settings: Settings,
    /// Run only when the linear search's result fails the nonlinear check
    /// (`--model auto`: [`crate::identify::pipeline::escalation`]).
    pub escalation: bool,
}

/// The whole plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The fitted parameters.
    pub fit: Vec<String>,
    pub stages: Vec<StagePlan>,
    /// What the search's objectives declare.
    pub declared: Declared,
    /// Whether the linear result is checked on the nonlinear test (`auto` with a gain
    /// curve), which decides the escalation stage.
    pub check_nonlinear: bool,
    /// Whether the search's objectives are rough (a closed-loop simulation).
    rough: bool,
}

/// Forward-difference step of the Gauss–Newton Jacobian (solver coordinates) on a
/// smooth cost, and on a rough one (a closed-loop simulation, or the nonlinear test).
const FD_SMOOTH: f64 = 1e-5;
const FD_ROUGH: f64 = 1e-3;
/// The step on a cost rough below a few per cent ([`crate::objectives::Smoothness::Grainy`]):
/// on the EMPS trace Levenberg–Marquardt stopped at 1e-3 with a cost 0.9 % above
/// Nelder–Mead's (its columns were the roughness), and reached it at 3e-2; at 1e-1
/// the forward differences' bias showed (+1e-4 in the cost).
const FD_GRAINY: f64 = 3e-2;

/// The central-difference step (in ln p) of the Jacobian behind the standard errors
/// and correlations. It must be larger than the scale on which the cost is rough, or
/// the Jacobian's columns are that roughness and the warnings say nothing: with a
/// closed-loop time simulation (torque curve, unbalance) the quantised encoders'
/// jitter fills the columns at steps below ~0.1 — at 2e-3 the torque curve's fm–fw
/// correlation reads −0.04, at 0.1 −0.89, at 0.3 −0.98 (the physics: fm and fw·Rg add
/// up) — and the nonlinear frequency response varies irregularly by ±0.03 dB near a
/// friction-flattened peak, which a 2 % step (a 1 % shift of the peak, ~0.7 dB on its
/// flanks) rises well above. The exact linear response is smooth: 1e-4.
pub(crate) fn uncertainty_step(rough: bool, fidelity: Fidelity) -> f64 {
    if rough {
        0.1
    } else if fidelity == Fidelity::Nonlinear {
        2e-2
    } else {
        1e-4
    }
}

impl Plan {
    /// The plan of `config`.
    pub fn new(config: &Config) -> Result<Plan, SetupError> {
        let declared = setup::declared(&config.experiments, Stage::Search)?;
        let fit = if config.fit.is_empty() {
            setup::default_fit(&config.experiments, &config.base)?
        } else {
            config.fit.clone()
        };
        let nonlinear = config.fidelity == FidelityChoice::Nonlinear;
        let auto = config.fidelity == FidelityChoice::Auto;
        // Without a measured gain curve there are no flanks to correct on: a
        // nonlinear fit then searches on the nonlinear test directly.
        let first = if nonlinear && !declared.gain_curve {
            Fidelity::Nonlinear
        } else {
            Fidelity::Linear
        };
        let o = &config.search;
        let rough = declared.rough;
        // A replay is grainy on a rigid direct drive only: a geared or coupled axis
        // adds backlash and the motor's stick, and on the virtual worm trace
        // Levenberg–Marquardt stopped at Cm +1.5 % (+1.2 % at a 0.1 step) where
        // Nelder–Mead lands within 1 % (tests/servo_trace.rs).
        let derivative_free =
            declared.derivative_free || (rough && config.base.topology != Topology::DirectDrive);
        let method = o.method.unwrap_or(match (rough, derivative_free) {
            (false, _) => Method::Lsq,
            (true, true) => Method::NelderMead,
            (true, false) => Method::Lm,
        });
        let mut stages = vec![StagePlan {
            stage: Stage::Search,
            fidelity: first,
            settings: Settings {
                method,
                starts: o.starts.unwrap_or(if rough { 1 } else { 4 }),
                seed: o.seed,
                max_iters: o.max_iters,
                fd_step: if first == Fidelity::Linear && !rough {
                    FD_SMOOTH
                } else if method == Method::Lm {
                    FD_GRAINY
                } else {
                    FD_ROUGH
                },
                max_evaluations: o.max_evaluations,
                simplex_step: SIMPLEX_STEP,
            },
            escalation: false,
        }];
        if (nonlinear || auto) && declared.gain_curve {
            stages.push(StagePlan {
                stage: Stage::Correction,
                fidelity: Fidelity::Nonlinear,
                settings: Settings {
                    method: Method::Lsq,
                    starts: 1,
                    seed: o.seed,
                    max_iters: 50,
                    fd_step: if rough { FD_ROUGH } else { FD_SMOOTH },
                    max_evaluations: o.max_evaluations,
                    simplex_step: SIMPLEX_STEP,
                },
                escalation: auto,
            });
        }
        Ok(Plan {
            fit,
            stages,
            declared,
            check_nonlinear: auto && declared.gain_curve,
            rough,
        })
    }

    /// The central-difference step (in ln p) of the Jacobian behind the standard
    /// errors, when the first `ran` stages have run.
    pub fn uncertainty_step(&self, ran: usize) -> f64 {
        uncertainty_step(self.rough, self.last_fidelity(ran))
    }

    /// The model of the last of the first `ran` stages (the first stage's when none
    /// ran).
    fn last_fidelity(&self, ran: usize) -> Fidelity {
        self.stages[..ran.clamp(1, self.stages.len())]
            .last()
            .map_or(Fidelity::Linear, |s| s.fidelity)
    }

    /// The plan of a search that starts at a direct estimate
    /// ([`crate::identify::start`]): the first stage's Nelder–Mead simplex starts small.
    pub fn from_estimate(mut self) -> Plan {
        self.stages[0].settings.simplex_step = SIMPLEX_STEP_NEAR;
        self
    }

    /// What the result says of the model after the first `ran` stages: `linear`,
    /// `nonlinear`, `linear, then nonlinear`; `nonlinear time simulation` when no
    /// objective depends on the frequency-response model (a torque curve is always
    /// simulated).
    pub(crate) fn fidelity_label(&self, ran: usize) -> String {
        if !self.declared.frequency_response {
            return "nonlinear time simulation".into();
        }
        self.stages[..ran.clamp(1, self.stages.len())]
            .iter()
            .map(|s| s.fidelity.name())
            .collect::<Vec<_>>()
            .join(", then ")
    }
}

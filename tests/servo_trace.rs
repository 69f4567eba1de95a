//! Servo traces: the EMPS benchmark's estimation record (real measurements, A. Janot,
//! M. Gautier, M. Brunot, "Data Set and Reference Models of EMPS", 2019) replayed with
//! the published model, its controller law checked sample by sample, the friction law
//! fitted to it; virtual traces of rtid's presets replayed exactly and fitted.
//!
//! Fixtures: fixtures/real/emps/emps_estimation.csv (a byte copy of the benchmark's
//! record as converted in shared/data/emps) and fixtures/real/emps/axis.json (the
//! published model as an rtid parameter file).

use std::path::PathBuf;

use rtid::controller::{Controller, Gains};
use rtid::estimation::inverse_dynamics::IdimSettings;
use rtid::experiments::servo_trace::{
    replay, replay_batch, simulation_error, virtual_trace, MoveTo, ServoTrace, TraceError,
    TrapezoidalMoves,
};
use rtid::experiments::torque_curve::idim_fit;
use rtid::experiments::torque_curve::{self, TorqueTest};
use rtid::io::experiment_file::{self, Data};
use rtid::model::modes::max_rate;
use rtid::model::{presets, Params};
use rtid::sim::{default_step, STEP_ACCURACY};

use crate::support;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/real/emps")
        .join(name)
}

/// The published EMPS model as an rtid parameter file.
fn emps_axis() -> Params {
    let text = std::fs::read_to_string(fixture("axis.json")).unwrap();
    let p: Params = serde_json::from_str(&text).unwrap();
    p.validate().unwrap();
    p
}

/// The estimation record as a trace, read through its experiment file (the recorded
/// output is the whole controller output: nothing was added to it).
fn emps_record() -> ServoTrace {
    let e = experiment_file::read(&fixture("emps_estimation.json")).unwrap();
    let Data::ServoTrace(file) = &e.data else {
        panic!(
            "emps_estimation.json is not a servo trace: {:?}",
            e.data.kind()
        );
    };
    let trace = ServoTrace::from_file(file);
    assert_eq!(trace.len(), 24_841);
    assert!(trace.controller_output.is_some());
    trace
}

/// RMS of the controller's output against the recorded one when the law is driven
/// by the measured positions (sample 0 left out: its previous sample is unknown).
fn law_rms(p: &Params, trace: &ServoTrace) -> f64 {
    let mut p = p.clone();
    // The measured positions are encoder readings already: no second quantisation.
    p.controller.motor_encoder_resolution = 0.0;
    let q = &trace.position;
    let mut c = Controller::new(Gains::new(&p).unwrap(), q[0], q[0]);
    let recorded = trace.controller_output.as_ref().unwrap();
    let mut sum = 0.0;
    for k in 0..trace.len() {
        c.update(trace.reference[k], q[k], q[k]);
        if k > 0 {
            sum += (c.output() - recorded[k]).powi(2);
        }
    }
    (sum / (trace.len() - 1) as f64).sqrt()
}

#[test]
fn the_emps_controller_law_reproduces_the_recorded_output() {
    let p = emps_axis();
    let trace = emps_record();
    let at_sample = law_rms(&p, &trace);
    // README of shared/data/emps: the law at the sample follows the recorded vir to
    // 0.050 V RMS (3 % of RMS vir) — the recorded output's own rounding and noise.
    assert!((at_sample - 0.050).abs() < 0.002, "{at_sample} V");
    // One sample late reproduces it worse (0.073 V), as the README says.
    let mut late = p.clone();
    late.controller.output_delay_periods = 1.0;
    let one_late = law_rms(&late, &trace);
    eprintln!(
        "controller law: {at_sample:.4} V RMS at the sample, {one_late:.4} V one sample late"
    );
    assert!(one_late > 1.3 * at_sample, "{one_late} V");
}

#[test]
fn the_emps_record_replays_to_the_published_simulation_error() {
    let p = emps_axis();
    let trace = emps_record();
    let run = replay(&p, &trace).unwrap();
    let e = simulation_error(&trace, &run).unwrap();
    let force_rms = (trace.force.iter().map(|f| f * f).sum::<f64>() / trace.len() as f64).sqrt();
    eprintln!(
        "EMPS replay: position {:.3} µm RMS, {:.2} µm max, force {:.3} N RMS ({:.2} % of {:.1} N RMS)",
        e.position_rms * 1e6,
        e.position_max * 1e6,
        e.force_rms,
        100.0 * e.force_rms / force_rms,
        force_rms,
    );
    // Published (Janot et al. 2019): 2.10 µm RMS, 12.6 µm max, 2.41 N RMS; measured
    // 2.095 µm, 12.55 µm, 2.420 N. Margins: 5 % on the RMS errors, 10 % on the
    // largest (a single sample). Their integrator, initial state and sign(0) are not
    // published; the margins are well inside what a wrong model costs (measured on
    // this record: M + 2 % → 2.54 µm, 2.66 N; Fc + 10 % → 2.56 µm, 3.17 N; Tload = 0
    // → 3.12 µm, 3.99 N; the law one sample late → 2.70 µm, 16.9 µm max, 3.11 N).
    assert!((e.position_rms / 2.10e-6 - 1.0).abs() < 0.05, "{e:?}");
    assert!((e.position_max / 12.6e-6 - 1.0).abs() < 0.10, "{e:?}");
    assert!((e.force_rms / 2.41 - 1.0).abs() < 0.05, "{e:?}");
}

#[test]
fn replays_in_lanes_give_each_parameter_set_its_lone_replay() {
    // The first 3 s of the record on nine sets: six of one shape (Jt, Ct, ft,
    // Tload each 3-10 % off, two velocity gains: a batch of four lanes and a pair),
    // two with Stribeck laws (a pair), and one invalid (its own error).
    let mut trace = emps_record();
    let n = 3000;
    for v in [
        &mut trace.time_s,
        &mut trace.reference,
        &mut trace.position,
        &mut trace.force,
    ] {
        v.truncate(n);
    }
    trace.controller_output = trace.controller_output.map(|c| c[..n].to_vec());
    let base = emps_axis();
    let sets: Vec<Params> = (0..9)
        .map(|l| {
            let mut p = base.clone();
            match l {
                0 => p.jt *= 1.03,
                1 => p.ct *= 0.95,
                2 => p.ft *= 1.1,
                3 => p.tload = -p.tload,
                4 | 5 => p.controller.kvp *= 0.1 * l as f64,
                6 | 7 => (p.fst, p.vst) = (0.1 * l as f64 * p.ft, 0.002 * l as f64),
                _ => p.jt = -1.0,
            }
            p
        })
        .collect();
    let batch = replay_batch(&sets, &trace);
    for (l, (p, got)) in sets.iter().zip(&batch).enumerate().take(8) {
        let alone = replay(p, &trace).unwrap();
        assert_eq!(got.as_ref().unwrap(), &alone, "set {l}");
    }
    assert!(batch[8].is_err(), "Jt < 0 is refused");
    assert_ne!(batch[0], batch[1], "the sets differ");
    assert_ne!(batch[4], batch[5], "the gains differ");
    assert_ne!(batch[6], batch[7], "the Stribeck laws differ");
}

#[test]
fn a_virtual_trace_of_the_worm_preset_replays_with_zero_error() {
    let p = presets::load("worm-gear").unwrap();
    let to = |target, speed| MoveTo { target, speed };
    let moves = TrapezoidalMoves {
        moves: vec![to(0.05, 0.1), to(-0.02, 0.05)],
        acceleration: 1.0,
        dwell_s: 0.1,
    };
    let trace = virtual_trace(&p, &moves, None).unwrap();
    assert!(trace.position.iter().any(|&x| x > 0.049), "the table moved");
    let run = replay(&p, &trace).unwrap();
    let e = simulation_error(&trace, &run).unwrap();
    assert_eq!(
        (e.position_rms, e.position_max, e.force_rms),
        (0.0, 0.0, 0.0)
    );
    assert_eq!(Some(run.controller_output), trace.controller_output);
    // Another model does not replay it: the comparison can fail.
    let mut stiffer = p.clone();
    stiffer.kw *= 1.5;
    let other = simulation_error(&trace, &replay(&stiffer, &trace).unwrap()).unwrap();
    assert!(
        other.force_rms > 0.0 && other.position_max > 0.0,
        "{other:?}"
    );
}

/// A drive clock of 4 ms read from a record as 0.0039999999 s is a multiple of no
/// decimal step near the accurate one: the step divides it evenly instead (before,
/// the search went down to 1e-11 s and a 10 s replay ran for hours). The virtual
/// trace at that period replays exactly, in a fraction of a second.
#[test]
fn a_recorded_control_period_is_divided_evenly_not_by_a_vanishing_step() {
    let mut p = presets::load("direct-drive").unwrap();
    p.controller.tc = 0.0039999999;
    let dt = default_step(&p).unwrap();
    let steps = (p.controller.tc / dt).round();
    assert!((steps * dt - p.controller.tc).abs() <= 1e-9 * p.controller.tc);
    // Accurate, and no smaller than half the ladder's largest accurate step (1e-5 s
    // at most: a rigid direct drive has no fast mode).
    let rate = max_rate(&p).unwrap();
    let accurate = (STEP_ACCURACY / rate).min(1e-5);
    assert!(
        rate * dt <= STEP_ACCURACY && dt >= 0.5 * accurate,
        "dt = {dt:e} s against {accurate:e} s"
    );
    let to = |target, speed| MoveTo { target, speed };
    let moves = TrapezoidalMoves {
        moves: vec![to(0.5, 1.0), to(-0.2, 0.5)],
        acceleration: 10.0,
        dwell_s: 0.1,
    };
    let trace = virtual_trace(&p, &moves, None).unwrap();
    let e = simulation_error(&trace, &replay(&p, &trace).unwrap()).unwrap();
    assert_eq!((e.position_max, e.force_rms), (0.0, 0.0));
}

/// A record whose replay would take more steps than a replay may (three samples
/// 10 000 s apart, on the direct drive's step of 10 µs or less: 2e9 steps and more)
/// is refused before any step is taken, with its cost.
#[test]
fn a_replay_too_long_to_run_is_refused_up_front() {
    let p = presets::load("direct-drive").unwrap();
    let trace = ServoTrace {
        time_s: vec![0.0, 1e4, 2e4],
        reference: vec![0.0; 3],
        position: vec![0.0; 3],
        table_position: None,
        force: vec![0.0; 3],
        controller_output: None,
        controller_added: None,
        drive_functions: None,
    };
    let e = replay(&p, &trace).expect_err("2e9 steps and more");
    assert!(
        matches!(e, TraceError::TooLong { steps, .. } if steps > 1.99e9),
        "{e:?}"
    );
    assert!(e.to_string().contains("steps of the model"), "{e}");
}

#[test]
fn an_added_signal_is_in_the_recorded_output_and_replays() {
    let p = presets::load("two-mass").unwrap();
    let dither = |t: f64| 0.05 * (2.0 * std::f64::consts::PI * 37.0 * t).sin();
    let moves = TrapezoidalMoves {
        moves: vec![MoveTo {
            target: 1.0,
            speed: 2.0,
        }],
        acceleration: 20.0,
        dwell_s: 0.1,
    };
    let with = virtual_trace(&p, &moves, Some(&dither)).unwrap();
    let without = virtual_trace(&p, &moves, None).unwrap();
    assert_ne!(with.force, without.force);
    let added = with.controller_added.clone().unwrap();
    assert!(added.iter().any(|&a| a.abs() > 0.04));
    let run = replay(&p, &with).unwrap();
    assert_eq!(simulation_error(&with, &run).unwrap().force_rms, 0.0);
    // Without its added signal the record does not replay.
    let mut stripped = with.clone();
    stripped.controller_added = None;
    let e = simulation_error(&with, &replay(&p, &stripped).unwrap()).unwrap();
    assert!(e.force_rms > 1e-3, "{e:?}");
}

#[test]
fn the_friction_law_of_the_emps_trace_is_the_published_one() {
    // Published IDIM-LS (Janot et al. 2019): M 95.1089 kg, Fv 203.5034 N·s/m,
    // Fc 20.3935 N, OF −3.1648 N. The method's own tests (tests/inverse_dynamics.rs)
    // check it closer; this one checks the trace as read from its file feeds it.
    let fit = emps_record()
        .fit_friction(&IdimSettings::default())
        .unwrap();
    assert!((fit.inertia.value / 95.1089 - 1.0).abs() < 0.01, "{fit:?}");
    assert!((fit.viscous.value / 203.5034 - 1.0).abs() < 0.01, "{fit:?}");
    assert!((fit.coulomb.value / 20.3935 - 1.0).abs() < 0.01, "{fit:?}");
    assert!((fit.offset.value + 3.1648).abs() < 0.05, "{fit:?}");
}

#[test]
fn the_friction_law_of_a_virtual_emps_trace_is_the_model_s() {
    let p = emps_axis();
    let trace = virtual_trace(&p, &TrapezoidalMoves::default(), None).unwrap();
    // Standstill left out: at rest the servo holds anywhere within ±Fc of the load,
    // which the law (sign(0) = 0) does not describe.
    let settings = IdimSettings {
        min_speed: 0.01,
        ..Default::default()
    };
    let fit = trace.fit_friction(&settings).unwrap();
    eprintln!("virtual EMPS trace: {fit:?}");
    let m = fit.inertia.value;
    assert!((m / p.jt - 1.0).abs() < 0.02, "{m}");
    assert!((fit.viscous.value / p.ct - 1.0).abs() < 0.02, "{fit:?}");
    assert!((fit.coulomb.value / p.ft - 1.0).abs() < 0.02, "{fit:?}");
    assert!((fit.offset.value + p.tload).abs() < 0.1, "{fit:?}");
}

#[test]
fn the_friction_law_of_the_worm_torque_curve_is_the_friction_at_the_motor() {
    let p = presets::load("worm-gear").unwrap();
    let curve = torque_curve::run(&p, &TorqueTest::default(), |_, _| {}).unwrap();
    let fit = idim_fit(&curve, &IdimSettings::default()).unwrap();
    let at_motor = p.fm + p.fw * p.rg.unwrap() + p.ft * p.ratio();
    let windows = torque_curve::evaluate(&curve, &TorqueTest::default())
        .unwrap()
        .friction_nm
        .unwrap();
    eprintln!(
        "worm torque curve: fit Fc = {:.4} N·m, reversal windows {windows:.4}, model {at_motor:.4}",
        fit.coulomb.value
    );
    assert!((fit.coulomb.value / at_motor - 1.0).abs() < 0.05, "{fit:?}");
}

/// Output-error identification on the real EMPS record (issue 11) as a user runs it:
/// starting values off by a factor 2 or more, the default fit (Jt, Ct, ft, Tload) and
/// the default start — the IDIM-LS estimate of the trace — then the replayed trace's
/// fit (Levenberg–Marquardt, one start: the replay's quantised encoder makes the cost
/// rough below a few per cent, issue 27). It converges in at most 20 replays (13 when
/// measured; Nelder–Mead spent 116 and stopped at its limit), lands within 3 % of the
/// published M and Fv, 5 % of Fc and 0.5 N of OF, and its simulation error is no
/// worse than the published model's (2.10 µm RMS position, 2.41 N RMS force). About
/// 2 s.
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (~2 s): --features slow-tests"
)]
fn output_error_from_the_idim_estimate_reaches_the_published_model() {
    use rtid::identify::{identify, Config, ExperimentSpec, Monitor};
    use rtid::objectives::Detail;
    let mut guess = emps_axis();
    for (name, value) in [("Jt", 50.0), ("Ct", 100.0), ("ft", 10.0), ("Tload", 1.0)] {
        guess.set(name, value).unwrap();
    }
    let e = experiment_file::read(&fixture("emps_estimation.json")).unwrap();
    let spec = ExperimentSpec::new("emps_estimation.json", e);
    let r = identify(&Config::new(vec![spec], guess, &[]), &Monitor::default()).unwrap();
    let estimate = &r.result.start_estimates;
    assert_eq!(estimate.len(), 1, "one IDIM-LS start: {estimate:?}");
    assert!(
        (estimate[0].values["Jt"] / 95.1089 - 1.0).abs() < 0.02,
        "{estimate:?}"
    );
    assert_eq!(
        r.result.initial, estimate[0].values,
        "the search starts there"
    );
    let got = |n: &str| r.result.parameters[n];
    let off = |n: &str, want: f64| (got(n) / want - 1.0).abs();
    eprintln!("EMPS output error from IDIM: {:?}", r.result.parameters);
    assert_eq!(r.result.method, "lm");
    assert!(
        r.result.termination.0.converged(),
        "{:?}",
        r.result.termination
    );
    assert!(
        r.result.evaluations <= 20,
        "{} replays",
        r.result.evaluations
    );
    assert!(off("Jt", 95.1089) < 0.03, "{:?}", r.result.parameters);
    assert!(off("Ct", 203.5034) < 0.03, "{:?}", r.result.parameters);
    assert!(off("ft", 20.3935) < 0.05, "{:?}", r.result.parameters);
    assert!(
        (got("Tload") - 3.1648).abs() < 0.5,
        "{:?}",
        r.result.parameters
    );
    let detail = r.result.residuals[0].detail.clone();
    let Some(Detail::Trace {
        force_rms,
        position_rms,
        ..
    }) = detail
    else {
        panic!("a trace detail: {detail:?}");
    };
    eprintln!("simulation error: {position_rms:.4e} m RMS, {force_rms:.4} N RMS");
    assert!(
        position_rms <= 2.10e-6 && force_rms <= 2.41,
        "{position_rms} m, {force_rms} N"
    );
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (~6 s): --features slow-tests"
)]
fn the_emps_profiles_count_the_misfits_correlation() {
    // The model's misfit on the real record is correlated over hundreds of samples:
    // the profiles (a bowl fitted to the replay's rough cost) count the residuals'
    // correlation, the standard errors do not (docs/identification.md).
    use rtid::identify::{identify, Config, ExperimentSpec, Monitor};
    let e = experiment_file::read(&fixture("emps_estimation.json")).unwrap();
    let spec = ExperimentSpec::new("emps_estimation.json", e);
    let fit = identify(
        &Config::new(vec![spec], emps_axis(), &[]),
        &Monitor::default(),
    )
    .unwrap();
    let names: Vec<&str> = fit.result.parameters.keys().map(String::as_str).collect();
    let (profiles, _) = support::profiles(&fit, &names);
    let m = fit.result.residuals[0].residuals.len() as f64;
    for (name, p) in &profiles {
        let s = p
            .surface
            .as_ref()
            .expect("a servo trace's replay is profiled on a bowl");
        let (lo, hi) = (p.lower.unwrap(), p.upper.unwrap());
        let v = fit.result.parameters[name];
        assert!(lo < v && v < hi, "{name}: the fit {v} outside {lo}…{hi}");
        assert!(s.effective_residuals < m / 10.0, "{name}: {s:?}");
        let se = fit.result.standard_error(name).unwrap();
        assert!(
            hi - lo > 5.0 * 2.0 * 1.96 * se,
            "{name}: {lo}…{hi}, se {se}"
        );
    }
}

/// The EMPS record as the force curve a user first tries (issue 11): time, force and
/// carriage position in a `torque_curve` file, with an amplitude and a period.
fn emps_as_force_curve() -> experiment_file::Experiment {
    use rtid::io::experiment_file::{Kind, Manifest};
    let trace = emps_record();
    let mut manifest = Manifest::new(Kind::TorqueCurve);
    manifest.conditions.amplitude_m = Some(0.1);
    manifest.conditions.period_s = Some(6.0);
    experiment_file::Experiment {
        manifest,
        data: Data::ForceCurve {
            time_s: trace.time_s.clone(),
            force_n: trace.force.clone(),
            table_position_m: Some(trace.position.clone()),
            extra: Default::default(),
        },
        path: PathBuf::from("emps_force_curve.json"),
        data_path: None,
    }
}

/// The evaluator's friction on a trajectory unlike the torque test's sine: the law
/// fitted over the whole curve reads the published Fc (20.39 N) where the reversal
/// windows, placed for a sine, read +39 % (the 28.4 N).
#[test]
fn the_torque_curve_evaluator_reads_the_published_friction_on_the_emps_motion() {
    let e = emps_as_force_curve();
    let curve = torque_curve::from_data(&e.data).expect("a force curve");
    let test = TorqueTest::from_conditions(&e.manifest.conditions);
    assert_eq!(test.amplitude, 0.1, "a linear amplitude in m");
    let report = torque_curve::evaluate(&curve, &test).unwrap();
    let windows: Vec<f64> = report.reversals.iter().map(|r| r.friction_nm).collect();
    eprintln!(
        "EMPS as a force curve: Fc {:?} from {}; reversal windows {windows:.2?}",
        report.friction_nm, report.friction_from
    );
    assert_eq!(report.friction_from, "inverse_dynamics");
    let fc = report.friction_nm.unwrap();
    assert!((fc / 20.3935 - 1.0).abs() < 0.02, "{fc}");
}

/// The torque-curve objective simulates its sine test: on a record of another motion
/// it refuses, naming the recorded amplitude and period against the test's and
/// pointing to the servo_trace kind, instead of walking to nonsense (the issue: fm =
/// 3.9, Cm = 39 with a 63.6 N RMS error).
#[test]
fn the_torque_curve_objective_refuses_a_motion_that_is_not_its_test() {
    use rtid::objectives::{Fidelity, ObjectiveKind, Source};
    let e = emps_as_force_curve();
    let source = Source {
        file: "emps_force_curve.json",
        experiment: &e,
    };
    let kind = ObjectiveKind::named("torque_curve").unwrap();
    let Err(err) = kind.build(&source, Fidelity::Linear) else {
        panic!("the EMPS motion was accepted as the torque test's sine");
    };
    let text = err.to_string();
    eprintln!("{text}");
    for part in [
        "emps_force_curve.json",
        "not the torque test's",
        "100.0000 mm",
        "6 s period",
        "servo_trace",
    ] {
        assert!(text.contains(part), "`{part}` missing: {text}");
    }
    // The worm fixture's recorded angle is its test's sine: accepted.
    let worm = experiment_file::read(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear/torque_curve.json"),
    )
    .unwrap();
    let source = Source {
        file: "torque_curve.json",
        experiment: &worm,
    };
    assert!(kind.build(&source, Fidelity::Linear).is_ok());
}

/// A virtual trace of the worm preset along trapezoidal moves — three speeds each way,
/// unlike the torque test's sine — gives back the motor friction fm and Cm by the
/// output error, as the EMPS record gives the direct drive's (issue 11), from a start
/// 29 % and 20 % off. About 10 s.
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (~10 s): --features slow-tests"
)]
fn output_error_on_a_virtual_worm_trace_gives_back_the_motor_friction() {
    use rtid::identify::{identify, Config, ExperimentSpec, Monitor};
    use rtid::io::experiment_file::{Axis, CommandUnit, Experiment, Kind, Manifest};
    let truth = presets::load("worm-gear").unwrap();
    let trace = virtual_trace(&truth, &TrapezoidalMoves::default(), None).unwrap();
    let experiment = Experiment {
        manifest: Manifest::new(Kind::ServoTrace),
        data: Data::ServoTrace(trace.to_file(Axis::Rotary, CommandUnit::NewtonMetre)),
        path: PathBuf::from("worm_trace.json"),
        data_path: None,
    };
    let mut start = truth.clone();
    start.fm *= 1.29;
    start.cm *= 0.8;
    let spec = ExperimentSpec::new("worm_trace.json", experiment);
    let r = identify(&Config::new(vec![spec], start, &[]), &Monitor::default()).unwrap();
    let got = &r.result.parameters;
    eprintln!(
        "worm trace: {got:?} (truth fm {}, Cm {})",
        truth.fm, truth.cm
    );
    assert_eq!(got.len(), 2, "the default fit on a geared table: fm, Cm");
    assert!((got["fm"] / truth.fm - 1.0).abs() < 0.01, "{got:?}");
    assert!((got["Cm"] / truth.cm - 1.0).abs() < 0.01, "{got:?}");
    assert!(
        r.result.start_estimates.is_empty(),
        "no IDIM start on a geared table"
    );
}

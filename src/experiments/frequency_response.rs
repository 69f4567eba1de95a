//! The frequency-response test as a virtual experiment (paper §4.1, MODEL.md §5.1).
//!
//! Open loop, motor torque `preload·Rg·Rw + A·sin(2πft)`, table brake `−preload`.
//! Every frequency is an independent nonlinear time simulation, run in parallel
//! (rayon, one simulation per task). Gain = 20·log10 of the steady amplitude of the
//! table angle over that of the motor angle × Rg·Rw; its peaks are the resonances
//! (the damped motor-held modes).
//!
//! **Start.** Each run starts from the steady state of the linearised model (exact
//! complex response to the sine, plus the static twist of the preload with the
//! flanks in contact), which removes most of the transient.
//!
//! **Steady state.** The run proceeds in windows of whole drive cycles (at least
//! [`FrequencyTest::window_s`] long). In each window the table and motor angles,
//! sampled ≥ 40 times a cycle, are fitted by least squares with an offset, a
//! quadratic drift (an open-loop sine from rest makes the whole drive drift, and
//! Coulomb friction makes that drift uneven) and sin/cos at the drive frequency. The
//! point is settled when the gain changes by less than `tolerance_db` and each
//! amplitude by less than 10× that in relative terms between two successive windows;
//! after `max_duration_s` the last window is used and the point is marked unsettled.
//!
//! **Backlash.** Per frequency, the fraction of the last window's samples in which
//! each mesh is out of contact (inside its gap) is reported. Where it is not zero the
//! table rattles in the gap and the "gain" is not a property of the drive.

use nalgebra::{Complex, DVector};
use rayon::prelude::*;

use crate::input::Sine;
use crate::model::drive::{idx::*, Drive, NSTATE};
use crate::model::modes::LinearModel;
use crate::model::Params;
use crate::recorder::Recorder;
use crate::sim::{SimError, Simulation};

/// Conditions of the test (defaults: MODEL.md §5.1).
#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyTest {
    /// Coarse grid, Hz (default 10, 20, …, 600).
    pub frequencies_hz: Vec<f64>,
    /// Sine amplitude of the motor torque, N·m (default 5).
    pub amplitude_nm: f64,
    /// Table brake torque balanced by a motor DC torque, N·m (default 0).
    pub preload_nm: f64,
    /// Refinement step around each coarse peak, Hz (default 1; 0: none).
    pub refine_step_hz: f64,
    /// Half-width of the refined band around each coarse peak, Hz (default 10).
    pub refine_half_width_hz: f64,
    /// Gain change between windows below which a point is settled, dB (0.01).
    pub tolerance_db: f64,
    /// Minimum window length, s (whole cycles; default 0.02).
    pub window_s: f64,
    /// Longest simulation per frequency, s (default 1).
    pub max_duration_s: f64,
    /// Integration step (default: the model's).
    pub dt: Option<f64>,
}

impl Default for FrequencyTest {
    fn default() -> Self {
        FrequencyTest {
            frequencies_hz: (1..=60).map(|i| 10.0 * i as f64).collect(),
            amplitude_nm: 5.0,
            preload_nm: 0.0,
            refine_step_hz: 1.0,
            refine_half_width_hz: 10.0,
            tolerance_db: 0.01,
            window_s: 0.02,
            max_duration_s: 1.0,
            dt: None,
        }
    }
}

/// The result at one frequency.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Point {
    pub frequency_hz: f64,
    pub gain_db: f64,
    /// Phase of the table relative to the motor angle, degrees.
    pub phase_deg: f64,
    /// Steady amplitudes, rad.
    pub motor_amplitude_rad: f64,
    pub table_amplitude_rad: f64,
    /// Fraction of the last window out of contact: spur mesh, drive mesh.
    pub contact_loss: [f64; 2],
    /// Whether the amplitudes settled before `max_duration_s`.
    pub settled: bool,
    /// Whether the table amplitude was below the table encoder's resolution (the
    /// table held inside the gap, say): the gain is then computed with that
    /// resolution as the table amplitude, the floor a measurement would show.
    pub below_resolution: bool,
    /// Simulated time, s.
    pub simulated_s: f64,
}

/// A resonance: a local maximum of the gain, located by parabolic interpolation.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Peak {
    pub frequency_hz: f64,
    pub gain_db: f64,
}

/// Samples of one window: time, motor angle, table angle, and contact counts.
struct Window {
    every: usize,
    count: usize,
    t: Vec<f64>,
    motor: Vec<f64>,
    table: Vec<f64>,
    open: [usize; 2],
    drive: Drive,
}

impl Recorder for Window {
    fn record(&mut self, t: f64, y: &[f64; NSTATE], _u: f64) {
        self.count += 1;
        if self.count % self.every != 0 {
            return;
        }
        self.t.push(t);
        self.motor.push(y[THETA_M]);
        self.table.push(y[THETA_T]);
        let dz = self.drive.mesh_deflections(y);
        let gaps = self.drive.gaps();
        for i in 0..2 {
            self.open[i] += usize::from(gaps[i] > 0.0 && dz[i] == 0.0);
        }
    }
}

impl Window {
    fn clear(&mut self) {
        self.count = 0;
        self.t.clear();
        self.motor.clear();
        self.table.clear();
        self.open = [0, 0];
    }
}

/// Amplitude and phase (rad) of the component at `omega` of `x(t)`, fitted with an
/// offset and a quadratic drift ([`super::stepped_sine::fit`]).
fn sine_component(t: &[f64], x: &[f64], omega: f64) -> (f64, f64) {
    let f = super::stepped_sine::fit(t, x, omega);
    (f.amplitude, f.phase)
}

/// The initial state: the linear steady state of the sine, plus the static twist of
/// the preload with the loaded flanks in contact.
pub(crate) fn initial_state(p: &Params, omega: f64, test: &FrequencyTest) -> [f64; NSTATE] {
    let mut y = [0.0; NSTATE];
    if let Ok(lin) = LinearModel::new(p) {
        let mut f = DVector::from_element(lin.n_dof(), Complex::new(0.0, 0.0));
        f[0] = Complex::new(test.amplitude_nm, 0.0);
        if let Some(x) = lin.response(omega, &f) {
            // Input A·sin(ωt) = Im(A·e^{iωt}): q(0) = Im X, q'(0) = ω·Re X.
            for (k, name) in lin.dofs.iter().enumerate() {
                let (pos, vel) = match *name {
                    "theta_m" => (THETA_M, OMEGA_M),
                    "theta_w" => (THETA_W, OMEGA_W),
                    "x_w" => (X_W, V_W),
                    _ => (THETA_T, OMEGA_T),
                };
                y[pos] = x[k].im;
                y[vel] = omega * x[k].re;
            }
        }
    }
    let spur = p.rg.is_some();
    if !spur {
        y[THETA_W] = y[THETA_M];
        y[OMEGA_W] = y[OMEGA_M];
    }
    // Static twist of the preload (positive flanks loaded), and of the backlash.
    let tw = test.preload_nm;
    if tw != 0.0 || p.theta_bw > 0.0 || p.theta_bg.unwrap_or(0.0) > 0.0 {
        let side = if tw < 0.0 { -1.0 } else { 1.0 };
        let xw = -tw / (p.r * p.kb);
        let dw = tw / p.kw + side * p.theta_bw;
        let shaft = (dw - xw / p.r) / p.rw;
        y[X_W] += xw;
        if spur {
            let tg = tw * p.rw;
            let dg = tg / p.kg.unwrap_or(f64::INFINITY) + side * p.theta_bg.unwrap_or(0.0);
            y[THETA_W] += shaft;
            y[THETA_M] += (dg + shaft) / p.rg.unwrap_or(1.0);
        } else {
            y[THETA_M] += shaft;
            y[THETA_W] = y[THETA_M];
        }
    }
    y
}

/// Simulates one frequency until its amplitudes settle.
pub fn simulate_point(
    p: &Params,
    frequency_hz: f64,
    test: &FrequencyTest,
) -> Result<Point, SimError> {
    let omega = std::f64::consts::TAU * frequency_hz;
    let mut sim = match test.dt {
        Some(dt) => Simulation::new(p, dt)?,
        None => Simulation::with_default_step(p)?,
    };
    let dt = sim.dt();
    sim.set_state(initial_state(p, omega, test));
    sim.set_load(-test.preload_nm);
    let mut input = Sine::new(frequency_hz, test.amplitude_nm, test.preload_nm * p.ratio());
    let period = 1.0 / frequency_hz;
    let cycles = (test.window_s / period).ceil().max(1.0);
    let window = cycles * period;
    let every = ((period / 40.0 / dt).floor() as usize).max(1);
    let capacity = (window / dt / every as f64).ceil() as usize + 2;
    let mut rec = Window {
        every,
        count: 0,
        t: Vec::with_capacity(capacity),
        motor: Vec::with_capacity(capacity),
        table: Vec::with_capacity(capacity),
        open: [0, 0],
        drive: *sim.drive(),
    };
    let ratio = p.ratio();
    // The smallest table amplitude a measurement resolves (0.0001° encoder), and a
    // floor for the ideal-encoder case, so that a table at rest gives a finite gain.
    let floor = p.controller.table_encoder_resolution.max(1e-12);
    let mut previous: Option<(f64, f64, f64)> = None;
    loop {
        rec.clear();
        // Windows end on whole cycles of the absolute time.
        let end = ((sim.time() + window) / period).round() * period;
        sim.run_open_loop(&mut input, end - sim.time(), &mut rec)?;
        let (am, pm) = sine_component(&rec.t, &rec.motor, omega);
        let (at, pt) = sine_component(&rec.t, &rec.table, omega);
        let below_resolution = at < floor;
        let gain = 20.0 * (at.max(floor) / (am.max(f64::MIN_POSITIVE) * ratio)).log10();
        let settled = previous.is_some_and(|(g, a, b)| {
            (gain - g).abs() < test.tolerance_db
                && ((am - a) / a).abs() < 10.0 * test.tolerance_db / 8.686
                && (below_resolution || ((at - b) / b).abs() < 10.0 * test.tolerance_db / 8.686)
        });
        let n = rec.t.len().max(1) as f64;
        if settled || sim.time() >= test.max_duration_s {
            let mut phase = (pt - pm).to_degrees();
            while phase > 180.0 {
                phase -= 360.0;
            }
            while phase <= -180.0 {
                phase += 360.0;
            }
            return Ok(Point {
                frequency_hz,
                gain_db: gain,
                phase_deg: phase,
                motor_amplitude_rad: am,
                table_amplitude_rad: at,
                contact_loss: rec.open.map(|k| k as f64 / n),
                settled,
                below_resolution,
                simulated_s: sim.time(),
            });
        }
        previous = Some((gain, am, at));
    }
}

/// The whole test: the coarse grid, then `refine_step_hz` steps around each local
/// maximum, all in parallel; `progress()` is called after every point. Points come
/// back sorted by frequency.
pub fn sweep(
    p: &Params,
    test: &FrequencyTest,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<Point>, SimError> {
    let run = |freqs: &[f64]| -> Result<Vec<Point>, SimError> {
        freqs
            .par_iter()
            .map(|&f| {
                let r = simulate_point(p, f, test);
                progress();
                r
            })
            .collect()
    };
    let mut points = run(&test.frequencies_hz)?;
    points.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    if test.refine_step_hz > 0.0 {
        let extra = refinement(&points, test);
        points.extend(run(&extra)?);
        points.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    }
    Ok(points)
}

/// The frequencies to add around each local maximum of the coarse gain.
pub fn refinement(points: &[Point], test: &FrequencyTest) -> Vec<f64> {
    let gains: Vec<(f64, f64)> = points.iter().map(|p| (p.frequency_hz, p.gain_db)).collect();
    let mut extra: Vec<f64> = Vec::new();
    for i in local_maxima(&gains) {
        let centre = gains[i].0;
        let n = (test.refine_half_width_hz / test.refine_step_hz).floor() as i64;
        for k in -n..=n {
            let f = centre + k as f64 * test.refine_step_hz;
            let known = |g: f64| (g - f).abs() < 1e-9;
            if f > 0.0
                && !points.iter().any(|p| known(p.frequency_hz))
                && !extra.iter().any(|&g| known(g))
            {
                extra.push(f);
            }
        }
    }
    extra
}

/// Indices of interior local maxima of a curve sorted by x.
fn local_maxima(curve: &[(f64, f64)]) -> Vec<usize> {
    (1..curve.len().saturating_sub(1))
        .filter(|&i| curve[i].1 > curve[i - 1].1 && curve[i].1 >= curve[i + 1].1)
        .collect()
}

/// Resonances of a gain curve sorted by frequency: local maxima located by the
/// parabola through each maximum and its neighbours, the highest `max_peaks` first
/// in importance, returned ascending in frequency.
pub fn peaks(curve: &[(f64, f64)], max_peaks: usize) -> Vec<Peak> {
    let mut found: Vec<Peak> = local_maxima(curve)
        .into_iter()
        .map(|i| {
            let ((x0, y0), (x1, y1), (x2, y2)) = (curve[i - 1], curve[i], curve[i + 1]);
            // Vertex of the parabola through three points.
            let d = (x0 - x1) * (x0 - x2) * (x1 - x2);
            let a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
            let b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
            let c = y1 - a * x1 * x1 - b * x1;
            if a < 0.0 {
                let xv = (-b / (2.0 * a)).clamp(x0, x2);
                Peak {
                    frequency_hz: xv,
                    gain_db: a * xv * xv + b * xv + c,
                }
            } else {
                Peak {
                    frequency_hz: x1,
                    gain_db: y1,
                }
            }
        })
        .collect();
    found.sort_by(|a, b| b.gain_db.total_cmp(&a.gain_db));
    found.truncate(max_peaks);
    found.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    found
}

/// The gain (dB) and phase (deg) of the linearised model at `freqs_hz`, solved in the
/// frequency domain (no backlash, no friction).
pub fn linear(p: &Params, freqs_hz: &[f64]) -> Result<Vec<(f64, f64)>, crate::model::ParamError> {
    Ok(crate::model::modes::frequency_response(p, freqs_hz)?
        .into_iter()
        .map(|h| (20.0 * h.norm().log10(), h.arg().to_degrees()))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sine_fit_ignores_offset_and_drift() {
        let omega = std::f64::consts::TAU * 50.0;
        let t: Vec<f64> = (0..400).map(|i| i as f64 * 1e-4).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&t| 3.0 + 20.0 * t - 5.0 * t * t + 0.7 * (omega * t + 0.4).sin())
            .collect();
        let (a, phi) = sine_component(&t, &x, omega);
        assert!(
            (a - 0.7).abs() < 1e-9 && (phi - 0.4).abs() < 1e-9,
            "{a} {phi}"
        );
    }

    #[test]
    fn parabolic_peaks_find_the_vertex() {
        let curve: Vec<(f64, f64)> = (0..20)
            .map(|i| {
                let f = 180.0 + i as f64;
                (f, 40.0 - 0.3 * (f - 186.4) * (f - 186.4))
            })
            .collect();
        let p = peaks(&curve, 5);
        assert_eq!(p.len(), 1);
        assert!((p[0].frequency_hz - 186.4).abs() < 1e-9 && (p[0].gain_db - 40.0).abs() < 1e-9);
    }
}

//! The frequency-response test as a virtual experiment (paper §4.1, MODEL.md §5.1).
//!
//! Open loop, motor torque `preload·Rg·Rw + A·sin(2πft)`, table brake `−preload`.
//! Every frequency is an independent nonlinear time simulation. They run in
//! [`LANES`]-wide batches advanced in lockstep ([`LaneSimulation`], vectorised), one
//! batch per rayon worker; a lane whose frequency has settled is refilled at once
//! with the next frequency of the shared queue, so lanes rarely idle. A lane
//! computes bit for bit what a lone simulation of its frequency computes
//! ([`simulate_point`] is the same code with one lane). Gain = 20·log10 of the
//! steady amplitude of the table angle over that of the motor angle × Rg·Rw; its
//! peaks are the resonances (the damped motor-held modes).
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

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use nalgebra::{Complex, DVector};
use rayon::prelude::*;

use crate::input::Sine;
use crate::model::drive::{idx::*, Drive, NSTATE};
use crate::model::lanes::Lanes;
use crate::model::modes::LinearModel;
use crate::model::rest::{rest_state, Preload};
use crate::model::Params;
use crate::sim::{default_step, LaneSimulation, SimError};

/// Frequencies advanced together by one worker (two AVX2 registers per state).
pub const LANES: usize = 4;

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
    /// Records left until the next sample.
    until: usize,
    t: Vec<f64>,
    motor: Vec<f64>,
    table: Vec<f64>,
    open: [usize; 2],
    drive: Drive,
}

impl Window {
    /// Counts one recorded state; true if it is to be sampled.
    #[inline]
    fn tick(&mut self) -> bool {
        self.until -= 1;
        if self.until == 0 {
            self.until = self.every;
        }
        self.until == self.every
    }

    fn sample(&mut self, t: f64, y: &[f64; NSTATE]) {
        self.t.push(t);
        self.motor.push(y[THETA_M]);
        self.table.push(y[THETA_T]);
        let dz = self.drive.mesh_deflections(y);
        let gaps = self.drive.gaps();
        for i in 0..2 {
            self.open[i] += usize::from(gaps[i] > 0.0 && dz[i] == 0.0);
        }
    }

    fn clear(&mut self) {
        self.until = self.every;
        self.t.clear();
        self.motor.clear();
        self.table.clear();
        self.open = [0, 0];
    }
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
    if test.preload_nm != 0.0 || p.theta_bw > 0.0 || p.theta_bg.unwrap_or(0.0) > 0.0 {
        let twist = rest_state(p, 0.0, Preload::Torque(test.preload_nm));
        for i in [THETA_M, THETA_W, X_W] {
            y[i] += twist[i];
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
    let dt = step(p, test)?;
    let next = AtomicUsize::new(0);
    let mut out = Vec::with_capacity(1);
    run_lanes::<1>(
        p,
        &[frequency_hz],
        test,
        dt,
        &|| take(&next, 1, None),
        &|| {},
        &mut out,
    )?;
    Ok(out[0].1)
}

/// The integration step of the test.
fn step(p: &Params, test: &FrequencyTest) -> Result<f64, SimError> {
    match test.dt {
        Some(dt) => Ok(dt),
        None => default_step(p),
    }
}

/// The next index of a queue of `n` shared by workers, unless one has failed.
fn take(next: &AtomicUsize, n: usize, failed: Option<&AtomicBool>) -> Option<usize> {
    if failed.is_some_and(|f| f.load(Ordering::Relaxed)) {
        return None;
    }
    let i = next.fetch_add(1, Ordering::Relaxed);
    (i < n).then_some(i)
}

/// The motor torques `offset + amplitude·sin(ωt)` of `L` lanes, each exactly as
/// [`Sine::step_torques`] computes them for its own clock `t` = steps·dt (the same
/// rotations of (sin, cos) by half steps, the same resynchronisation every
/// [`Sine::RESYNC`] steps or on a clock jump), but advanced lane-wise.
struct Sines<const L: usize> {
    dt: f64,
    amplitude: [f64; L],
    offset: [f64; L],
    omega: [f64; L],
    /// sin, cos of ω·t at the next step start, and of ω·dt/2.
    sin: [f64; L],
    cos: [f64; L],
    half_sin: [f64; L],
    half_cos: [f64; L],
    /// Steps taken (the lane's clock is steps·dt), and steps left before the next
    /// resynchronisation (0: now).
    steps: [f64; L],
    count: [u32; L],
    next_t: [f64; L],
}

impl<const L: usize> Sines<L> {
    /// Zero torque in every lane.
    fn new(dt: f64) -> Self {
        Sines {
            dt,
            amplitude: [0.0; L],
            offset: [0.0; L],
            omega: [0.0; L],
            sin: [0.0; L],
            cos: [1.0; L],
            half_sin: [0.0; L],
            half_cos: [1.0; L],
            steps: [0.0; L],
            count: [u32::MAX; L],
            next_t: [0.0; L],
        }
    }

    /// Lane `l` starts `input`'s sine at t = 0 (a fresh [`Sine`]).
    fn start(&mut self, l: usize, frequency_hz: f64, amplitude_nm: f64, offset_nm: f64) {
        self.amplitude[l] = amplitude_nm;
        self.offset[l] = offset_nm;
        self.omega[l] = std::f64::consts::TAU * frequency_hz;
        (self.half_sin[l], self.half_cos[l]) = (0.5 * self.omega[l] * self.dt).sin_cos();
        self.steps[l] = 0.0;
        self.count[l] = 0;
        self.next_t[l] = f64::NAN;
    }

    /// Lane `l` applies no torque.
    fn stop(&mut self, l: usize) {
        (self.amplitude[l], self.offset[l]) = (0.0, 0.0);
        self.count[l] = u32::MAX;
    }

    /// The torques of every lane at the start, middle and end of the next step.
    #[inline]
    fn step_torques(&mut self) -> [[f64; L]; 3] {
        let h = self.dt;
        let t = Lanes(self.steps) * h;
        let jump = t.zip(Lanes(self.next_t), |t, n| {
            if (t - n).abs() > 1e-6 * h {
                1.0
            } else {
                0.0
            }
        });
        let mut resync = jump.any(|j| j != 0.0);
        for c in &mut self.count {
            resync |= *c == 0;
        }
        if resync {
            self.resync(t, jump);
        }
        for c in &mut self.count {
            *c = c.wrapping_sub(1);
        }
        let rotate = |s: Lanes<L>, c: Lanes<L>| {
            let (sh, ch) = (Lanes(self.half_sin), Lanes(self.half_cos));
            (s * ch + c * sh, c * ch - s * sh)
        };
        let (s0, c0) = (Lanes(self.sin), Lanes(self.cos));
        let (s1, c1) = rotate(s0, c0);
        let (s2, c2) = rotate(s1, c1);
        let (a, o) = (Lanes(self.amplitude), Lanes(self.offset));
        self.sin = s2.0;
        self.cos = c2.0;
        self.next_t = (t + h).0;
        self.steps = (Lanes(self.steps) + 1.0).0;
        [s0, s1, s2].map(|s| (o + a * s).0)
    }

    #[cold]
    #[inline(never)]
    fn resync(&mut self, t: Lanes<L>, jump: Lanes<L>) {
        for l in 0..L {
            if self.count[l] == 0 || jump.0[l] != 0.0 {
                (self.sin[l], self.cos[l]) = (self.omega[l] * t.0[l]).sin_cos();
                self.count[l] = Sine::RESYNC;
            }
        }
    }
}

/// One frequency in progress in a lane: its input, its current window and the
/// amplitudes of the previous one.
struct Run {
    index: usize,
    frequency_hz: f64,
    omega: f64,
    period: f64,
    window: f64,
    rec: Window,
    /// Steps left in the current window.
    remaining: u64,
    previous: Option<(f64, f64, f64)>,
}

impl Run {
    /// Starts frequency `index` in lane `l` of `sim`, from the linear steady state.
    fn start<const L: usize>(
        sim: &mut LaneSimulation<L>,
        sines: &mut Sines<L>,
        l: usize,
        p: &Params,
        index: usize,
        frequency_hz: f64,
        test: &FrequencyTest,
    ) -> Self {
        let omega = std::f64::consts::TAU * frequency_hz;
        let dt = sim.dt();
        sim.start(l, initial_state(p, omega, test), -test.preload_nm);
        let period = 1.0 / frequency_hz;
        let cycles = (test.window_s / period).ceil().max(1.0);
        let window = cycles * period;
        let every = ((period / 40.0 / dt).floor() as usize).max(1);
        let capacity = (window / dt / every as f64).ceil() as usize + 2;
        let mut run = Run {
            index,
            frequency_hz,
            omega,
            period,
            window,
            rec: Window {
                every,
                until: every,
                t: Vec::with_capacity(capacity),
                motor: Vec::with_capacity(capacity),
                table: Vec::with_capacity(capacity),
                open: [0, 0],
                drive: *sim.drive(),
            },
            remaining: 0,
            previous: None,
        };
        sines.start(
            l,
            frequency_hz,
            test.amplitude_nm,
            test.preload_nm * p.ratio(),
        );
        run.begin_window(sim, l);
        // The initial state is the first record of the first window.
        if run.rec.tick() {
            run.rec.sample(0.0, &sim.state(l));
        }
        run
    }

    /// Clears the window and sets its length: whole cycles of the absolute time.
    fn begin_window<const L: usize>(&mut self, sim: &LaneSimulation<L>, l: usize) {
        self.rec.clear();
        let now = sim.time(l);
        let end = ((now + self.window) / self.period).round() * self.period;
        self.remaining = (((end - now) / sim.dt()).round() as u64).max(1);
    }

    /// After a step of lane `l`: records, and at the end of a window evaluates it;
    /// returns the point when the run is over.
    #[inline]
    fn after_step<const L: usize>(
        &mut self,
        sim: &LaneSimulation<L>,
        l: usize,
        p: &Params,
        test: &FrequencyTest,
    ) -> Option<Point> {
        if self.rec.tick() {
            self.rec.sample(sim.time(l), &sim.state(l));
        }
        self.remaining -= 1;
        if self.remaining > 0 {
            return None;
        }
        let point = self.end_window(sim.time(l), p, test);
        if point.is_none() {
            self.begin_window(sim, l);
        }
        point
    }

    /// Fits the window; the point if it settled or the time is up.
    fn end_window(&mut self, time: f64, p: &Params, test: &FrequencyTest) -> Option<Point> {
        let rec = &self.rec;
        let ratio = p.ratio();
        // The smallest table amplitude a measurement resolves (0.0001° encoder), and a
        // floor for the ideal-encoder case, so that a table at rest gives a finite gain.
        let floor = p.controller.table_encoder_resolution.max(1e-12);
        let [(am, pm), (at, pt)] =
            super::stepped_sine::components(&rec.t, [&rec.motor, &rec.table], self.omega);
        let below_resolution = at < floor;
        let gain = 20.0 * (at.max(floor) / (am.max(f64::MIN_POSITIVE) * ratio)).log10();
        let settled = self.previous.is_some_and(|(g, a, b)| {
            (gain - g).abs() < test.tolerance_db
                && ((am - a) / a).abs() < 10.0 * test.tolerance_db / 8.686
                && (below_resolution || ((at - b) / b).abs() < 10.0 * test.tolerance_db / 8.686)
        });
        let n = rec.t.len().max(1) as f64;
        if settled || time >= test.max_duration_s {
            let mut phase = (pt - pm).to_degrees();
            while phase > 180.0 {
                phase -= 360.0;
            }
            while phase <= -180.0 {
                phase += 360.0;
            }
            return Some(Point {
                frequency_hz: self.frequency_hz,
                gain_db: gain,
                phase_deg: phase,
                motor_amplitude_rad: am,
                table_amplitude_rad: at,
                contact_loss: rec.open.map(|k| k as f64 / n),
                settled,
                below_resolution,
                simulated_s: time,
            });
        }
        self.previous = Some((gain, am, at));
        None
    }
}

/// Runs frequencies taken from `next` (indices into `freqs`) in the `L` lanes of one
/// simulation until the queue is empty, refilling each lane as its point finishes;
/// pushes (index, point) to `out` and calls `progress` after each point.
fn run_lanes<const L: usize>(
    p: &Params,
    freqs: &[f64],
    test: &FrequencyTest,
    dt: f64,
    next: &dyn Fn() -> Option<usize>,
    progress: &(dyn Fn() + Sync),
    out: &mut Vec<(usize, Point)>,
) -> Result<(), SimError> {
    let mut sim = LaneSimulation::<L>::new(p, dt)?;
    let mut sines = Sines::<L>::new(dt);
    let mut runs: [Option<Run>; L] = std::array::from_fn(|_| None);
    let mut queue_open = true;
    loop {
        if queue_open {
            for (l, run) in runs.iter_mut().enumerate() {
                if run.is_none() {
                    match next() {
                        Some(i) => {
                            *run = Some(Run::start(&mut sim, &mut sines, l, p, i, freqs[i], test))
                        }
                        None => {
                            queue_open = false;
                            break;
                        }
                    }
                }
            }
        }
        if runs.iter().all(Option::is_none) {
            return Ok(());
        }
        sim.step(&sines.step_torques())?;
        for (l, slot) in runs.iter_mut().enumerate() {
            if let Some(run) = slot {
                if let Some(point) = run.after_step(&sim, l, p, test) {
                    out.push((run.index, point));
                    progress();
                    *slot = None;
                    // Idle until refilled: at rest, without load or torque.
                    sim.start(l, [0.0; NSTATE], 0.0);
                    sines.stop(l);
                }
            }
        }
    }
}

/// Every frequency of `freqs`, in [`LANES`]-wide batches on the rayon workers;
/// points in the order of `freqs`.
fn simulate_all(
    p: &Params,
    freqs: &[f64],
    test: &FrequencyTest,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<Point>, SimError> {
    let dt = step(p, test)?;
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let workers = rayon::current_num_threads()
        .min(freqs.len().div_ceil(LANES))
        .max(1);
    let done: Vec<Result<Vec<(usize, Point)>, SimError>> = (0..workers)
        .into_par_iter()
        .map(|_| {
            let mut out = Vec::new();
            let take = || take(&next, freqs.len(), Some(&failed));
            let r = run_lanes::<LANES>(p, freqs, test, dt, &take, progress, &mut out);
            if r.is_err() {
                failed.store(true, Ordering::Relaxed);
            }
            r.map(|()| out)
        })
        .collect();
    let mut points: Vec<Option<Point>> = vec![None; freqs.len()];
    for worker in done {
        for (i, point) in worker? {
            points[i] = Some(point);
        }
    }
    Ok(points.into_iter().flatten().collect())
}

/// The whole test: the coarse grid, then `refine_step_hz` steps around each local
/// maximum, all in parallel; `progress()` is called after every point. Points come
/// back sorted by frequency.
pub fn sweep(
    p: &Params,
    test: &FrequencyTest,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<Point>, SimError> {
    let mut points = simulate_all(p, &test.frequencies_hz, test, progress)?;
    points.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    if test.refine_step_hz > 0.0 {
        let extra = refinement(&points, test);
        points.extend(simulate_all(p, &extra, test, progress)?);
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
        let [(a, phi)] = super::super::stepped_sine::components(&t, [&x], omega);
        assert!(
            (a - 0.7).abs() < 1e-9 && (phi - 0.4).abs() < 1e-9,
            "{a} {phi}"
        );
    }

    #[test]
    fn lanes_of_sines_equal_lone_sines() {
        use crate::input::TorqueInput;
        let dt = 1e-5;
        let mut lanes = Sines::<4>::new(dt);
        let mut lone: Vec<(Sine, u64)> = Vec::new();
        for (l, f) in [10.0, 230.0, 599.0, 47.5].into_iter().enumerate() {
            lanes.start(l, f, 5.0, 0.1 * l as f64);
            lone.push((Sine::new(f, 5.0, 0.1 * l as f64), 0));
        }
        for k in 0..20_000 {
            if k == 7_000 {
                // Lane 2 restarts with another frequency, out of step with the rest.
                lanes.start(2, 321.0, 3.0, -1.0);
                lone[2] = (Sine::new(321.0, 3.0, -1.0), 0);
            }
            let m = lanes.step_torques();
            for (l, (sine, steps)) in lone.iter_mut().enumerate() {
                let expected = sine.step_torques(*steps as f64 * dt, dt);
                *steps += 1;
                assert_eq!([m[0][l], m[1][l], m[2][l]], expected, "lane {l}, step {k}");
            }
        }
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

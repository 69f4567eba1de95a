//! The frequencies of the test, each an independent nonlinear simulation, run in
//! lockstep lanes (module docs of the parent): the lane runner, its window sampler,
//! and the initial state of each run.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use nalgebra::{Complex, DVector};
use rayon::prelude::*;

use super::sines::Sines;
use super::{FrequencyTest, Point, LANES};
use crate::model::drive::{idx::*, Drive, NSTATE};
use crate::model::modes::LinearModel;
use crate::model::rest::{rest_state, Preload};
use crate::model::Params;
use crate::sim::{default_step, LaneSimulation, SimError};

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
                drive: *sim.drive(l),
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
        let [(am, pm), (at, pt)] = crate::estimation::stepped_sine::components(
            &rec.t,
            [&rec.motor, &rec.table],
            self.omega,
        );
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
pub(super) fn simulate_all(
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

#[cfg(test)]
mod tests {
    #[test]
    fn the_sine_fit_ignores_offset_and_drift() {
        let omega = std::f64::consts::TAU * 50.0;
        let t: Vec<f64> = (0..400).map(|i| i as f64 * 1e-4).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&t| 3.0 + 20.0 * t - 5.0 * t * t + 0.7 * (omega * t + 0.4).sin())
            .collect();
        let [(a, phi)] = crate::estimation::stepped_sine::components(&t, [&x], omega);
        assert!(
            (a - 0.7).abs() < 1e-9 && (phi - 0.4).abs() < 1e-9,
            "{a} {phi}"
        );
    }
}
